// The fused raster + encode path (cl/fine_encode.cl) against the unfused one (cl/fine.cl writing the
// view volume, then cl/encode.cl): the display images must be identical bit for bit, for display
// parameter sets that exercise the whole encoder map (reversed views, slanted lenses with irrational-
// looking pitches, offsets on exact integers, display pixels whose subpixels straddle screen tiles,
// view rasters larger and smaller than the display), several tile shapes, view counts and samples per
// pixel.
#include <gtest/gtest.h>

#include "pmr/rig.h"
#include "test_util.h"

namespace pmr {
namespace {

struct FusedCase {
  const char* name;
  int views, view_w, view_h, display_w, display_h;
  const char *lens, *slant, *offset;
  bool reversed;
  int tile[3];
  bool angular = false;
  int samples = 1;
};

std::vector<uint16_t> encode(const Scene& scene, const Rig& rig, const Display& d, const int* tile, int samples,
                             bool fuse, bool* fused) {
  PipelineConfig pc;
  pc.tile_x = tile[0], pc.tile_y = tile[1], pc.tile_v = tile[2];
  pc.samples = samples;
  pc.fuse_encode = fuse;
  test::EncodedRender r = test::render_encoded(scene, rig, d, pc);
  *fused = r.fused;
  return r.image;
}

class FusedEncode : public ::testing::TestWithParam<FusedCase> {};

TEST_P(FusedEncode, EqualsRasterThenEncodeBitForBit) {
  const FusedCase c = GetParam();
  Scene scene = test::random_scene(120, 77u + c.views, true);
  Display d;
  d.width = c.display_w, d.height = c.display_h;
  d.lens_pitch = parse_rational(c.lens, "L");
  d.tan_slant = parse_rational(c.slant, "T");
  d.offset = parse_rational(c.offset, "O");
  d.reversed = c.reversed;
  RigConfig rc;
  rc.views = c.views, rc.view_w = c.view_w, rc.view_h = c.view_h;
  rc.angular_spacing = c.angular;
  const Rig rig = make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
  bool fused = false, unfused = true;
  const std::vector<uint16_t> want = encode(scene, rig, d, c.tile, c.samples, false, &unfused);
  const std::vector<uint16_t> got = encode(scene, rig, d, c.tile, c.samples, true, &fused);
  ASSERT_FALSE(unfused);
  ASSERT_TRUE(fused) << "the fused path should have been chosen";
  ASSERT_EQ(got.size(), want.size());
  size_t drawn = 0, partial = 0;
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(got[i], want[i]) << "display pixel " << i / 4 << " (x " << (i / 4) % size_t(c.display_w) << ", y "
                               << (i / 4) / size_t(c.display_w) << ") channel " << i % 4;
    if (i % 4 == 3) drawn += want[i] != 0, partial += want[i] != 0 && want[i] != 0x3c00;
  }
  EXPECT_GT(drawn, want.size() / 4 / 10) << "the scene should cover a good part of the display";
  EXPECT_GT(partial, 0u) << "some pixels should mix covered and empty subpixels (alpha 1/3, 2/3)";
}

INSTANTIATE_TEST_SUITE_P(
    Displays, FusedEncode,
    ::testing::Values(
        // the paper-8k lens on a small panel; tile boundaries fall on whole display pixels
        FusedCase{"paper_lens", 96, 64, 32, 480, 270, "16", "1/18", "-1/12", false, {16, 2, 4}},
        // 5-pixel-wide tiles: display pixels straddle tile columns
        FusedCase{"straddling", 24, 50, 30, 333, 101, "4.6667", "-1/7", "0.25", true, {5, 3, 4}},
        // N t on exact integers, views wider than the display: several view columns per display pixel
        FusedCase{"integer_offsets", 7, 200, 40, 61, 37, "3", "1/3", "0", false, {8, 2, 3}},
        // one view, tiny tiles that split every display pixel
        FusedCase{"one_view", 1, 40, 20, 31, 17, "5", "0", "0", false, {1, 1, 1}},
        // wide tile rows (two vectors per row), reversed views
        FusedCase{"wide_tiles", 12, 96, 40, 200, 90, "9", "1/9", "-1/24", true, {32, 4, 5}},
        // angular camera spacing (Looking Glass): the paper lens and the straddling tiles again
        FusedCase{"paper_lens_angular", 96, 64, 32, 480, 270, "16", "1/18", "-1/12", false, {16, 2, 4}, true},
        FusedCase{"straddling_angular", 24, 50, 30, 333, 101, "4.6667", "-1/7", "0.25", true, {5, 3, 4}, true},
        // samples per pixel: the resolved colours (fractional alpha at edges) through both paths
        FusedCase{"paper_lens_4_samples", 96, 64, 32, 480, 270, "16", "1/18", "-1/12", false, {16, 2, 4}, false, 4},
        FusedCase{"straddling_8_samples", 24, 50, 30, 333, 101, "4.6667", "-1/7", "0.25", true, {5, 3, 4}, true, 8}),
    [](const ::testing::TestParamInfo<FusedCase>& i) { return std::string(i.param.name); });

}  // namespace
}  // namespace pmr
