// Samples per pixel (DESIGN section 3b) through the whole pipeline: a mesh that tiles the screen covers
// every sample of every view exactly once and resolves to full coverage with no seam; a pixel that an
// edge halves has alpha 1/2 within 1/S; pixels a triangle covers wholly have its one-sample colour.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <cmath>

#include "test_util.h"

namespace pmr {
namespace {

// A white rectangle on the focal plane (zero disparity: the same raster position in every view) from
// raster x = x_left to beyond the right border, over the whole height.
Scene rectangle_from(const Rig& rig, double x_left, double x_right = -1.0) {
  Scene s = test::empty_scene();
  const double xs[2] = {x_left, x_right > x_left ? x_right : rig.view_w + 10.0}, ys[2] = {-10.0, rig.view_h + 10.0};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      s.positions.push_back(test::focal_point(rig, xs[i], ys[j]));
      PmrVertexAttr a{};
      a.normal[2] = 1.0f;
      for (int k = 0; k < 4; ++k) a.color[k] = 1.0f;
      s.attributes.push_back(a);
    }
  PmrTriangle t{};
  t.has_normals = 1;
  t.v[0] = 0, t.v[1] = 2, t.v[2] = 1;  // raster y grows downwards: counter-clockwise in the world
  s.triangles.push_back(t);
  t.v[0] = 1, t.v[1] = 2, t.v[2] = 3;
  s.triangles.push_back(t);
  return s;
}

TEST(Samples, AnEdgeThroughPixelCentersHalvesTheirCoverage) {
  const Rig rig = test::small_rig(3, 40, 12);
  const Scene scene = rectangle_from(rig, 20.5);  // the edge passes through column 20's centers
  PipelineConfig one;
  one.shading = Shading::Lambert;
  const test::Rendered single = test::render_with(scene, rig, one);
  for (int samples : {4, 8, 16}) {
    PipelineConfig pc = one;
    pc.samples = samples;
    const test::Rendered out = test::render_with(scene, rig, pc);
    ASSERT_EQ(out.volume.size(), single.volume.size());
    for (size_t voxel = 0; voxel < out.volume.size() / 4; ++voxel) {
      const int px = int(voxel % size_t(rig.view_w));
      const float alpha = test::half_value(out.volume[voxel * 4 + 3]);
      if (px < 20) {
        EXPECT_EQ(alpha, 0.0f) << "S " << samples << " voxel " << voxel;
      } else if (px == 20) {
        EXPECT_NEAR(alpha, 0.5f, 1.0f / samples) << "S " << samples << " voxel " << voxel;
        EXPECT_NEAR(test::half_value(out.volume[voxel * 4]), alpha * test::half_value(single.volume[voxel * 4]), 1e-3)
            << "premultiplied: the colour scales with coverage";
      } else {
        for (int c = 0; c < 4; ++c)
          ASSERT_EQ(out.volume[voxel * 4 + size_t(c)], single.volume[voxel * 4 + size_t(c)])
              << "S " << samples << " voxel " << voxel << ": a wholly covered pixel is shaded at its center";
      }
    }
  }
}

// alphaMode MASK is tested once per pixel and triangle at its shading point, not per sample: alpha falls
// linearly from 1 on the right to 0 on the left and crosses the cutoff at x = 20.25, between column 20's
// center and its leftmost samples, yet every pixel is wholly kept or wholly dropped, as with one sample.
// (Pixels the rectangle's diagonal crosses are left out: there the triangle that misses the center is
// shaded and tested at the centroid of its samples, which may lie left of the cutoff.)
TEST(Samples, AlphaMaskKeepsOrDropsWholePixels) {
  const Rig rig = test::small_rig(3, 40, 12);
  Scene scene = rectangle_from(rig, -10.0, 50.5);
  for (size_t v = 0; v < scene.attributes.size(); ++v) scene.attributes[v].color[3] = v % 2 == 0 ? 0.0f : 1.0f;
  scene.materials[0].alpha_mode = PMR_ALPHA_MASK;
  scene.materials[0].alpha_cutoff = 0.5f;
  PipelineConfig one;
  one.shading = Shading::Lambert;
  const test::Rendered single = test::render_with(scene, rig, one);
  for (int samples : {4, 16}) {
    PipelineConfig pc = one;
    pc.samples = samples;
    const test::Rendered out = test::render_with(scene, rig, pc);
    size_t kept = 0;
    for (size_t voxel = 0; voxel < out.volume.size() / 4; ++voxel) {
      const int px = int(voxel % size_t(rig.view_w)), py = int(voxel / size_t(rig.view_w) % size_t(rig.view_h));
      const double diagonal_y = -10.0 + (rig.view_h + 20.0) * (50.5 - (px + 0.5)) / 60.5;  // from (50.5, -10)
      if (std::abs(diagonal_y - (py + 0.5)) < 1.5) continue;
      EXPECT_EQ(test::half_value(out.volume[voxel * 4 + 3]), px < 20 ? 0.0f : 1.0f)
          << "S " << samples << " voxel " << voxel;
      for (int c = 0; c < 4; ++c)
        EXPECT_EQ(out.volume[voxel * 4 + size_t(c)], single.volume[voxel * 4 + size_t(c)])
            << "S " << samples << " voxel " << voxel;
      kept += px >= 20;
    }
    EXPECT_GT(kept, 0u);
  }
}

// The Z channel (Pipeline::read_depth) holds each pixel's nearest covered sample's depth, not a mean:
// where an edge halves a pixel, the rectangle's depth (constant, on the focal plane) as in the pixels it
// covers wholly, +infinity where nothing is drawn.
TEST(Samples, DepthIsTheNearestCoveredSampleNotAMean) {
  const Rig rig = test::small_rig(3, 40, 12);
  const Scene scene = rectangle_from(rig, 20.5);
  for (int samples : {1, 4, 16}) {
    PipelineConfig pc;
    pc.samples = samples;
    pc.debug_outputs = true;
    Pipeline p(test::runtime(), pc);
    p.set_scene(scene);
    p.configure(rig, nullptr);
    p.render(rig);
    std::vector<float> z;
    p.read_depth(z);
    ASSERT_EQ(z.size(), size_t(rig.views) * rig.view_w * rig.view_h);
    const float z_covered = z[size_t(rig.view_w) - 1];
    ASSERT_TRUE(std::isfinite(z_covered) && z_covered > 0.0f && z_covered < 1.0f) << z_covered;
    for (size_t voxel = 0; voxel < z.size(); ++voxel) {
      const int px = int(voxel % size_t(rig.view_w));
      if (px < 20)  // (one sample: column 20's center lies on the rectangle's left edge, which owns it)
        EXPECT_EQ(z[voxel], INFINITY) << "S " << samples << " voxel " << voxel;
      else EXPECT_EQ(z[voxel], z_covered) << "S " << samples << " voxel " << voxel;
    }
  }
}

// The sidecar records the samples per pixel (absent in older sidecars: one), and --resume refuses a
// folder rendered with another count.
TEST(Samples, SidecarRecordsThemAndResumeComparesThem) {
  test::expect_resume_compares("--samples 8", "\"samples_per_pixel\": 8", "samples_per_pixel");
}

}  // namespace
}  // namespace pmr
