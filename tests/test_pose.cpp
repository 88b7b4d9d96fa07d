// Posing animated scenes (DESIGN section 7): skins and morph targets of the shared corpus against
// vertex positions computed by hand from the files' data, node animation through a hierarchy, the
// turntable, and that a pose depends only on its request. Corpus cases skip when ../shared/gltf is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "pmr/scene.h"
#include "test_util.h"

using namespace pmr;
using pmr::test::corpus_dir;

namespace {

std::string corpus_file(const std::string& model) {
  const std::string dir = corpus_dir();
  return dir.empty() ? "" : dir + "/" + model + "/glTF/" + model + ".gltf";
}

#define SKIP_WITHOUT_CORPUS(path) \
  if ((path).empty()) GTEST_SKIP() << "../shared/gltf not found: skipped"

void expect_near(const glm::vec3& a, const glm::vec3& b, double tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

Scene posed(const Scene& rest, double t, int animation = 0) {
  Scene out;
  PoseRequest r;
  r.time = t;
  r.animation = animation;
  pose_scene(rest, r, out);
  return out;
}

}  // namespace

// SimpleSkin: a 1 x 2 strip of 10 vertices over joints 1 (root, identity) and 2 (at y = 1, inverse
// bind = translate(0, -1, 0)); the animation turns joint 2 about +Z. At t = 1 s its key is
// (0, 0, 0.707, 0.707): 90 degrees. A vertex with weights (a, b) goes to a p + b (T R T^-1) p, with T the
// translation to y = 1 and R (x, y) -> (-y, x).
TEST(PoseTest, SimpleSkinMatchesHandComputedPositions) {
  const std::string path = corpus_file("SimpleSkin");
  SKIP_WITHOUT_CORPUS(path);
  const Scene rest = load_scene(path);
  ASSERT_EQ(rest.animations.size(), 1u);
  EXPECT_DOUBLE_EQ(rest.animations[0].end, 5.5);
  ASSERT_EQ(rest.positions.size(), 10u);
  const Scene s = posed(rest, 1.0);
  const float x[2] = {-0.5f, 0.5f};
  const double wb[5] = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f};  // weight of joint 2 per row
  for (int row = 0; row < 5; ++row)
    for (int col = 0; col < 2; ++col) {
      const glm::dvec2 p(x[col], 0.5 * row);
      const glm::dvec2 turned(-(p.y - 1.0), p.x + 1.0);
      const glm::dvec2 e = (1.0 - wb[row]) * p + wb[row] * turned;
      expect_near(s.positions[size_t(2 * row + col)], glm::vec3(e.x, e.y, 0.0), 1e-5,
                  "vertex " + std::to_string(2 * row + col));
      // rest pose: the bind pose, unmoved
      expect_near(rest.positions[size_t(2 * row + col)], glm::vec3(p.x, p.y, 0.0), 0.0, "rest");
    }
  // before the first key and after the last: the first and last values (identity rotations)
  const Scene late = posed(rest, 100.0);
  for (size_t v = 0; v < 10; ++v) expect_near(late.positions[v], rest.positions[v], 1e-6, "t = 100");
}

// SimpleMorph: base triangle (0,0,0) (1,0,0) (0.5,0.5,0); target 0 moves vertex 2 by (-1,1,0), target 1
// by (1,1,0). Mesh default weights (0.5, 0.5); animated weights keys t = 0..4: (0,0) (0,1) (1,1) (1,0) (0,0).
TEST(PoseTest, SimpleMorphMatchesHandComputedPositions) {
  const std::string path = corpus_file("SimpleMorph");
  SKIP_WITHOUT_CORPUS(path);
  const Scene rest = load_scene(path);
  ASSERT_EQ(rest.positions.size(), 3u);
  expect_near(rest.positions[2], {0.5f, 1.5f, 0.0f}, 0.0, "rest: default weights");
  expect_near(posed(rest, 1.0).positions[2], {1.5f, 1.5f, 0.0f}, 1e-6, "t = 1");
  expect_near(posed(rest, 2.5).positions[2], {0.0f, 2.0f, 0.0f}, 1e-6, "t = 2.5: weights (1, 0.5)");
  expect_near(posed(rest, 0.0).positions[2], {0.5f, 0.5f, 0.0f}, 1e-6, "t = 0: base shape");
  expect_near(posed(rest, 2.5).positions[0], {0.0f, 0.0f, 0.0f}, 0.0, "unmoved vertex");
  // no animation selected: the rest pose
  expect_near(posed(rest, 1.0, kNoAnimation).positions[2], {0.5f, 1.5f, 0.0f}, 0.0, "no animation");
}

