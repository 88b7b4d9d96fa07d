// The environment's occlusion (DESIGN section 4d; host/shading/environment_occlusion.h): its diffuse and
// specular visibility against the exact fractions, ray-cast in double precision
// (tests/reference/visibility_reference.h), and what it does to the shaded image.
#include <gtest/gtest.h>

#include <cmath>

#include "environment_maps.h"
#include "pbr_support.h"
#include "pipeline/shadow_sizes.h"
#include "reference/visibility_reference.h"
#include "shading/environment_occlusion.h"
#include "shadow_support.h"
#include "test_util.h"

namespace pmr {
namespace {

// A ground plane at y = -0.5, a ball resting on it and a box standing beside it: contact regions, a
// gap between two casters and open ground.
Scene ball_and_box() {
  Scene s = test::empty_scene(false);
  test::add_quad(s, {-1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, -1.5f}, {-1.5f, -0.5f, -1.5f});
  test::add_sphere(s, {-0.4f, -0.1f, 0.1f}, 0.4f, 10);
  test::add_box(s, {0.2f, -0.5f, -0.4f}, {0.6f, 0.3f, 0.2f});
  return s;
}

// A frame of the unit vector n: t, b, n.
void frame_of(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
  t = glm::normalize(glm::cross(std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0), n));
  b = glm::cross(n, t);
}

// The exact diffuse visibility of a uniform environment at receiver r: the cosine-weighted fraction of
// its hemisphere that sees past the scene, from n x n stratified directions (Malley's method: points
// of the unit disk raised onto the hemisphere).
double exact_diffuse_visibility(const Scene& s, const test::Receiver& r, int n) {
  glm::dvec3 t, b;
  frame_of(r.n, t, b);
  double on = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = (i + 0.5) / n, v = (j + 0.5) / n, rad = std::sqrt(u), a = 2.0 * M_PI * v;
      const double x = rad * std::cos(a), y = rad * std::sin(a), z = std::sqrt(std::max(0.0, 1.0 - u));
      on += ref::transmittance(s, r.p, x * t + y * b + z * r.n, 1e-7, 1e300);
    }
  return on / (double(n) * n);
}

// The exact specular visibility: the fraction of the GGX lobe's reflected light, integral of
// f_spec(v, l) n.l V(l) dl over that of f_spec(v, l) n.l, from n x n stratified directions of the
// hemisphere drawn by cosine and weighted by f_spec.
double exact_specular_visibility(const Scene& s, const test::Receiver& r, const glm::dvec3& v, double roughness,
                                 int n) {
  glm::dvec3 t, b;
  frame_of(r.n, t, b);
  const double a2 = std::pow(roughness, 4.0);
  double on = 0.0, all = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = (i + 0.5) / n, w = (j + 0.5) / n, rad = std::sqrt(u), a = 2.0 * M_PI * w;
      const glm::dvec3 l = rad * std::cos(a) * t + rad * std::sin(a) * b + std::sqrt(std::max(0.0, 1.0 - u)) * r.n;
      const glm::dvec3 h = glm::normalize(l + v);
      const double nh = glm::dot(r.n, h), d = nh * nh * (a2 - 1.0) + 1.0;
      const double f = a2 / (d * d);  // D; Vis and F change little over the lobe
      all += f, on += f * ref::transmittance(s, r.p, l, 1e-7, 1e300);
    }
  return on / all;
}

std::vector<test::Receiver> ground_receivers(double step) {
  std::vector<test::Receiver> at;
  for (double x = -1.2; x <= 1.2; x += step)
    for (double z = -1.0; z <= 1.0; z += step) {
      const bool in_box = x > 0.2 && x < 0.6 && z > -0.4 && z < 0.2;
      if (!in_box) at.push_back({{x, -0.5, z}, {0, 1, 0}});
    }
  return at;
}

// Under the uniform environment, over the ground's receivers that the scene shades (exact diffuse
// visibility below 0.99), the mean |V_d - exact| is at most 0.03.
TEST(EnvironmentOcclusion, DiffuseVisibilityMatchesRayCasting) {
  const Scene s = ball_and_box();
  const test::ShadowMaps m = test::render_maps(s, nullptr, 1.0);
  const std::vector<test::Receiver> at = ground_receivers(0.05);
  const std::vector<glm::dvec3> up(at.size(), glm::dvec3(0, 1, 0));
  const std::vector<glm::vec2> v = test::probe_environment(m, kOcclusionDirections, at, up, 1.0f);
  double sum = 0.0, bias = 0.0, worst = 0.0;
  size_t shaded = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    const double e = exact_diffuse_visibility(s, at[i], 16);
    if (e >= 0.99) continue;
    ++shaded, sum += std::abs(v[i].x - e), bias += v[i].x - e, worst = std::max(worst, std::abs(v[i].x - e));
  }
  const double mean = sum / double(shaded);
  std::printf(
      "[ env occl ] %zu receivers shaded by the scene: mean |V_d error| %.4f (mean V_d - exact %.4f), worst "
      "%.3f\n",
      shaded, mean, bias / double(shaded), worst);
  EXPECT_GT(shaded, 1000u);
  EXPECT_LE(mean, 0.03);
}

