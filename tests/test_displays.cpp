// Real displays: Looking Glass calibrations against an independent evaluation of Looking Glass's own
// interlacing shader (looking-glass-webxr 0.6 / holoplay-core 0.0.11, BGR as the HoloPlay / Unity
// shaders swap red and blue), subpixel by subpixel through the encode kernel; every preset shows every
// view; malformed calibration files get one clear error naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <Imath/half.h>

#include "pmr/display_presets.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

// The shader, written from its GLSL (not from the encoder's derivation): for display pixel (px, py),
// py from the top, and output channel c, the view index it picks with filter_mode 0. Returns -1 where
// (1 - fract) * N lies within 1e-9 of a whole number (a tie that float evaluation cannot settle).
// The shader's phase for output channel c of display pixel (px, py), py from the top.
long double shader_phase(const LookingGlassCalibration& cal, int px, int py, int c) {
  const double W = cal.screen_w, H = cal.screen_h;
  // LookingGlassConfig.ts, in double
  const double pitch = cal.pitch * W / cal.dpi * std::cos(std::atan(1.0 / cal.slope));
  const double tilt = H / (W * cal.slope) * (cal.flip_x ? -1 : 1);
  const long double subp = 1.0L / (W * 3.0L) * (cal.flip_x ? -1 : 1);
  // the fragment's texture coordinate: texel center, v from the bottom
  const long double u = (px + 0.5L) / W, v = (H - 1 - py + 0.5L) / H;
  if (cal.cells.empty()) {
    // BGR panels: red takes the phase of subpixel offset 2 and blue of offset 0 (ri, bi = 2, 0)
    const int offset = cal.flip_subp ? 2 - c : c;
    return (u + offset * subp + v * (long double)tilt) * (long double)pitch - cal.center;
  }
  // GetCellForPixel and GetSubpixelViews with subpixel cells (pattern from the calibration)
  const int x = px, y = cal.screen_h - 1 - py;
  int cell = 0;
  switch (cal.cell_pattern) {
    case 1:
      cell = ((y % 2 == 0 && x % 2 == 0) || (y % 2 != 0 && x % 2 != 0)) ? 0 : 1;
      break;
    case 2:
      cell = x % 2;
      break;
    case 3:
      cell = (y + (x % 2) * 2) % 4;
      break;
    case 4:
      cell = y % 2;
      break;
    default:
      cell = 0;
  }
  const std::array<double, 6>& off = cal.cells[size_t(cell) % cal.cells.size()];
  const long double du = off[size_t(2 * c)] / W, dv = off[size_t(2 * c + 1)] / H;
  return ((u + du) + (v + dv) * (long double)tilt) * (long double)pitch - cal.center;
}

// The shader's continuous view coordinate a N, a = 1 - fract(phase) clamped as the shader clamps it.
long double shader_view_coordinate(const LookingGlassCalibration& cal, int views, int px, int py, int c) {
  const long double phase = shader_phase(cal, px, py, c);
  long double a = 1.0L - (phase - std::floor(phase));
  a = std::min(std::max(a, 0.00001L), 0.999999L);
  return a * views;
}

// The shader, written from its GLSL (not from the encoder's derivation): the view index it picks with
// filter_mode 0 for display pixel (px, py), py from the top, and output channel c. Returns -1 where
// (1 - fract) * N lies within 1e-9 of a whole number (a tie that float evaluation cannot settle).
int shader_view(const LookingGlassCalibration& cal, int views, int px, int py, int c) {
  const long double z = shader_view_coordinate(cal, views, px, py, c);
  if (std::fabs(z - std::round(z)) < 1e-9L) return -1;
  return int(std::floor(z));
}

LookingGlassCalibration small_panel(double slope, bool flip_x, bool flip_subp) {
  LookingGlassCalibration c;
  c.screen_w = 120, c.screen_h = 90;
  c.dpi = 324;  // the Portrait's: about 18 subpixels per lens with pitch 52
  c.pitch = 52.09813690185547;
  c.slope = slope;
  c.center = 0.5658454895019531;
  c.flip_x = flip_x, c.flip_subp = flip_subp;
  return c;
}

