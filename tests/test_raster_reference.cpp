// Kernels against the C++ reference: vertex records, setup records (MTAs), tile bins, and fine raster
// coverage, depth and visibility, bit for bit, for random triangles and N in {1, 2, 7, 48, 96}, with
// linear and angular camera spacing, at every sample of 1, 4, 8 and 16 samples per pixel; the "tiny" cases
// are thousands of triangles of a few pixels in the default 16x2x16 tiles, most of whose queue entries take
// the fine raster's small-triangle path (cl/fine_small.h), the others its general path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <set>

#include "reference/reference.h"
#include "test_util.h"

namespace pmr {
namespace {

struct Case {
  int views, w, h, tris;
  bool double_sided, angular = false;
  int samples = 1;
  float max_size = 0.6f;    // of a triangle's vertices around its center, in a scene of the unit box
  int tile[3] = {4, 4, 4};  // x, y, views
};

// Thousands of triangles of one to a few pixels, in the default tiles.
Case tiny(int views, int samples, bool angular) {
  Case c{views, 64, 32, 2000, true, angular, samples};
  c.max_size = 0.06f;
  c.tile[0] = 16, c.tile[1] = 2, c.tile[2] = 16;
  return c;
}

// Tens of thousands of triangles under a pixel: most hold no sample position in some views or in all,
// which setup trims or drops (the coverage stays the reference's, which never trims).
Case micro(int views, int samples) {
  Case c{views, 64, 32, 8000, false, false, samples};
  c.max_size = 0.012f;
  c.tile[0] = 16, c.tile[1] = 2, c.tile[2] = 16;
  return c;
}

class RasterReference : public ::testing::TestWithParam<Case> {};

TEST_P(RasterReference, MatchesReferenceBitForBit) {
  const Case c = GetParam();
  const Scene scene = test::random_scene(c.tris, 1234u + c.views, c.double_sided, c.max_size);
  const Rig rig = test::small_rig(c.views, c.w, c.h, c.angular);
  PipelineConfig pc;
  pc.tile_x = c.tile[0], pc.tile_y = c.tile[1], pc.tile_v = c.tile[2];
  pc.samples = c.samples;
  const test::Rendered out = test::render_with(scene, rig, pc);
  PmrParams P = test::params_for(rig);
  set_sample_pattern(c.samples, P);

  // setup records
  std::vector<PmrVertex> verts;
  for (const auto& p : scene.positions) verts.push_back(ref::transform_vertex(P, &p.x));
  const auto clipped = ref::clip_triangles(P, scene, verts);
  std::vector<PmrMta> want = ref::make_mtas(P, clipped), got = out.mtas;
  ref::sort_mtas(got);
  ASSERT_EQ(got.size(), want.size());
  if (c.max_size < 0.02f) {  // micro-triangles: setup drops most of them
    PmrParams whole = P;
    whole.sample_area = PMR_SAMPLES_PIXEL;  // no view trimmed
    const size_t untrimmed = ref::make_mtas(whole, clipped).size();
    EXPECT_LT(want.size(), untrimmed / 2) << "setup should drop the MTAs that hold no sample position";
  }
  for (size_t i = 0; i < want.size(); ++i)
    ASSERT_EQ(0, std::memcmp(&got[i], &want[i], sizeof(PmrMta))) << "MTA " << i << " key " << want[i].key;

  // coverage, depth, visibility
  const ref::RasterResult r = ref::rasterize(P, clipped);
  size_t covered = 0;
  ASSERT_EQ(out.key.size(), r.key.size());
  for (size_t v = 0; v < r.key.size(); ++v) {
    ASSERT_EQ(out.count[v], r.count[v]) << "voxel " << v / size_t(c.samples) << " sample " << v % size_t(c.samples);
    ASSERT_EQ(out.key[v], r.key[v]) << "voxel " << v / size_t(c.samples) << " sample " << v % size_t(c.samples);
    if (r.key[v] != PMR_NO_KEY) {
      ASSERT_EQ(out.depth[v], r.depth[v]) << "voxel " << v / size_t(c.samples) << " sample " << v % size_t(c.samples);
      ++covered;
    }
  }
  // (thousands of tiny triangles leave most of the volume empty)
  EXPECT_GT(covered, r.key.size() / (c.max_size < 0.02f  ? 400
                                     : c.max_size < 0.6f ? 50
                                                         : 20))
      << "the test scene should cover a good part of the volume";
}

INSTANTIATE_TEST_SUITE_P(Views, RasterReference,
                         ::testing::Values(Case{1, 67, 33, 60, false}, Case{2, 64, 32, 60, true},
                                           Case{7, 53, 29, 60, false}, Case{96, 48, 24, 40, true},
                                           Case{2, 64, 32, 60, true, true}, Case{7, 53, 29, 60, false, true},
                                           Case{48, 56, 28, 50, true, true}, Case{96, 48, 24, 40, true, true},
                                           Case{7, 53, 29, 60, false, false, 4}, Case{48, 56, 28, 50, true, true, 4},
                                           Case{2, 64, 32, 60, true, false, 8}, Case{7, 53, 29, 60, true, true, 16},
                                           tiny(96, 1, false), tiny(40, 4, true), tiny(7, 8, false), micro(96, 1),
                                           micro(48, 4)),
                         [](const ::testing::TestParamInfo<Case>& i) {
                           return "N" + std::to_string(i.param.views) + (i.param.double_sided ? "_double" : "_single") +
                                  (i.param.angular ? "_angular" : "") +
                                  (i.param.samples > 1 ? "_S" + std::to_string(i.param.samples) : "") +
                                  (i.param.max_size < 0.02f  ? "_micro"
                                   : i.param.max_size < 0.6f ? "_tiny"
                                                             : "");
                         });

}  // namespace
}  // namespace pmr