// A plane alone shadows nothing of itself: from every direction above it, grazing ones included, its
// own map must not hide it (no acne), so V_d and V_s read 1 over all of it.
TEST(EnvironmentOcclusion, AFlatGroundDoesNotOccludeItself) {
  Scene s = test::empty_scene(false);
  test::add_quad(s, {-6.0f, 0.0f, 6.0f}, {6.0f, 0.0f, 6.0f}, {6.0f, 0.0f, -6.0f}, {-6.0f, 0.0f, -6.0f});
  const test::ShadowMaps m = test::render_maps(s, nullptr, 1.0);
  std::vector<test::Receiver> at;
  for (double x = -5.9; x <= 5.9; x += 0.173)
    for (double z = -5.9; z <= 5.9; z += 0.173) at.push_back({{x, 0.0, z}, {0, 1, 0}});
  const glm::dvec3 r = glm::normalize(glm::dvec3(0.3, 0.2, 0.9));
  const std::vector<glm::vec2> v =
      test::probe_environment(m, kOcclusionDirections, at, std::vector<glm::dvec3>(at.size(), r), 16.0f);
  float lowest_d = 1.0f, lowest_s = 1.0f;
  for (const glm::vec2& x : v) lowest_d = std::min(lowest_d, x.x), lowest_s = std::min(lowest_s, x.y);
  std::printf("[ env occl ] a lone plane: lowest V_d %.4f, V_s %.4f over %zu receivers\n", lowest_d, lowest_s,
              at.size());
  EXPECT_GE(lowest_d, 0.999f);
  EXPECT_GE(lowest_s, 0.999f);
}

// The specular lobe's visibility, seen from 45 degrees above the ground: on a rough surface (r = 0.7,
// whose GGX lobe is wider than the directions' spacing) the mean |V_s - exact| is at most 0.04; on a
// glossy one (r = 0.3) the estimate's lobe is never narrower than the spacing allows, and the error is
// reported.
TEST(EnvironmentOcclusion, SpecularVisibilityFollowsTheLobe) {
  const Scene s = ball_and_box();
  const test::ShadowMaps m = test::render_maps(s, nullptr, 1.0);
  const std::vector<test::Receiver> at = ground_receivers(0.1);
  const glm::dvec3 v = glm::normalize(glm::dvec3(0.0, 1.0, 1.0)), r = glm::dvec3(0.0, v.y, -v.z);
  const std::vector<glm::dvec3> reflected(at.size(), r);
  for (const double roughness : {0.7, 0.3}) {
    const double a = roughness * roughness;
    // the kernel's sharpness (cl/shade.h, environment_occlusion_lanes)
    const float sharpness = float(std::min(0.5 / (a * a), kOcclusionDirections / 4.0));
    const std::vector<glm::vec2> vs = test::probe_environment(m, kOcclusionDirections, at, reflected, sharpness);
    double sum = 0.0, bias = 0.0;
    size_t shaded = 0;
    for (size_t i = 0; i < at.size(); ++i) {
      const double e = exact_specular_visibility(s, at[i], v, roughness, 24);
      if (e >= 0.99) continue;
      ++shaded, sum += std::abs(vs[i].y - e), bias += vs[i].y - e;
    }
    const double mean = sum / double(shaded);
    std::printf(
        "[ env occl ] specular, roughness %.1f: %zu receivers shaded, mean |V_s error| %.4f (mean V_s - "
        "exact %.4f)\n",
        roughness, shaded, mean, bias / double(shaded));
    EXPECT_GT(shaded, 150u);
    if (roughness >= 0.5) {
      EXPECT_LE(mean, 0.04);
    }
  }
}

// A sun taken out of an environment image casts its own shadow, and the occlusion leaves the sky's
// light there: on the ground in a pole's sun shadow, away from its foot, the sun's visibility is 0 and
// the environment's diffuse visibility stays above 0.9 (the pole hides little of the sky).
TEST(EnvironmentOcclusion, SkyLightStaysInASunsShadow) {
  Scene s = test::empty_scene(false);
  test::add_quad(s, {-3.0f, -0.6f, 3.0f}, {3.0f, -0.6f, 3.0f}, {3.0f, -0.6f, -3.0f}, {-3.0f, -0.6f, -3.0f});
  test::add_box(s, {-0.05f, -0.6f, -0.05f}, {0.05f, 0.8f, 0.05f});
  auto env = std::make_shared<const Environment>(
      Environment::with_lights_taken_out(test::make_map(256, 128, test::sun_sky), "sky"));
  ASSERT_EQ(env->distant_lights().size(), 1u);
  const SceneLight sun = env->distant_lights()[0];
  const test::ShadowMaps m = test::render_maps(s, env);
  const std::vector<PmrShadowMap> sun_maps(m.maps.begin(), m.maps.begin() + kShadowSamples);
  std::vector<test::Receiver> at;
  const glm::dvec3 toward = glm::normalize(sun.position);
  const glm::dvec3 along = glm::normalize(glm::dvec3(-toward.x, 0.0, -toward.z));
  for (double d = 0.3; d <= 1.2; d += 0.05) at.push_back({glm::dvec3(0.0, -0.6, 0.0) + d * along, {0, 1, 0}});
  const std::vector<float> v_sun = test::probe({sun_maps, m.depth}, sun, at);
  const std::vector<glm::vec2> v_env = test::probe_environment(m, int(m.maps.size()) - kShadowSamples, at,
                                                               std::vector<glm::dvec3>(at.size(), {0, 1, 0}), 1.0f);
  size_t in_shadow = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    if (v_sun[i] > 0.0f) continue;
    ++in_shadow;
    EXPECT_GT(v_env[i].x, 0.9f) << "at " << glm::length(at[i].p - glm::dvec3(0.0, -0.6, 0.0)) << " m from the pole";
  }
  std::printf("[ env occl ] %zu receivers in the pole's sun shadow\n", in_shadow);
  EXPECT_GE(in_shadow, 10u);
}

}  // namespace
}  // namespace pmr
