// Quilts (Looking Glass convention), depth channels and PNG previews: layouts, the name as Looking
// Glass software parses it, every tile equal to its view bit for bit, view-space depth of a plane at a
// known distance, and PNGs that decode to the EXR's values through the sRGB curve.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/quilt.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::run;
using test::temp_dir;

float half_value(uint16_t bits) {
  half h;
  h.setBits(bits);
  return float(h);
}

}  // namespace

TEST(Quilt, LayoutsFollowTheLookingGlassConventions) {
  auto layout = [](int n, int w, int h) {
    const QuiltLayout l = choose_quilt_layout(n, w, h);
    return std::to_string(l.columns) + "x" + std::to_string(l.rows);
  };
  EXPECT_EQ(layout(48, 420, 560), "8x6");                      // Looking Glass Portrait's standard quilt, 3360x3360
  EXPECT_EQ(layout(45, 819, 455), "5x9");                      // the 16" panels' standard quilt, 4095x4095
  EXPECT_EQ(layout(96, 1024, 512), "8x12");                    // 8192x6144
  EXPECT_EQ(layout(8, 1024, 512), "2x4");                      // square
  const QuiltLayout prime = choose_quilt_layout(7, 100, 100);  // no exact near-square factorization
  EXPECT_GE(prime.columns * prime.rows, 7);
  EXPECT_LE(prime.columns * prime.rows, 9);
  EXPECT_THROW(choose_quilt_layout(96, 4096, 2048), Error);  // over 16384 px whatever the layout
  EXPECT_EQ(parse_quilt_layout("6x8", 48, 420, 560).columns, 6);
  for (const char* bad : {"8", "8x", "x6", "0x6", "8x5", "8x6x2", "axb"})
    EXPECT_THROW(parse_quilt_layout(bad, 48, 420, 560), Error) << bad;
  try {
    parse_quilt_layout("96x1", 96, 1024, 512);
    ADD_FAILURE() << "a 98304-px-wide quilt was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("8x12"), std::string::npos) << e.what();  // suggests a layout that fits
  }
}

// Looking Glass software finds the layout with a pattern like qs(\d+)x(\d+)a(\d+(\.\d+)?).
TEST(Quilt, NameParsesAsLookingGlassSoftwareParsesIt) {
  const std::regex lg("_qs(\\d+)x(\\d+)a(\\d+(?:\\.\\d+)?)");
  for (double aspect : {0.75, 166.0 / 93.0, 1.0, 16.0 / 9.0}) {
    const std::string stem = quilt_stem("shot_0007", QuiltLayout{8, 6}, aspect);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(stem, m, lg)) << stem;
    EXPECT_EQ(m[1].str(), "8");
    EXPECT_EQ(m[2].str(), "6");
    EXPECT_NEAR(std::stod(m[3].str()), aspect, 1e-4) << stem;
    EXPECT_EQ(stem.substr(0, 9), "shot_0007");
  }
  EXPECT_EQ(quilt_stem("f", QuiltLayout{8, 6}, 0.75), "f_qs8x6a0.75");
}

TEST(Quilt, TilesHoldTheirViewsFromTheBottomLeft) {
  const int views = 5, w = 3, h = 2;
  std::vector<uint16_t> volume(size_t(views) * w * h * 4);
  std::vector<float> depth(size_t(views) * w * h);
  for (size_t i = 0; i < volume.size(); ++i) volume[i] = uint16_t(i + 1);
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = float(i);
  const QuiltLayout l{3, 2};  // 6 tiles, the last empty
  std::vector<uint16_t> quilt;
  std::vector<float> zq;
  assemble_quilt(l, views, w, h, volume.data(), depth.data(), quilt, &zq);
  ASSERT_EQ(quilt.size(), size_t(9 * 4 * 4));
  const int qw = 9;
  for (int v = 0; v < 6; ++v) {
    const int tx = v % 3, ty_from_bottom = v / 3;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t q = size_t((1 - ty_from_bottom) * h + y) * qw + size_t(tx * w + x);
        for (int c = 0; c < 4; ++c) {
          const uint16_t expect = v < views ? volume[((size_t(v) * h + y) * w + x) * 4 + c] : 0;
          EXPECT_EQ(quilt[q * 4 + c], expect) << "view " << v;
        }
        EXPECT_EQ(zq[q], v < views ? depth[(size_t(v) * h + y) * w + x] : INFINITY);
      }
  }
}