// A gen3 panel's calibration (the 16" Spatial's cells as Looking Glass Bridge stores them) on a small
// screen.
LookingGlassCalibration gen3_panel(int pattern, bool flip_x) {
  LookingGlassCalibration c = small_panel(-6.874565686767793, flip_x, false);
  c.pitch = 44.75058319896644;
  c.dpi = 283;
  c.center = 0.16935753461833172;
  c.cells = {{-0.3100000023841858, 0.25, 0.2800000011920929, 0.25, 0.0, -0.25},
             {-0.3100000023841858, -0.25, 0.2800000011920929, -0.25, 0.0, 0.25}};
  if (pattern == 3)
    c.cells.push_back({0.1, 0.2, -0.2, 0.1, 0.3, -0.1}), c.cells.push_back({0.0, 0.0, 0.1, 0.1, -0.1, 0.2});
  c.cell_pattern = pattern;
  return c;
}

void write_file(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace

TEST(Displays, CalibrationMatchesTheLookingGlassShaderSubpixelBySubpixel) {
  struct Case {
    const char* name;
    LookingGlassCalibration cal;
    int views;
  };
  const Case cases[] = {
      {"Portrait-like", small_panel(-7.134567737579346, false, false), 48},
      {"flipImageX", small_panel(-7.134567737579346, true, false), 48},
      {"BGR (flipSubp)", small_panel(-7.134567737579346, false, true), 48},
      {"flipped BGR", small_panel(-7.134567737579346, true, true), 45},
      {"positive slope", small_panel(6.3, false, false), 66},
      {"gen3 cells, pattern 2", gen3_panel(2, false), 49},
      {"gen3 cells, pattern 1 (checkerboard)", gen3_panel(1, false), 49},
      {"gen3 cells, pattern 3, flipped", gen3_panel(3, true), 66},
      {"gen3 cells, pattern 4", gen3_panel(4, false), 66},
  };
  for (const Case& t : cases) {
    SCOPED_TRACE(t.name);
    const Display d = display_from_calibration(t.cal);
    const std::vector<int> got = test::encoded_view_indices(d, t.views, 16, 12);
    size_t ties = 0, checked = 0;
    for (int py = 0; py < d.height; ++py)
      for (int px = 0; px < d.width; ++px)
        for (int c = 0; c < 3; ++c) {
          const int want = shader_view(t.cal, t.views, px, py, c);
          if (want < 0) {
            ++ties;
            continue;
          }
          ASSERT_EQ(got[(size_t(py) * d.width + px) * 3 + size_t(c)], want)
              << "pixel " << px << "," << py << " channel " << c;
          ++checked;
        }
    EXPECT_EQ(ties, 0u);
    EXPECT_EQ(checked, size_t(d.width) * d.height * 3);
  }
}

// --blend-views: with every channel of view v holding v, each subpixel shows v + w (w the phase's
// fraction), i.e. the shader's continuous view coordinate a N, up to half precision (the last view
// stands in for view N).
TEST(Displays, BlendedViewsFollowTheContinuousPhase) {
  const LookingGlassCalibration cal = small_panel(-7.134567737579346, false, true);
  Display d = display_from_calibration(cal);
  d.blend_views = true;
  const int views = 48;
  RigConfig rc;
  rc.views = views, rc.view_w = 16, rc.view_h = 12;
  const Rig rig = make_rig(rc, d, glm::dvec3(-1), glm::dvec3(1));
  Pipeline p(test::runtime(), PipelineConfig{});
  p.set_scene(test::random_scene(1, 1, false));
  p.configure(rig, &d);
  const size_t plane = size_t(16) * 12;
  std::vector<uint16_t> vol(plane * views * 4), enc;
  for (int v = 0; v < views; ++v)
    for (size_t x = 0; x < plane * 4; ++x) vol[size_t(v) * plane * 4 + x] = half(float(v)).bits();
  p.encode_volume(vol);
  p.read_display(enc);
  size_t blended = 0;
  for (int py = 0; py < d.height; ++py)
    for (int px = 0; px < d.width; ++px)
      for (int c = 0; c < 3; ++c) {
        const int v = shader_view(cal, views, px, py, c);
        if (v < 0) continue;
        const long double z = shader_view_coordinate(cal, views, px, py, c);
        half h;
        h.setBits(enc[(size_t(py) * d.width + px) * 4 + size_t(c)]);
        const double want = v == views - 1 ? double(views - 1) : double(z);
        ASSERT_NEAR(float(h), want, 0.04) << "pixel " << px << "," << py << " channel " << c;
        blended += std::fabs(want - v) > 0.1;
      }
  EXPECT_GT(blended, size_t(d.width) * d.height);  // most subpixels really mix two views
}

TEST(Displays, EveryPresetShowsEveryView) {
  for (const DisplayPreset& p : display_presets()) {
    SCOPED_TRACE(p.name);
    const std::vector<int> v = test::table_view_indices(p.display, p.rig.views);
    std::vector<bool> seen(size_t(p.rig.views), false);
    for (int x : v) seen[size_t(x)] = true;
    for (int i = 0; i < p.rig.views; ++i) EXPECT_TRUE(seen[size_t(i)]) << "view " << i << " never shown";
    // and a rig can be built for it (guard band, cone)
    EXPECT_NO_THROW(make_rig(p.rig, p.display, glm::dvec3(-1), glm::dvec3(1)));
    // the default sampling docs/SAMPLING.md chose from measurements ("Which default")
    const bool chosen_subpixel =
        p.name == "lg-portrait" || p.name == "lg-go" || p.name == "lg-16" || p.name == "lg-16-portrait";
    EXPECT_EQ(p.subpixel_sampling, chosen_subpixel);
  }
  EXPECT_THROW(find_display_preset("lg-99"), Error);
}

// A calibration file is a few KB: a 30 MB one (parsed, about a hundred times that) is refused from its
// size before it is read, in one line.
TEST(Displays, AHugeCalibrationFileIsRefusedBeforeItIsParsed) {
  const std::string dir = test::temp_dir("calibration_huge");
  fs::create_directories(dir);
  write_file(dir + "/visual.json", "[" + std::string(30000000, ' ') + "]");
  try {
    read_looking_glass_calibration(dir + "/visual.json", nullptr, uint64_t(1) << 40);
    ADD_FAILURE() << "a 30 MB calibration file was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has 30000002 bytes; a Looking Glass calibration file has a few thousand"),
              std::string::npos)
        << e.what();
  }
}