// A pose depends only on its request: posing t1 then t2 equals posing t2 on a fresh scene, bit for bit.
TEST(PoseTest, PoseIsIndependentOfHistory) {
  const std::string path = corpus_file("RiggedSimple");
  SKIP_WITHOUT_CORPUS(path);
  const Scene rest = load_scene(path);
  PoseRequest r;
  r.animation = 0;
  Scene a, b;
  r.time = 0.7;
  pose_scene(rest, r, a);
  r.time = 1.3;
  pose_scene(rest, r, a);
  pose_scene(rest, r, b);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(glm::vec3)));
  EXPECT_EQ(0, std::memcmp(a.attributes.data(), b.attributes.data(), a.attributes.size() * sizeof(PmrVertexAttr)));
  EXPECT_EQ(0, std::memcmp(a.triangles.data(), b.triangles.data(), a.triangles.size() * sizeof(PmrTriangle)));
  // and back to no animation: the rest arrays
  r.animation = kNoAnimation;
  pose_scene(rest, r, a);
  EXPECT_EQ(0, std::memcmp(a.positions.data(), rest.positions.data(), a.positions.size() * sizeof(glm::vec3)));
}

// Every animated corpus model poses over its whole animation with finite positions, unit normals and
// bounds that stay plausible (within 10x the rest pose's extent about its center).
TEST(PoseTest, CorpusAnimationsPoseWithPlausibleBounds) {
  if (corpus_dir().empty()) GTEST_SKIP() << "../shared/gltf not found: skipped";
  for (const char* model : {"AnimatedTriangle", "BoxAnimated", "AnimatedCube", "InterpolationTest", "RiggedSimple",
                            "RiggedFigure", "CesiumMan", "AnimatedMorphCube", "SimpleSkin", "SimpleMorph"}) {
    SCOPED_TRACE(model);
    const Scene rest = load_scene(corpus_file(model));
    ASSERT_FALSE(rest.animations.empty());
    ASSERT_TRUE(rest.motion);
    glm::dvec3 lo, hi;
    ASSERT_TRUE(scene_bounds(rest, lo, hi));
    const glm::dvec3 c = 0.5 * (lo + hi);
    const double extent = glm::length(hi - lo);
    bool moved = false;
    for (int k = 0; k <= 16; ++k) {
      const double t = rest.animations[0].start + (rest.animations[0].end - rest.animations[0].start) * k / 16.0;
      const Scene s = posed(rest, t);
      glm::dvec3 l, h;
      ASSERT_TRUE(scene_bounds(s, l, h));
      EXPECT_LT(glm::length(l - c), 10 * extent) << "t = " << t;
      EXPECT_LT(glm::length(h - c), 10 * extent) << "t = " << t;
      for (size_t v = 0; v < s.positions.size(); ++v) {
        moved |= s.positions[v] != rest.positions[v];
        const float* n = s.attributes[v].normal;
        const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
        if (len != 0.0) {
          ASSERT_NEAR(len, 1.0, 1e-5) << "vertex " << v << " t = " << t;
        }
      }
    }
    // AnimatedTriangle etc. move their node; every model here moves some vertex at some time
    EXPECT_TRUE(moved);
  }
}

// MorphPrimitivesTest: no animation, but its mesh's default weights apply at rest to both primitives.
TEST(PoseTest, DefaultMorphWeightsApplyAtRest) {
  const std::string path = corpus_file("MorphPrimitivesTest");
  SKIP_WITHOUT_CORPUS(path);
  const Scene s = load_scene(path);
  EXPECT_TRUE(s.animations.empty());
  EXPECT_FALSE(s.motion);
  for (const std::string& w : s.warnings) EXPECT_EQ(w.find("morph"), std::string::npos) << w;
}

// Turntable: about +Y through the pivot, counter-clockwise seen from above; whole turns are exact.
TEST(PoseTest, TurntableTurnsAboutThePivot) {
  Scene rest;
  rest.positions = {{2, 0, 1}, {1, 1, 1}, {1, 0, 2}};
  rest.attributes.resize(3);
  rest.attributes[0].normal[0] = 1.0f;
  PmrTriangle t{};
  t.v[0] = 0, t.v[1] = 1, t.v[2] = 2;
  rest.triangles = {t};
  PoseRequest r;
  r.turntable = true;
  r.pivot = glm::dvec3(1, 0, 1);
  r.turntable_deg = 90.0;
  Scene out;
  EXPECT_TRUE(pose_scene(rest, r, out));
  // +X about the pivot goes to -Z under a counter-clockwise quarter turn seen from +Y
  expect_near(out.positions[0], {1, 0, 0}, 0.0, "quarter turn");
  expect_near(out.positions[1], {1, 1, 1}, 0.0, "on the axis");
  EXPECT_EQ(out.attributes[0].normal[2], -1.0f);
  r.turntable_deg = turntable_angle(96, 360.0, 96);
  EXPECT_EQ(r.turntable_deg, 0.0);
  pose_scene(rest, r, out);
  EXPECT_EQ(0, std::memcmp(out.positions.data(), rest.positions.data(), 3 * sizeof(glm::vec3)));
  EXPECT_DOUBLE_EQ(turntable_angle(3, 360.0, 96), 11.25);
  EXPECT_DOUBLE_EQ(turntable_angle(-1, 90.0, 4), 337.5);
  r.turntable_deg = 37.0;
  pose_scene(rest, r, out);
  EXPECT_NEAR(glm::length(glm::dvec3(out.positions[0]) - r.pivot), 1.0, 1e-6);
}