// The CLI's quilt equals the views file tile by tile (colour and depth); the depth of a square facing
// the camera on the focal plane is the focal distance where it is drawn and +infinity elsewhere, in
// every view; PNG previews decode to the EXR values through the sRGB curve within 1/255.
TEST(Quilt, CliQuiltDepthAndPreviews) {
  const std::string out = temp_dir("quilt");
  fs::create_directories(out);
  const std::string scene = out + "/square.glb";
  test::save_square_glb(scene);
  const CliRun r = run("render '" + scene +
                       "' --views 6 --view-size 96x48 --display 480x270 --write encoded,views,quilt,depth --quilt 3x2 "
                       "--preview --name f%02d --out " +
                       out);
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream sj(out + "/f00.json");
  std::stringstream text;
  text << sj.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str());
  const double focal = j["rig"]["focal_distance"].get<double>();
  const std::string quilt_name = j["outputs"]["quilt"].get<std::string>();
  EXPECT_EQ(quilt_name, quilt_stem("f00", QuiltLayout{3, 2}, j["rig"]["aspect"].get<double>()) + ".exr");
  int qw = 0, qh = 0;
  std::vector<uint16_t> quilt;
  std::vector<float> qz;
  read_views_exr_part(out + "/" + quilt_name, 0, qw, qh, quilt, &qz);
  ASSERT_EQ(qw, 3 * 96);
  ASSERT_EQ(qh, 2 * 48);
  ASSERT_EQ(qz.size(), size_t(qw) * qh);
  size_t covered = 0;
  for (int v = 0; v < 6; ++v) {
    int w = 0, h = 0;
    std::vector<uint16_t> px;
    std::vector<float> z;
    read_views_exr_part(out + "/f00.views.exr", v, w, h, px, &z);
    ASSERT_EQ(z.size(), size_t(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * w + x;
        const size_t q = size_t((1 - v / 3) * h + y) * qw + size_t((v % 3) * w + x);
        for (int c = 0; c < 4; ++c) ASSERT_EQ(quilt[q * 4 + c], px[i * 4 + c]) << "view " << v;
        ASSERT_EQ(std::memcmp(&qz[q], &z[i], sizeof(float)), 0) << "view " << v;
        if (px[i * 4 + 3] != 0) {
          ++covered;
          EXPECT_NEAR(z[i], focal, 1e-5 * focal) << "view " << v << " (" << x << ", " << y << ")";
        } else {
          EXPECT_EQ(z[i], INFINITY);
        }
      }
  }
  EXPECT_GT(covered, 6u * 96 * 48 / 10);
  // previews
  // opaque: the encoded preview, RGB over black with alpha 255 (read_png_rgba8 expands RGB so)
  auto check_png = [](const std::string& png, const std::vector<uint16_t>& exr, int w, int h, bool opaque = false) {
    int pw = 0, ph = 0;
    std::vector<uint8_t> rgba;
    read_png_rgba8(png, pw, ph, rgba);
    ASSERT_EQ(pw, w);
    ASSERT_EQ(ph, h);
    for (size_t i = 0; i < size_t(w) * h; ++i)
      for (int c = 0; c < 4; ++c) {
        // PNG's alpha is straight: a partly covered pixel's colour is divided by its coverage
        const double a = half_value(exr[i * 4 + 3]), straight = !opaque && a > 0.0 && a < 1.0 ? 1.0 / a : 1.0;
        const double lin = half_value(exr[i * 4 + c]) * (c < 3 ? straight : 1.0);
        const double expect = 255.0 * (c < 3 ? srgb_encode(lin) : opaque ? 1.0 : std::min(1.0, std::max(0.0, lin)));
        ASSERT_LE(std::abs(double(rgba[i * 4 + c]) - expect), 1.0) << png << " pixel " << i << " channel " << c;
      }
  };
  int w = 0, h = 0;
  std::vector<uint16_t> encoded;
  read_rgba_exr(out + "/f00.exr", w, h, encoded);
  check_png(out + "/f00.png", encoded, w, h, true);
  // the center view's pixels are not square here (96x48 for a 166:93 display): its PNG is stretched to
  // square pixels (tests/test_previews.cpp), the quilt's is not
  int cw = 0, ch = 0;
  std::vector<uint8_t> center_png;
  read_png_rgba8(out + "/f00.center.png", cw, ch, center_png);
  EXPECT_EQ(cw, 96);
  EXPECT_EQ(ch, std::lround(48 / (j["rig"]["aspect"].get<double>() * 48 / 96)));
  EXPECT_EQ(j["preview_center_view"], 3);
  check_png(out + "/" + quilt_name.substr(0, quilt_name.size() - 4) + ".png", quilt, qw, qh);
  // srgb_encode against the standard's values
  EXPECT_NEAR(srgb_encode(0.5), 0.735356, 1e-6);
  EXPECT_NEAR(srgb_encode(0.002), 0.02584, 1e-6);
  EXPECT_EQ(srgb_encode(2.0), 1.0);
  EXPECT_EQ(srgb_encode(-1.0), 0.0);
}