TEST(Displays, MalformedCalibrationFilesFailNamingTheField) {
  const std::string dir = test::temp_dir("calibration");
  fs::create_directories(dir);
  const std::string good = R"({"serial": "LKG-P0", "pitch": {"value": 52.1}, "slope": {"value": -7.1},
    "center": {"value": 0.56}, "DPI": {"value": 324}, "screenW": {"value": 1536}, "screenH": {"value": 2048},
    "viewCone": {"value": 40}, "flipImageX": {"value": 0}, "flipSubp": {"value": 0}, "invView": {"value": 1}})";
  write_file(dir + "/good.json", good);
  const LookingGlassCalibration c = read_looking_glass_calibration(dir + "/good.json", nullptr);
  EXPECT_EQ(c.screen_w, 1536);
  EXPECT_EQ(c.serial, "LKG-P0");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  const std::pair<std::string, std::string> bad[] = {
      {with(R"("DPI": {"value": 324})", R"("DPI": {"value": 0})"), "'DPI'"},
      {with(R"("slope": {"value": -7.1})", R"("slope": {"value": 0})"), "'slope'"},
      {with(R"("pitch": {"value": 52.1},)", ""), "'pitch' is missing"},
      {with(R"("center": {"value": 0.56})", R"("center": {"value": "x"})"), "'center' is not a number"},
      {with(R"("screenW": {"value": 1536})", R"("screenW": {"value": 0})"), "'screenW'"},
      {with(R"("screenH": {"value": 2048})", R"("screenH": {"value": 20.5})"), "'screenH'"},
      {with(R"("center": {"value": 0.56})", R"("center": {"value": NaN})"), "not a JSON"},
      {with(R"("serial": "LKG-P0",)", R"("subpixelCells": [{"ROffsetX": 0.1}],)"), "'subpixelCells' needs a number"},
      {with(R"("serial": "LKG-P0",)", R"("CellPatternMode": {"value": 7}, "subpixelCells": [],)"), "'CellPatternMode'"},
      {"[1, 2]", "expected an object"},
  };
  for (const auto& [text, fragment] : bad) {
    write_file(dir + "/bad.json", text);
    try {
      read_looking_glass_calibration(dir + "/bad.json", nullptr);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_looking_glass_calibration(dir + "/absent.json", nullptr), Error);
  // through the CLI: one line, exit 1
  write_file(dir + "/bad.json", with(R"("DPI": {"value": 324})", R"("DPI": {"value": 0})"));
  test::expect_one_error_line(test::run("render --display-config " + dir + "/bad.json --out " + dir + "/o"), "'DPI'");
}

