// The previews' view transform (host/output/view_transform.h, docs/COLOUR.md): an OpenColorIO config
// written here, whose views the tests compute by hand (the sRGB curve after a channel-mixing matrix), so
// that no expected value comes from OpenColorIO or from pmr.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "output/view_transform.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

// Display "panel": Standard (the sRGB curve) and Mix (a matrix that mixes channels, then the curve);
// the look Half halves scene-linear colour.
const char* const kConfig = R"(ocio_profile_version: 2
roles:
  scene_linear: linear
  default: linear
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  panel:
    - !<View> {name: Standard, colorspace: srgb_out}
    - !<View> {name: Mix, colorspace: mix_out}
looks:
  - !<Look>
    name: Half
    process_space: linear
    transform: !<MatrixTransform> {matrix: [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1]}
colorspaces:
  - !<ColorSpace>
    name: linear
  - !<ColorSpace>
    name: srgb_out
    from_scene_reference: !<ExponentWithLinearTransform> {gamma: 2.4, offset: 0.055, direction: inverse}
  - !<ColorSpace>
    name: mix_out
    from_scene_reference: !<GroupTransform>
      children:
        - !<MatrixTransform> {matrix: [0.5, 0.5, 0, 0, 0, 1, 0, 0, 0.25, 0, 0.75, 0, 0, 0, 0, 1]}
        - !<ExponentWithLinearTransform> {gamma: 2.4, offset: 0.055, direction: inverse}
)";

// The Mix view with the Half look, by hand, as an 8-bit code.
double mix_half(const float rgb[3], int k) {
  const double r = 0.5 * rgb[0], g = 0.5 * rgb[1], b = 0.5 * rgb[2];
  const double mixed[3] = {0.5 * r + 0.5 * g, g, 0.25 * r + 0.75 * b};
  return 255.0 * srgb_encode(mixed[k]);
}

std::string write_config(const std::string& dir) {
  fs::create_directories(dir);
  const std::string path = dir + "/test.ocio";
  std::ofstream(path) << kConfig;
  return path;
}

TEST(ViewTransform, StandardIsTheSrgbCurveAndExposureAndGammaFollowBlender) {
  float px[4] = {0.02f, 0.18f, 0.9f, 1.0f};
  ViewTransformOptions o;
  o.exposure = 1.0, o.gamma = 2.0;
  const ViewTransform t(o);
  EXPECT_FALSE(t.is_standard());
  EXPECT_FALSE(t.mixes_channels());
  float out[4] = {px[0], px[1], px[2], px[3]};
  t.apply(out, 1);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], std::pow(srgb_encode(2.0 * px[c]), 0.5), 1e-6) << c;
  EXPECT_EQ(out[3], 1.0f);
  EXPECT_TRUE(ViewTransform().is_standard());
}

// Standard through the writer's table and through no transform at all: the same bytes, as before.
TEST(ViewTransform, TheDefaultWritesTheSamePngAsNoTransform) {
  const std::string dir = test::temp_dir("vt_default");
  fs::create_directories(dir);
  std::vector<uint16_t> px(64 * 4);
  for (size_t i = 0; i < px.size(); ++i) px[i] = half(float(i % 7) / 5.0f * (i % 4 == 3 ? 0.3f : 1.0f)).bits();
  const ViewTransform standard;
  write_png_preview(dir + "/a.png", 8, 8, px.data(), 1.0, false);
  write_png_preview(dir + "/b.png", 8, 8, px.data(), 1.0, false, &standard);
  std::ifstream a(dir + "/a.png", std::ios::binary), b(dir + "/b.png", std::ios::binary);
  std::stringstream sa, sb;
  sa << a.rdbuf(), sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
}

TEST(ViewTransform, BadConfigsAndNamesAreOneLineErrors) {
  const std::string dir = test::temp_dir("vt_errors");
  const std::string config = write_config(dir);
  const std::string small = " --views 4 --view-size 32x16 --display 64x36 --preview --out " + dir + "/out";
  const test::CliRun missing = test::run("render --ocio " + dir + "/none.ocio" + small);
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1) << missing.output;
  EXPECT_NE(missing.output.find("none.ocio"), std::string::npos) << missing.output;
  const test::CliRun view = test::run("render --ocio " + config + " --view Filmic" + small);
  EXPECT_EQ(view.status, 2) << view.output;
  EXPECT_EQ(std::count(view.output.begin(), view.output.end(), '\n'), 1) << view.output;
  EXPECT_NE(view.output.find("'Standard', 'Mix'"), std::string::npos) << view.output;
  const test::CliRun look = test::run("render --ocio " + config + " --look Sharp" + small);
  EXPECT_EQ(look.status, 2) << look.output;
  EXPECT_NE(look.output.find("'Half'"), std::string::npos) << look.output;
  const test::CliRun no_config = test::run("render --view Mix" + small);
  EXPECT_EQ(no_config.status, 2) << no_config.output;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// Every view's colour is transformed before the encoder picks its channel: each panel-PNG subpixel is
