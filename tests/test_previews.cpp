// PNG previews and pixel aspect: a view's pixels span the display's aspect A (W x H pixels for an A:1
// window), so they are A H / W as wide as tall. The center-view PNG is stretched to square pixels
// (viewers ignore PNG's pixel aspect), so a square in the scene is square in it; the quilt PNG keeps
// the rendered tiles and records the aspect in its pHYs chunk.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pmr/output.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::run;
using test::temp_dir;

uint16_t bits(float v) { return half(v).bits(); }

// The pHYs chunk's pixels per unit (x, y), or (0, 0) without one.
std::pair<uint32_t, uint32_t> phys(const std::string& png) {
  std::ifstream in(png, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = bytes.find("pHYs");
  if (at == std::string::npos || at + 13 > bytes.size()) return {0, 0};
  auto be32 = [&](size_t i) {
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = v << 8 | uint8_t(bytes[i + size_t(k)]);
    return v;
  };
  return {be32(at + 4), be32(at + 8)};
}

nlohmann::json sidecar(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

// The bounding box of the pixels more than half covered: (width, height) in pixels.
std::pair<int, int> covered_box(const std::vector<uint8_t>& rgba, int w, int h) {
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (rgba[(size_t(y) * w + x) * 4 + 3] > 127)
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  return {x1 - x0 + 1, y1 - y0 + 1};
}

}  // namespace

// PNG's alpha is straight: a half-covered red edge (premultiplied 0.5, alpha 0.5) is full red at alpha
// 128, a half-covered linear grey 0.25 is straight 0.5 (sRGB 188), and the opaque form keeps what the
// pixel shows over black.
TEST(Previews, PngColourIsStraightAlpha) {
  const std::string dir = temp_dir("png_straight");
  fs::create_directories(dir);
  const std::vector<uint16_t> px = {bits(0.5f),  0,          0,           bits(0.5f), bits(0.25f), bits(0.25f),
                                    bits(0.25f), bits(0.5f), bits(0.25f), 0,          0,           bits(1.0f)};
  int w = 0, h = 0;
  std::vector<uint8_t> rgba;
  write_png_preview(dir + "/a.png", 3, 1, px.data());
  read_png_rgba8(dir + "/a.png", w, h, rgba);
  ASSERT_EQ(w, 3);
  const std::vector<uint8_t> want = {255, 0, 0, 128, 188, 188, 188, 128, 137, 0, 0, 255};
  EXPECT_EQ(rgba, want);
  write_png_preview(dir + "/b.png", 3, 1, px.data(), 1.0, true);
  read_png_rgba8(dir + "/b.png", w, h, rgba);
  EXPECT_EQ(rgba[0], 188) << "opaque: premultiplied 0.5 red shown over black";
  EXPECT_EQ(rgba[3], 255);
}

TEST(Previews, SquarePixelsStretchOneAxis) {
  // 2x1 pixels, each twice as wide as tall: 4x1; the ends keep their values, the middle is between
  const std::vector<uint16_t> two = {bits(0), bits(0), bits(0), bits(0), bits(1), bits(0.5f), bits(0.25f), bits(1)};
  int w = 0, h = 0;
  std::vector<uint16_t> out = square_pixels(two.data(), 2, 1, 2.0, w, h);
  ASSERT_EQ(w, 4);
  ASSERT_EQ(h, 1);
  EXPECT_EQ(test::half_value(out[0]), 0.0f);
  EXPECT_EQ(test::half_value(out[12]), 1.0f);
  EXPECT_EQ(test::half_value(out[13]), 0.5f);
  EXPECT_GT(test::half_value(out[4]), 0.0f);
  EXPECT_LT(test::half_value(out[4]), test::half_value(out[8]));
  EXPECT_LT(test::half_value(out[8]), 1.0f);
  // tall pixels (aspect 0.5): the height doubles; a uniform image stays uniform
  const std::vector<uint16_t> flat(3 * 2 * 4, bits(0.3f));
  out = square_pixels(flat.data(), 3, 2, 0.5, w, h);
  ASSERT_EQ(w, 3);
  ASSERT_EQ(h, 4);
  for (uint16_t b : out) EXPECT_EQ(b, bits(0.3f));
  // square pixels: unchanged
  out = square_pixels(two.data(), 2, 1, 1.0, w, h);
  EXPECT_EQ(out, two);
  EXPECT_EQ(w, 2);
}

// lg-16-like views with non-square pixels: a square facing the camera is square in the center PNG,
// which is stretched, and not in the quilt PNG, which records the pixel aspect.
TEST(Previews, CenterPngHasSquarePixelsQuiltPngRecordsTheAspect) {
  const std::string out = temp_dir("previews");
  fs::create_directories(out);
  const std::string scene = out + "/square.glb";
  test::save_square_glb(scene);
  // 16:9 display, 80x90 views: pixels 16/9 * 90/80 = 2 times as wide as tall
  const CliRun r = run("render '" + scene +
                       "' --views 4 --view-size 80x90 --display 320x180 --display-size 160x90 "
                       "--write quilt --quilt 2x2 --preview --out " +
                       out);
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = sidecar(out + "/frame_0000.json");
  const double aspect = j["rig"]["aspect"].get<double>() * 90.0 / 80.0;
  ASSERT_NEAR(aspect, 2.0, 1e-12);

  int w = 0, h = 0;
  std::vector<uint8_t> center;
  read_png_rgba8(out + "/frame_0000.center.png", w, h, center);
  EXPECT_EQ(w, 160);
  EXPECT_EQ(h, 90);
  const auto [bw, bh] = covered_box(center, w, h);
  EXPECT_GT(bh, 30);
  EXPECT_LE(std::abs(bw - bh), 2) << bw << " x " << bh << " pixels for a square";
  EXPECT_EQ(phys(out + "/frame_0000.center.png"), (std::pair<uint32_t, uint32_t>{0, 0}));

  const std::string quilt = out + "/" + j["outputs"]["preview_quilt"].get<std::string>();
  std::vector<uint8_t> tiles;
  read_png_rgba8(quilt, w, h, tiles);
  EXPECT_EQ(w, 160);
  EXPECT_EQ(h, 180);
  const auto [x_ppu, y_ppu] = phys(quilt);
  ASSERT_GT(x_ppu, 0u);
  EXPECT_NEAR(double(y_ppu) / double(x_ppu), aspect, 1e-5) << "pixel width / height = y / x pixels per unit";
}

// Square view pixels: the center PNG is the view itself, pixel for pixel.
TEST(Previews, SquareViewPixelsAreKept) {
  const std::string out = temp_dir("previews_square");
  const CliRun r =
      run("render --views 4 --view-size 96x48 --display 240x120 --display-size 200x100 --write views "
          "--preview --out " +
          out);
  ASSERT_EQ(r.status, 0) << r.output;
  int w = 0, h = 0, pw = 0, ph = 0;
  std::vector<uint16_t> view;
  read_views_exr_part(out + "/frame_0000.views.exr", 2, w, h, view);
  std::vector<uint8_t> png;
  read_png_rgba8(out + "/frame_0000.center.png", pw, ph, png);
  ASSERT_EQ(pw, w);
  ASSERT_EQ(ph, h);
  for (size_t i = 0; i < size_t(w) * h; ++i)
    ASSERT_NEAR(png[i * 4 + 3], 255.0 * std::min(1.0f, test::half_value(view[i * 4 + 3])), 1.0) << "pixel " << i;
}

}  // namespace pmr