// A panel's calibration file and a preset through the CLI: the model's views and quilt, the calibration
// in the sidecar.
TEST(Displays, CliRendersForALookingGlassPanel) {
  const std::string dir = test::temp_dir("lg_cli");
  fs::create_directories(dir);
  write_file(dir + "/visual.json", R"({"serial": "LKG-P0", "pitch": {"value": 52.1}, "slope": {"value": -7.1},
    "center": {"value": 0.56}, "DPI": {"value": 324}, "screenW": {"value": 1536}, "screenH": {"value": 2048},
    "viewCone": {"value": 40}, "invView": {"value": 0}})");
  const test::CliRun r = test::run("render --display-config " + dir +
                                   "/visual.json --view-size 42x56 --write encoded,quilt --out " + dir + "/o");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("invView = 0 ignored"), std::string::npos) << r.output;
  // the calibration's offset reaches the encoder (not the generic -L / 2N)
  const Display want = display_from_calibration(read_looking_glass_calibration(dir + "/visual.json", nullptr));
  const std::string sidecar = test::read_file(dir + "/o/frame_0000.json");
  EXPECT_NE(sidecar.find("\"offset_fraction\": \"" + to_string(want.offset) + "\""), std::string::npos) << sidecar;
  // an LKG-P panel renders as its preset does: angular spacing through PMR, subpixel sampling
  EXPECT_NE(sidecar.find("\"camera_spacing\": \"angular\""), std::string::npos);
  EXPECT_NE(sidecar.find("\"method\": \"pmr\""), std::string::npos);
  EXPECT_NE(sidecar.find("\"sampling\": \"subpixel\""), std::string::npos);
  EXPECT_EQ(r.output.find("multipass"), std::string::npos) << r.output;
  const test::CliRun pr = test::run("render --preset lg-portrait --view-size 42x56 --out " + dir + "/p");
  ASSERT_EQ(pr.status, 0) << pr.output;
  EXPECT_NE(test::read_file(dir + "/p/frame_0000.json")
                .find("\"offset_fraction\": \"" + to_string(find_display_preset("lg-portrait").display.offset) + "\""),
            std::string::npos);
  EXPECT_TRUE(test::exists(dir + "/o/frame_0000_qs8x6a0.75.exr")) << r.output;
  const test::CliRun h = test::run("render --preset help");
  EXPECT_EQ(h.status, 0);
  for (const DisplayPreset& p : display_presets()) EXPECT_NE(h.output.find(p.name), std::string::npos);
  test::expect_usage_error(test::run("render --preset lg-99 --out " + dir + "/o"), "lg-portrait");
  test::expect_usage_error(
      test::run("render --preset lg-portrait --display-config " + dir + "/visual.json --out " + dir + "/o"), "once");
}

}  // namespace pmr

