// Looking Glass calibration files (visual.json) and their mapping onto DESIGN section 5 (derivation in
// docs/DISPLAYS.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <new>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "output/checksum.h"
#include "pmr/display_presets.h"
#include "pmr/error.h"
#include "pmr/json_text.h"
#include "pmr/limits.h"

namespace pmr {

namespace {

using json = nlohmann::json;

// A field stored as {"value": x} (or, leniently, as a bare number).
double number_field(const json& doc, const char* key, const std::string& path, bool required, double fallback) {
  if (!doc.contains(key)) {
    if (required) throw Error(path + ": calibration field '" + key + "' is missing");
    return fallback;
  }
  const json& f = doc[key];
  const json* v = f.is_object() && f.contains("value") ? &f["value"] : &f;
  if (!v->is_number()) throw Error(path + ": calibration field '" + key + "' is not a number");
  const double x = v->get<double>();
  if (!std::isfinite(x)) throw Error(path + ": calibration field '" + key + "' is not finite");
  return x;
}

// An exact decimal for a long double computed from the calibration: 17 decimals below 1, fewer above,
// so that numerator and denominator stay below 2^62 (parse_rational's limit); the rounding (below
// 1e-16 subpixels) is far below the double precision of the shader's own inputs.
Rational exact_decimal(long double x, const std::string& what) {
  int decimals = 17;
  for (long double a = std::fabs(x); a >= 1.0L && decimals > 0; a /= 10.0L) --decimals;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*Lf", decimals, x);
  return parse_rational(buf, what);
}

}  // namespace

LookingGlassCalibration read_looking_glass_calibration(const std::string& path, std::vector<std::string>* warnings,
                                                       uint64_t max_bytes) {
  // A panel's calibration is a few KB; parsed, JSON takes about a hundred times its text, so a large
  // file is refused before it is read rather than parsed into gigabytes.
  constexpr uint64_t kMaxCalibrationBytes = uint64_t(1) << 20;
  std::error_code ec;
  const uint64_t size = std::filesystem::is_regular_file(path, ec) ? std::filesystem::file_size(path, ec) : 0;
  if (!ec && size > kMaxCalibrationBytes)
    throw Error(path + ": has " + std::to_string(size) +
                " bytes; a Looking Glass calibration file has a few thousand (at most 1 MiB is read)");
  const std::vector<unsigned char> file = read_user_file(path, std::min(max_bytes, kMaxCalibrationBytes));
  const std::string text(file.begin(), file.end());
  if (json_depth(text) > kMaxJsonDepth)
    throw Error(path + ": not a JSON calibration file (nested more than " + std::to_string(kMaxJsonDepth) +
                " levels deep)");
  json doc;
  try {
    doc = json::parse(text);
  } catch (const std::bad_alloc&) {  // not the file's fault
    throw Error(path + ": out of host memory while parsing it (" + std::to_string(text.size()) + " bytes)");
  } catch (const std::exception& e) {
    throw Error(path + ": not a JSON calibration file (" + std::string(e.what()).substr(0, 120) + ")");
  }
  if (!doc.is_object()) throw Error(path + ": not a JSON calibration file (expected an object)");
  LookingGlassCalibration c;
  c.checksum = checksum_hex(text.data(), text.size());
  c.path = path;
  if (doc.contains("serial") && doc["serial"].is_string()) c.serial = doc["serial"].get<std::string>();
  if (doc.contains("configVersion") && doc["configVersion"].is_string())
    c.config_version = doc["configVersion"].get<std::string>();
  c.pitch = number_field(doc, "pitch", path, true, 0);
  c.slope = number_field(doc, "slope", path, true, 0);
  c.center = number_field(doc, "center", path, true, 0);
  c.dpi = number_field(doc, "DPI", path, true, 0);
  c.view_cone = number_field(doc, "viewCone", path, false, 40.0);
  c.fringe = number_field(doc, "fringe", path, false, 0.0);
  const double w = number_field(doc, "screenW", path, true, 0), h = number_field(doc, "screenH", path, true, 0);
  c.flip_x = number_field(doc, "flipImageX", path, false, 0.0) >= 0.5;
  c.flip_y = number_field(doc, "flipImageY", path, false, 0.0) >= 0.5;
  c.flip_subp = number_field(doc, "flipSubp", path, false, 0.0) >= 0.5;
  c.inv_view = number_field(doc, "invView", path, false, 1.0) >= 0.5;
  auto absurd = [&](const char* field, const std::string& why) {
    throw Error(path + ": calibration field '" + field + "' " + why);
  };
  if (!(c.pitch > 0.0)) absurd("pitch", "must be positive (lenticules per inch)");
  if (c.slope == 0.0 || std::fabs(c.slope) > 1e6) absurd("slope", "must be non-zero");
  if (!(c.dpi > 0.0)) absurd("DPI", "must be positive");
  const std::string pixels = "must be a whole number of pixels in 1.." + std::to_string(kMaxDisplaySide);
  if (!(w >= 1 && w <= kMaxDisplaySide && w == std::floor(w))) absurd("screenW", pixels);
  if (!(h >= 1 && h <= kMaxDisplaySide && h == std::floor(h))) absurd("screenH", pixels);
  if (!(c.view_cone > 0.0 && c.view_cone < 180.0)) absurd("viewCone", "must be in (0, 180) degrees");
  c.screen_w = int(w), c.screen_h = int(h);
  if (doc.contains("subpixelCells") && !doc["subpixelCells"].is_null()) {
    const json& cells = doc["subpixelCells"];
    if (!cells.is_array() || cells.size() > 4) absurd("subpixelCells", "must be a list of at most 4 cells");
    const char* keys[6] = {"ROffsetX", "ROffsetY", "GOffsetX", "GOffsetY", "BOffsetX", "BOffsetY"};
    for (const json& cell : cells) {
      std::array<double, 6> v{};
      for (int k = 0; k < 6; ++k) {
        if (!cell.is_object() || !cell.contains(keys[k]) || !cell[keys[k]].is_number())
          absurd("subpixelCells", std::string("needs a number ") + keys[k] + " in every cell");
        v[size_t(k)] = cell[keys[k]].get<double>();
        if (!std::isfinite(v[size_t(k)]) || std::fabs(v[size_t(k)]) > 4.0)
          absurd("subpixelCells", "has an offset beyond 4 pixels");
      }
      c.cells.push_back(v);
    }
    // CellPatternMode as the Unity plugin reads it (capital C, else cellPatternMode)
    const char* mode_key = doc.contains("CellPatternMode") ? "CellPatternMode" : "cellPatternMode";
    const double mode = number_field(doc, mode_key, path, false, 0.0);
    if (!(mode >= 0 && mode <= 4 && mode == std::floor(mode))) absurd("CellPatternMode", "must be 0, 1, 2, 3 or 4");
    c.cell_pattern = int(mode);
  }
  if (warnings) {
    if (!c.inv_view)
      warnings->push_back(path + ": invView = 0 ignored, as Looking Glass's current shader (webxr 0.6) does");
    if (c.flip_y) warnings->push_back(path + ": flipImageY ignored, as Looking Glass's current shader does");
    if (c.fringe != 0.0) warnings->push_back(path + ": fringe ignored, as Looking Glass's current shader does");
  }
  return c;
}

Display display_from_calibration(const LookingGlassCalibration& c) {
  // The shader's uniforms, in double as LookingGlassConfig.ts computes them.
  const double W = c.screen_w, H = c.screen_h;
  const double sign = c.flip_x ? -1.0 : 1.0;
  const double pitch_px = c.pitch * W / c.dpi * std::cos(std::atan(1.0 / c.slope));
  const double tilt = H / (W * c.slope) * sign;
  // DESIGN section 5 (derivation in docs/DISPLAYS.md).
  const long double L = 3.0L * W / (long double)pitch_px;
  const long double T = (long double)W * tilt / H;
  const long double O =
      -1.5L + (c.flip_x ? 2.0L : 0.0L) - 3.0L * W * (long double)tilt * (H - 0.5L) / H + (long double)c.center * L;
  // Each field is checked alone when read; together they must give an encoder that exact arithmetic
  // holds (numerators and denominators below 2^62). Refused here, naming the file and its fields, not
  // later as an option (--lens-pitch, --offset) the user never gave.
  const std::string file = c.path.empty() ? std::string("the calibration") : c.path;
  auto out_of_range = [&](const char* fields, const char* what, long double value, const char* range) {
    char v[48];
    std::snprintf(v, sizeof v, "%.6Lg", value);
    throw Error(file + ": calibration fields " + fields + " give a " + what + " of " + v + ", outside " + range);
  };
  if (!(pitch_px > 0.0) || !std::isfinite(pitch_px) || !std::isfinite(tilt) || !(L >= 1e-3L && L <= 1e6L))
    out_of_range("pitch, DPI, slope and screenW", "lens pitch (3 DPI / (pitch cos(atan(1 / slope))))", L,
                 "0.001 to 1e6 subpixels");
  if (!(std::fabs(T) <= 1e6L)) out_of_range("slope, screenW and screenH", "lens slant (1 / slope)", T, "-1e6 to 1e6");
  // gen3 cells: the offset times 10^14 must fit 63 bits
  const long double max_offset = c.cells.empty() ? 1e15L : 9e4L;
  if (!(std::fabs(O) <= max_offset))
    out_of_range("center, pitch, DPI and slope", "subpixel offset (center x lens pitch, and the slant's share)", O,
                 c.cells.empty() ? "-1e15 to 1e15" : "-9e4 to 9e4 (with subpixelCells)");
  Display d;
  d.width = c.screen_w;
  d.height = c.screen_h;
  d.size_w_cm = W / c.dpi * 2.54;
  d.size_h_cm = H / c.dpi * 2.54;
  // Looking Glass software renders with a 14 degree vertical field of view (webxr's fovy default): the
  // viewing distance that gives it.
  d.viewing_distance_cm = 0.5 * d.size_h_cm / std::tan(7.0 * 3.14159265358979323846 / 180.0);
  d.lens_pitch = exact_decimal(L, "lens pitch (from the calibration)");
  d.tan_slant = exact_decimal(T, "slant (from the calibration)");
  d.offset = exact_decimal(O, "offset (from the calibration)");
  d.phase_sign = -1;
  d.subpixel_bgr = c.flip_subp != c.flip_x;
  if (!c.cells.empty()) {
    // Gen3: no per-channel subp term; channel k of a pixel in cell m sits at
    // ((j + 1/2 + dX) / W, (H - 1 - i + 1/2 + dY) / H), so its phase position is 3j and its offset
    // -3/2 - 3 dX - 3 W tilt (H - 1/2 + dY) / H + center L, as exact numerators over 10^14.
    static const int kRows[5] = {1, 2, 1, 4, 2};
    d.cell_rows = kRows[c.cell_pattern];
    d.subpixel_bgr = false;
    for (int row_class = 0; row_class < d.cell_rows; ++row_class)
      for (int xpar = 0; xpar < 2; ++xpar) {
        int cell = 0;  // GetCellForPixel with y mod cell_rows = row_class (y from the bottom), x mod 2 = xpar
        switch (c.cell_pattern) {
          case 1:
            cell = (xpar + row_class) % 2;
            break;
          case 2:
            cell = xpar;
            break;
          case 3:
            cell = (row_class + 2 * xpar) % 4;
            break;
          case 4:
            cell = row_class % 2;
            break;
          default:
            cell = 0;
        }
        const std::array<double, 6>& off = c.cells[size_t(cell) % c.cells.size()];
        for (int k = 0; k < 3; ++k) {
          const long double dx = off[size_t(2 * k)], dy = off[size_t(2 * k + 1)];
          const long double o =
              -1.5L - 3.0L * dx - 3.0L * W * (long double)tilt * (H - 0.5L + dy) / H + (long double)c.center * L;
          const long double scaled = std::round(o * 1e14L);
          if (!(std::fabs(scaled) < 9.0e18L))
            throw Error(file +
                        ": calibration fields center and subpixelCells give offsets too large for exact evaluation");
          d.cell_offsets.push_back(int64_t(scaled));
        }
      }
  }
  return d;
}

}  // namespace pmr
