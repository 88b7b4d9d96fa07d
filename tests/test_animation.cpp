// glTF animation sampling (host/scene/animation.cpp) against hand-computed values: STEP, LINEAR,
// spherical LINEAR across the quaternion double cover, CUBICSPLINE Hermite with tangents scaled by the
// key interval, clamping outside the keys, malformed samplers.
#include <gtest/gtest.h>

#include <cmath>

#include "pmr/error.h"
#include "scene/animation.h"

namespace pmr {
namespace {

void expect_near(const std::vector<float>& got, const std::vector<float>& want, float tol = 1e-6f) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], tol) << "component " << i;
}

AnimationSampler three_keys(Interpolation i) {
  AnimationSampler s;
  s.interpolation = i;
  s.times = {0.0f, 1.0f, 2.0f};
  s.values = {0, 0, 0, 1, 2, 3, 5, 5, 5};
  s.width = 3;
  return s;
}

TEST(Animation, StepHoldsEachKeyUntilTheNext) {
  const AnimationSampler s = three_keys(Interpolation::Step);
  expect_near(sample(s, 0.5), {0, 0, 0});
  expect_near(sample(s, 1.0), {1, 2, 3});
  expect_near(sample(s, 1.99), {1, 2, 3});
  expect_near(sample(s, -3.0), {0, 0, 0});
  expect_near(sample(s, 7.0), {5, 5, 5});
}

TEST(Animation, LinearInterpolatesAndClamps) {
  const AnimationSampler s = three_keys(Interpolation::Linear);
  expect_near(sample(s, 0.25), {0.25f, 0.5f, 0.75f});
  expect_near(sample(s, 1.5), {3.0f, 3.5f, 4.0f});
  expect_near(sample(s, -1.0), {0, 0, 0});
  expect_near(sample(s, 2.5), {5, 5, 5});
}

TEST(Animation, RotationsSlerpOnTheShorterArc) {
  AnimationSampler s;
  s.interpolation = Interpolation::Linear;
  s.rotation = true;
  s.width = 4;
  s.times = {0.0f, 1.0f};
  const float h = float(std::sqrt(0.5));
  s.values = {0, 0, 0, 1, 0, 0, h, h};  // identity, then 90 degrees about +Z
  const std::vector<float> want = {0, 0, float(std::sin(M_PI / 8)), float(std::cos(M_PI / 8))};  // 45 degrees
  expect_near(sample(s, 0.5), want);
  // the same end rotation written as -q: still the short way, the same 45 degrees
  s.values = {0, 0, 0, 1, 0, 0, -h, -h};
  expect_near(sample(s, 0.5), want);
  // a quarter of the way: 22.5 degrees
  expect_near(sample(s, 0.25), {0, 0, float(std::sin(M_PI / 16)), float(std::cos(M_PI / 16))});
}

TEST(Animation, CubicSplineScalesTangentsByTheKeyInterval) {
  AnimationSampler s;
  s.interpolation = Interpolation::CubicSpline;
  s.width = 1;
  s.times = {0.0f, 2.0f};
  // per key: in-tangent, value, out-tangent
  s.values = {0, 0, 2, 0, 1, 0};
  // p(u) = h00 v0 + h10 dt b0 + h01 v1 + h11 dt a1 with dt = 2, b0 = 2, a1 = 0, v0 = 0, v1 = 1
  expect_near(sample(s, 1.0), {1.0f});      // u = 1/2: 0.125 * 2 * 2 + 0.5 * 1
  expect_near(sample(s, 0.5), {0.71875f});  // u = 1/4: 0.140625 * 4 + 0.15625
  expect_near(sample(s, 2.0), {1.0f});      // the last key's value, not a tangent
  expect_near(sample(s, -1.0), {0.0f});
}

TEST(Animation, MalformedSamplersAreRefused) {
  AnimationSampler s = three_keys(Interpolation::CubicSpline);  // 9 values, CUBICSPLINE needs 27
  EXPECT_THROW(sample(s, 0.5), Error);
  s.times.clear();
  EXPECT_THROW(sample(s, 0.5), Error);
  EXPECT_EQ(parse_interpolation("STEP"), Interpolation::Step);
  EXPECT_THROW(parse_interpolation("CUBIC"), Error);
}

}  // namespace
}  // namespace pmr

// A time just below the last key that rounds to it as a float (1.2 < 1.2f) stays inside the key arrays.
TEST(Animation, TimeJustBelowTheLastKeyStaysInRange) {
  pmr::AnimationSampler s;
  s.interpolation = pmr::Interpolation::Linear;
  s.width = 1;
  s.times = {0.0f, 1.2f};
  s.values = {0.0f, 10.0f};
  ASSERT_LT(1.2, double(1.2f));
  const std::vector<float> v = pmr::sample(s, 1.2);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_NEAR(v[0], 10.0f, 1e-5f);
  s.interpolation = pmr::Interpolation::Step;
  EXPECT_EQ(pmr::sample(s, 1.2)[0], 0.0f);  // still the first key's interval
}