namespace pmr {

// A gen3 calibration whose cells depend on the column only (pattern 2) keeps the fused raster+encode
// path; its image equals the separate raster-then-encode path's bit for bit. Pattern 1 (row classes)
// falls back to the separate path and renders too.
TEST(Displays, Gen3CalibrationRendersFusedAndSeparateAlike) {
  const std::string dir = test::temp_dir("lg_gen3");
  fs::create_directories(dir);
  for (int pattern : {2, 1}) {
    const std::string cal = dir + "/visual" + std::to_string(pattern) + ".json";
    write_file(cal, R"({"configVersion": "3.0", "serial": "LKG-J00332", "pitch": {"value": 44.75058319896644},
      "slope": {"value": -6.874565686767793}, "center": {"value": 0.16935753461833172}, "viewCone": {"value": 50.0},
      "DPI": {"value": 283.0}, "screenW": {"value": 384.0}, "screenH": {"value": 216.0}, "flipImageX": {"value": 0.0},
      "CellPatternMode": {"value": )" +
                        std::to_string(pattern) + R"(.0}, "subpixelCells": [
        {"ROffsetX": -0.31, "ROffsetY": 0.25, "GOffsetX": 0.28, "GOffsetY": 0.25, "BOffsetX": 0.0, "BOffsetY": -0.25},
        {"ROffsetX": -0.31, "ROffsetY": -0.25, "GOffsetX": 0.28, "GOffsetY": -0.25, "BOffsetX": 0.0, "BOffsetY": 0.25}]})");
    const std::string a = dir + "/fused" + std::to_string(pattern), b = dir + "/separate" + std::to_string(pattern);
    const std::string common = " --display-config " + cal + " --view-size 96x96 ";
    ASSERT_EQ(test::run("render" + common + "--out " + a).status, 0);
    ASSERT_EQ(test::run("render" + common + "--write encoded,views --out " + b).status, 0);
    int w = 0, h = 0;
    std::vector<uint16_t> x, y;
    read_rgba_exr(a + "/frame_0000.exr", w, h, x);
    read_rgba_exr(b + "/frame_0000.exr", w, h, y);
    EXPECT_EQ(x, y) << "pattern " << pattern;
    size_t covered = 0;
    for (size_t i = 3; i < x.size(); i += 4) covered += x[i] != 0;
    EXPECT_GT(covered, x.size() / 4 / 20) << "pattern " << pattern;
  }
}

}  // namespace pmr

namespace pmr {

// Angular camera spacing (the Looking Glass convention): the offsets are D tan(cone ((i + 1/2) / N -
// 1/2)) moved onto the view-coordinate grid (at most 1/(2Q) of a view spacing), and every rendered view
// (PMR, and multipass with each view's own matrices) puts a small square where that view's sidecar
// matrices project it, in front of and behind the focal plane.
TEST(Displays, AngularSpacingViewsMatchTheirMatrices) {
  Scene s = test::empty_scene(true);
  const float h = 0.1f;
  for (const auto& [x, z] : std::vector<std::pair<float, float>>{{-0.5f, 0.6f}, {0.5f, -0.6f}}) {
    test::add_triangle(s, {x - h, -h, z}, {x + h, -h, z}, {x + h, h, z});
    test::add_triangle(s, {x - h, -h, z}, {x + h, h, z}, {x - h, h, z});
  }
  RigConfig rc;
  rc.views = 8, rc.view_w = 256, rc.view_h = 128;
  rc.cone_deg = 40;
  rc.angular_spacing = true;
  const Display d;
  const Rig rig = make_rig(rc, d, glm::dvec3(-1), glm::dvec3(1));
  const double spacing = rig.baseline() / (rig.views - 1);
  ASSERT_GT(rig.spacing_q, 1);
  for (int i = 0; i < rig.views; ++i) {
    const double exact = rig.focal * std::tan(rig.cone * ((i + 0.5) / 8.0 - 0.5));
    EXPECT_DOUBLE_EQ(rig.angular_offset(i), exact);
    EXPECT_LE(std::abs(rig.camera_offset(i) - exact), spacing / (2.0 * rig.spacing_q) * (1 + 1e-9)) << "view " << i;
    EXPECT_DOUBLE_EQ(rig.camera_offset(i), spacing * rig.view_coord(i) / rig.spacing_q);
    EXPECT_DOUBLE_EQ(rig.camera_offset(rig.views - 1 - i), -rig.camera_offset(i));  // symmetric
  }
  for (Method method : {Method::Pmr, Method::Multipass}) {
    SCOPED_TRACE(to_string(method));
    PipelineConfig pc;
    pc.method = method;
    Pipeline p(test::runtime(), pc);
    p.set_scene(s);
    p.configure(rig, nullptr);
    p.render(rig);
    std::vector<uint16_t> vol;
    p.read_volume(vol);
    const size_t plane = size_t(rig.view_w) * rig.view_h;
    double first_px[2] = {0, 0}, shift = 0;
    for (int i = 0; i < rig.views; ++i)
      for (const float x : {-0.5f, 0.5f}) {
        const float z = x < 0 ? 0.6f : -0.6f;
        const glm::dvec4 c = rig.projection(i) * rig.view_matrix(i) * glm::dvec4(x, 0, z, 1);
        const double px = (c.x / c.w + 1) / 2 * rig.view_w, py = (1 - c.y / c.w) / 2 * rig.view_h;
        // centroid of the covered pixels near the expected position
        double sx = 0, sy = 0, n = 0;
        for (int y = 0; y < rig.view_h; ++y)
          for (int xx = 0; xx < rig.view_w; ++xx) {
            if (std::abs(xx + 0.5 - px) > 16 || std::abs(y + 0.5 - py) > 16) continue;
            if (vol[(size_t(i) * plane + size_t(y) * rig.view_w + size_t(xx)) * 4 + 3] == 0) continue;
            sx += xx + 0.5, sy += y + 0.5, n += 1;
          }
        ASSERT_GT(n, 4) << "view " << i << " square " << x;
        EXPECT_NEAR(sx / n, px, 0.5) << "view " << i << " square " << x;
        EXPECT_NEAR(sy / n, py, 0.5) << "view " << i << " square " << x;
        if (i == 0) first_px[x > 0] = px;
        if (i == rig.views - 1) shift += std::abs(px - first_px[x > 0]);
      }
    EXPECT_GT(shift, 1.0);  // the squares off the focal plane do move between views
  }
}

}  // namespace pmr