// --depth-empty 1e10 (what Cycles writes) replaces +infinity where nothing was drawn, and only there;
// the sidecar records it, so a resume with the default depth does not take the frame as its own.
TEST(Quilt, DepthEmptyIsWrittenWhereNothingWasDrawn) {
  const std::string out = temp_dir("depth_empty");
  fs::create_directories(out);
  const std::string scene = out + "/square.glb";
  test::save_square_glb(scene);
  const std::string args = "render '" + scene + "' --views 4 --view-size 48x24 --write views,depth -q --out " + out;
  const CliRun r = run(args + " --depth-empty 1e10");
  ASSERT_EQ(r.status, 0) << r.output;
  int w = 0, h = 0;
  std::vector<uint16_t> px;
  std::vector<float> z;
  size_t empty = 0, covered = 0;
  for (int v = 0; v < 4; ++v) {
    read_views_exr_part(out + "/frame_0000.views.exr", v, w, h, px, &z);
    for (size_t i = 0; i < z.size(); ++i) {
      if (px[i * 4 + 3] == 0) {
        ++empty;
        ASSERT_EQ(z[i], 1e10f) << "view " << v << " pixel " << i;
      } else {
        ++covered;
        ASSERT_LT(z[i], 1e3f) << "view " << v << " pixel " << i;
      }
    }
  }
  EXPECT_GT(empty, 0u);
  EXPECT_GT(covered, 0u);
  std::ifstream sj(out + "/frame_0000.json");
  std::stringstream text;
  text << sj.rdbuf();
  EXPECT_EQ(nlohmann::json::parse(text.str())["depth_empty"].get<double>(), 1e10);
  const CliRun resumed = run(args + " --resume");  // a frame of another configuration: refused by name
  EXPECT_EQ(resumed.status, 1) << resumed.output;
  EXPECT_NE(resumed.output.find("depth_empty differs"), std::string::npos) << resumed.output;
  const CliRun again = run(args + " --overwrite");
  ASSERT_EQ(again.status, 0) << again.output;
  read_views_exr_part(out + "/frame_0000.views.exr", 0, w, h, px, &z);
  size_t empty0 = 0;
  for (size_t i = 0; i < z.size(); ++i) empty0 += px[i * 4 + 3] == 0;
  EXPECT_GT(empty0, 0u);
  EXPECT_EQ(size_t(std::count(z.begin(), z.end(), INFINITY)), empty0) << "rendered again with the default, +infinity";
  EXPECT_EQ(run(args + " --depth-empty -1").status, 2);
}

TEST(Quilt, BadQuiltOptionsFailWithOneLine) {
  const std::string out = temp_dir("quilt_bad");
  test::expect_usage_error(run("render --write depth --out " + out), "depth");
  test::expect_usage_error(run("render --quilt 4x4 --views 8 --view-size 64x32 --display 240x135 --out " + out),
                           "--write quilt");
  test::expect_usage_error(
      run("render --write quilt --quilt 3x2 --views 8 --view-size 64x32 --display 240x135 --out " + out), "6 tiles");
  test::expect_one_error_line(run("render --write quilt --views 96 --view-size 4096x2048 --out " + out), "16384");
}

}  // namespace pmr
