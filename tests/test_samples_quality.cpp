// pmr quality --samples (host/quality/samples_quality.cpp): the box filter and the error measures on
// hand-made volumes, and on a real render that four samples per pixel come closer to the 64-sample
// reference than one.
#include <gtest/gtest.h>

#include <cmath>

#include "cli/render_command.h"
#include "quality/samples_quality.h"
#include "test_util.h"

namespace pmr {
namespace {

TEST(SamplesQuality, DownsampleIsTheBoxMean) {
  // one view, 4x2 fine pixels -> 2x1
  std::vector<float> fine(4 * 2 * 4, 0.0f);
  const float values[2][4] = {{0.0f, 1.0f, 0.25f, 0.25f}, {0.5f, 0.5f, 1.0f, 0.0f}};  // [y][x], every channel
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 4; ++c) fine[size_t((y * 4 + x) * 4 + c)] = values[y][x] * float(c + 1);
  const std::vector<float> out = downsample_2x2(fine, 1, 2, 1);
  ASSERT_EQ(out.size(), 8u);
  for (int c = 0; c < 4; ++c) {
    EXPECT_FLOAT_EQ(out[size_t(c)], 0.5f * float(c + 1));        // (0 + 1 + 0.5 + 0.5) / 4
    EXPECT_FLOAT_EQ(out[size_t(4 + c)], 0.375f * float(c + 1));  // (0.25 + 0.25 + 1 + 0) / 4
  }
}

TEST(SamplesQuality, EdgePixelsAreFractionalAlphaAndTheirNeighbourhood) {
  // 5x5, empty but for a half-covered grey pixel at (2, 2): it and its 8 neighbours are edge pixels
  std::vector<float> reference(5 * 5 * 4, 0.0f), image;
  for (int c = 0; c < 4; ++c) reference[size_t((2 * 5 + 2) * 4 + c)] = 0.5f;
  image = reference;
  for (int c = 0; c < 4; ++c) image[size_t((2 * 5 + 2) * 4 + c)] = 1.0f;  // squared difference 4 x 0.25 = 1
  const ViewDifference d = compare_views(image, reference, 1, 5, 5);
  EXPECT_NEAR(d.rmse, std::sqrt(1.0 / (4.0 * 25.0)), 1e-12);
  EXPECT_NEAR(d.edge_rmse, std::sqrt(1.0 / (4.0 * 9.0)), 1e-12);
  EXPECT_NEAR(d.edge_fraction, 9.0 / 25.0, 1e-12);
  EXPECT_EQ(compare_views(reference, reference, 1, 5, 5).rmse, 0.0);
}

TEST(SamplesQuality, FourSamplesComeCloserToTheReferenceThanOne) {
  RigConfig rig;
  rig.views = 4, rig.view_w = 96, rig.view_h = 48;
  PipelineConfig pc;
  pc.shading = Shading::Lambert;
  const Scene scene = load_scene(default_scene_path());
  const std::vector<SamplesQualityRow> rows = samples_quality(test::runtime(), scene, rig, Display{}, pc, {1, 4});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_GT(rows[0].error.edge_fraction, 0.01) << "the bundled scene should have edges in view";
  EXPECT_LT(rows[1].error.rmse, 0.8 * rows[0].error.rmse);
  EXPECT_LT(rows[1].error.edge_rmse, 0.8 * rows[0].error.edge_rmse);
}

}  // namespace
}  // namespace pmr