namespace pmr {

// Angular spacing on fixed-point view coordinates: for every preset framing a scene as the CLI does,
// each camera lies within 1/(2Q) of a view spacing of its exact Looking Glass position, and that moves
// no point of the depth range [near, far] by more than kSpacingErrorPx view pixels of disparity
// (checked here from the cameras themselves: the disparity of the worst camera at both ends of the
// range); the view coordinates increase and stay within PMR_MAX_VIEW_COORD. Linear spacing is exact.
TEST(Displays, AngularSpacingQuantizationStaysWithinTheBound) {
  for (const DisplayPreset& preset : display_presets())
    for (bool angular : test::kSpacings) {
      SCOPED_TRACE(preset.name + ", " + test::spacing_name(angular));
      RigConfig rc = preset.rig;
      rc.angular_spacing = angular;
      const Rig rig = make_rig(rc, preset.display, glm::dvec3(-1.0, -0.5, -2.0), glm::dvec3(1.5, 0.5, 1.0));
      const double spacing = rig.baseline() / (rig.views - 1);
      double worst = 0.0;
      for (int i = 0; i < rig.views; ++i) {
        const double moved =
            std::abs(rig.camera_offset(i) -
                     (angular ? rig.angular_offset(i) : (double(i) / (rig.views - 1) - 0.5) * rig.baseline()));
        EXPECT_LE(moved, spacing / (2.0 * rig.spacing_q) * (1.0 + 1e-9)) << "view " << i;
        worst = std::max(worst, moved / spacing);
        EXPECT_LE(std::abs(rig.view_coord(i)), PMR_MAX_VIEW_COORD);
        if (i > 0) {
          EXPECT_GT(rig.view_coord(i), rig.view_coord(i - 1));
        }
        if (!angular) {
          EXPECT_EQ(rig.view_coord(i), i);
        }
      }
      // a camera moved by m view spacings shifts a point at depth w by m Delta(w) / (N - 1) view pixels
      const double px = worst *
                        std::max(std::abs(rig.disparity_px(rig.near_eff)), std::abs(rig.disparity_px(rig.far))) /
                        (rig.views - 1);
      EXPECT_LE(px, kSpacingErrorPx);
      EXPECT_NEAR(spacing_error(rig).view_px, px, 1e-12);
      if (!angular) {
        EXPECT_EQ(rig.spacing_q, 1);
      }
      if (angular) {
        EXPECT_GT(worst, 0.0) << "the exact angular positions are not on the grid";
        // the numbers the docs quote: view spacings, and display pixels at the cone's edge
        const double display_px = px * double(preset.display.width) / rig.view_w;
        std::printf("  %-16s Q %4d, |F| <= %5d: cameras moved <= %.5f view spacings = %.4f view px = %.4f display px\n",
                    preset.name.c_str(), rig.spacing_q, rig.view_coord(rig.views - 1), worst, px, display_px);
      }
    }
}

}  // namespace pmr
