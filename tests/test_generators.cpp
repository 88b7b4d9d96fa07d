// The procedural scenes of `pmr bench` (--synthetic, --objects) and save_glb: the CAD-like scene is
// what it claims (closed double-sided objects at different depths, about the requested triangles),
// and a saved .glb loads back to the same triangles and renders the same image.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <tuple>

#include "test_util.h"

namespace pmr {
namespace {

using PositionKey = std::tuple<uint32_t, uint32_t, uint32_t>;

PositionKey key_of(const glm::vec3& p) {
  uint32_t b[3];
  std::memcpy(b, &p, sizeof b);
  return {b[0], b[1], b[2]};
}

TEST(Generators, ObjectsSceneIsClosedDoubleSidedObjectsAtDifferentDepths) {
  for (size_t n : {3000u, 200000u}) {
    const Scene s = make_objects_scene(n);
    EXPECT_NEAR(double(s.triangles.size()), double(n), 0.05 * double(n)) << n;
    EXPECT_EQ(s.materials.size(), std::min<size_t>(100, n / 100)) << "one material per object";
    for (const PmrMaterial& m : s.materials) EXPECT_EQ(m.double_sided, 1u);
    glm::dvec3 lo, hi;
    scene_bounds(s, lo, hi);
    EXPECT_GT(hi.z - lo.z, 2.5) << "spread through the depth range";
    // closed: every edge (between vertex positions, so seams and poles count as joined) is shared by
    // exactly two triangles of the same object, once in each direction
    std::map<std::pair<PositionKey, PositionKey>, int> directed;
    for (const PmrTriangle& t : s.triangles)
      for (int e = 0; e < 3; ++e) {
        const PositionKey a = key_of(s.positions[t.v[e]]), b = key_of(s.positions[t.v[(e + 1) % 3]]);
        ASSERT_NE(a, b) << "degenerate edge";
        ++directed[{a, b}];
      }
    size_t open = 0;
    for (const auto& [edge, count] : directed) open += count != 1 || directed.count({edge.second, edge.first}) != 1;
    EXPECT_EQ(open, 0u) << n << " triangles";
  }
}

TEST(Generators, SavedGlbLoadsBackToTheSameTrianglesAndImage) {
  const Scene s = make_objects_scene(4000, 7);
  const std::string path = ::testing::TempDir() + "pmr_objects_test_" + std::to_string(getpid()) + ".glb";
  save_glb(s, path);
  const Scene l = load_scene(path);
  ASSERT_EQ(l.triangles.size(), s.triangles.size());
  ASSERT_EQ(l.materials.size(), s.materials.size() + 1) << "the loader's default material at index 0";
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    const PmrTriangle &a = s.triangles[t], &b = l.triangles[t];
    ASSERT_EQ(b.material, a.material + 1) << t;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(key_of(l.positions[b.v[k]]), key_of(s.positions[a.v[k]])) << "triangle " << t << " corner " << k;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(l.attributes[b.v[k]].normal[c], s.attributes[a.v[k]].normal[c], 1e-6);
    }
  }
  for (size_t m = 0; m < s.materials.size(); ++m) {
    EXPECT_EQ(l.materials[m + 1].double_sided, 1u);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(l.materials[m + 1].base_color[c], s.materials[m].base_color[c]);
  }
  // same coverage and visibility; colours within half precision of normals that moved by an ulp
  const Rig rig = test::small_rig(5, 96, 48);
  const test::Rendered a = test::render(s, rig), b = test::render(l, rig);
  ASSERT_EQ(a.key, b.key);
  size_t covered = 0;
  for (uint32_t k : a.key) covered += k != PMR_NO_KEY;
  EXPECT_GT(covered, a.key.size() / 20) << "the objects are visible";
  ASSERT_EQ(a.volume.size(), b.volume.size());
  for (size_t i = 0; i < a.volume.size(); ++i)
    ASSERT_LE(std::abs(int(a.volume[i]) - int(b.volume[i])), 2) << "half bits of voxel channel " << i;
  std::remove(path.c_str());
}

TEST(Generators, BenchSavesTheGeneratedSceneAndRefusesAmbiguousRequests) {
  const std::string path = ::testing::TempDir() + "pmr_bench_saved_" + std::to_string(getpid()) + ".glb";
  auto run = [](const std::string& args) {
    const int st = std::system((std::string(PMR_BINARY) + " bench " + args + " > /dev/null 2>&1").c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  };
  std::remove(path.c_str());
  EXPECT_EQ(run("--objects 3000 --save-scene " + path), 0);
  EXPECT_EQ(load_scene(path).triangles.size(), make_objects_scene(3000).triangles.size());
  EXPECT_NE(run("--objects 3000,6000 --save-scene " + path), 0) << "two scenes, one file";
  EXPECT_NE(run("--objects 3000 --synthetic 3000"), 0);
  EXPECT_NE(run("--objects 12x"), 0);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pmr