// channel k of its view's transformed colour (the views EXR, over black), within one 8-bit code; the
// quilt PNG is each view's straight colour transformed. The sidecar records the transform.
TEST(ViewTransform, PanelAndQuiltPreviewsAreTheTransformedViews) {
  const std::string dir = test::temp_dir("vt_panel");
  const std::string config = write_config(dir);
  const int views = 6, vw = 64, vh = 32, dw = 240, dh = 135;
  const test::CliRun r = test::run(
      "render --views 6 --view-size 64x32 --display 240x135 --sampling view "
      "--write encoded,views,quilt --quilt 3x2 --preview -q --ocio " +
      config + " --view Mix --look Half --out " + dir + "/out");
  ASSERT_EQ(r.status, 0) << r.output;
  std::vector<std::vector<uint16_t>> volume(views);
  for (int v = 0; v < views; ++v) {
    int w = 0, h = 0;
    read_views_exr_part(dir + "/out/frame_0000.views.exr", v, w, h, volume[size_t(v)]);
    ASSERT_EQ(w, vw);
    ASSERT_EQ(h, vh);
  }
  int pw = 0, ph = 0;
  std::vector<uint8_t> panel;
  read_png_rgba8(dir + "/out/frame_0000.png", pw, ph, panel);
  ASSERT_EQ(pw, dw);
  ASSERT_EQ(ph, dh);
  std::ifstream sj(dir + "/out/frame_0000.json");
  std::stringstream text;
  text << sj.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str());
  Display display;  // paper-8k's, at the size asked for, with the offset the CLI chooses
  display.width = dw, display.height = dh;
  display.offset = default_offset(display.lens_pitch, views);
  double worst = 0.0;
  size_t lit = 0;
  for (int i = 0; i < dh; ++i)
    for (int jx = 0; jx < dw; ++jx)
      for (int k = 0; k < 3; ++k) {
        const int v = encode_view_index(display, views, jx, i, k);
        const double u = (jx + (k + 0.5) / 3.0) / dw, t = (i + 0.5) / dh;
        const size_t at = (size_t(std::floor(t * vh)) * vw + size_t(std::floor(u * vw))) * 4;
        const float rgb[3] = {test::half_value(volume[size_t(v)][at]), test::half_value(volume[size_t(v)][at + 1]),
                              test::half_value(volume[size_t(v)][at + 2])};
        const double want = mix_half(rgb, k);
        worst = std::max(worst, std::abs(double(panel[(size_t(i) * dw + jx) * 4 + size_t(k)]) - want));
        lit += want > 8.0;
      }
  EXPECT_LE(worst, 1.0);
  EXPECT_GT(lit, size_t(dw) * dh / 10) << "the scene should be seen";
  std::vector<uint8_t> quilt;
  read_png_rgba8(dir + "/out/" + j["outputs"]["preview_quilt"].get<std::string>(), pw, ph, quilt);
  ASSERT_EQ(pw, 3 * vw);
  double quilt_worst = 0.0;
  for (int v = 0; v < views; ++v)
    for (int y = 0; y < vh; ++y)
      for (int x = 0; x < vw; ++x) {
        const uint16_t* p = &volume[size_t(v)][(size_t(y) * vw + x) * 4];
        const float a = test::half_value(p[3]), s = a > 0.0f && a < 1.0f ? 1.0f / a : 1.0f;
        const float rgb[3] = {test::half_value(p[0]) * s, test::half_value(p[1]) * s, test::half_value(p[2]) * s};
        const size_t q = size_t((1 - v / 3) * vh + y) * size_t(pw) + size_t((v % 3) * vw + x);
        for (int k = 0; k < 3; ++k)
          if (quilt[q * 4 + 3] > 0)
            quilt_worst = std::max(quilt_worst, std::abs(double(quilt[q * 4 + size_t(k)]) - mix_half(rgb, k)));
      }
  EXPECT_LE(quilt_worst, 1.0);
  const nlohmann::json& vt = j["view_transform"];
  EXPECT_EQ(vt["config"], config);
  EXPECT_EQ(vt["display"], "panel");
  EXPECT_EQ(vt["view"], "Mix");
  EXPECT_EQ(vt["look"], "Half");
  EXPECT_EQ(vt["colorspace"], "linear");
}

}  // namespace
}  // namespace pmr
