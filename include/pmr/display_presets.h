// Real displays (docs/DISPLAYS.md): the paper's 8K panel and Looking Glass panels, as presets and from a
// Looking Glass calibration file ("visual.json"), mapped onto DESIGN section 5's encoder.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "pmr/input_files.h"
#include "pmr/rig.h"

namespace pmr {

// A Looking Glass calibration as the panel's visual.json stores it (each field {"value": x}).
struct LookingGlassCalibration {
  std::string serial, config_version;
  double pitch = 0, slope = 0, center = 0, dpi = 0, view_cone = 0, fringe = 0;
  int screen_w = 0, screen_h = 0;
  bool flip_x = false, flip_y = false, flip_subp = false, inv_view = true;
  // Gen3 panels: subpixel cells, each {R, G, B} x {X, Y} offsets in pixels, and the pattern that
  // assigns a cell to each pixel (CellPatternMode 0..4).
  std::vector<std::array<double, 6>> cells;
  int cell_pattern = 0;
  std::string checksum;  // XXH3-64 of the file's bytes as read (output/checksum.h), 16 hex digits
  std::string path;      // the file as given, for messages about values derived from it
};

// Reads and checks a visual.json: one clear pmr::Error naming the file and the field on anything
// missing, non-numeric or absurd (zero DPI or slope, NaN, non-positive or huge screen size, malformed
// subpixelCells or CellPatternMode, which gen3 panels carry).
// `warnings` receives what is read but ignored (invView = 0, flipImageY, fringe, verticalAngle).
// The file must be a regular file of at most `max_bytes` (the file-bytes budget): a FIFO or /dev/zero
// is refused, not read.
LookingGlassCalibration read_looking_glass_calibration(const std::string& path, std::vector<std::string>* warnings,
                                                       uint64_t max_bytes = InputLimits().file_bytes);

// The display in DESIGN terms for a calibration (pmr::Error naming the file and its fields when the
// values, each plausible alone, give a lens pitch, slant or offset out of range), following Looking Glass's current interlacing shader
// (looking-glass-webxr 0.6 / holoplay-core 0.0.11): pitch' = pitch W / DPI cos(atan(1 / slope)) and
// tilt = H / (W slope) computed in double as LookingGlassConfig.ts does (both negated with flipImageX,
// as is subp), then exactly: L = 3W / pitch', tan = W tilt / H, offset = -1.5 (+2 when flipped)
// - 3W tilt (H - 1/2) / H + center L, phase_sign -1 (the shader's 1 - fract), subpixel_bgr = flipSubp
// xor flipImageX (flipSubp as the HoloPlay / Unity shaders swap red and blue). Size from the DPI.
Display display_from_calibration(const LookingGlassCalibration& c);

// Where a job's display came from, as its sidecars record it: a preset (the default paper-8k unless
// --preset names another) or a calibration file, whose values are recorded as read.
struct DisplaySource {
  std::string name = "preset paper-8k";  // "preset NAME" or "calibration FILE"
  std::optional<LookingGlassCalibration> calibration;
};

struct DisplayPreset {
  std::string name, description;
  Display display;
  RigConfig rig;      // views, view raster, cone, yfov as the maker recommends
  std::string quilt;  // the maker's quilt layout "CxR"
  // The default --sampling: subpixel where it measured at least twice as accurate for at most 1.5x the
  // time of view sampling (docs/SAMPLING.md).
  bool subpixel_sampling = false;
};

// Every preset, paper-8k first (the default).
const std::vector<DisplayPreset>& display_presets();
// Throws pmr::Error listing the names when there is no such preset.
const DisplayPreset& find_display_preset(const std::string& name);
// The text of `pmr render --preset help`.
std::string display_presets_help();

}  // namespace pmr
