// KHR_materials_anisotropy (DESIGN 4c): GGX stretched along a direction of the tangent frame, in every
// path, against the double-precision reference (tests/reference/pbr_reference.cpp), under a point light
// and an environment image (the bent normal); the anisotropic distribution's normalization by numerical
// integration; and the Khronos sample model AnisotropyStrengthTest.
#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>
#include <cmath>
#include <memory>

#include "pbr_support.h"
#include "reference/pbr_reference.h"
#include "shading/environment.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::VoxelReference;

constexpr double kPi = glm::pi<double>();

// test::add_feature_quads:
// 1. a metal of roughness 0.4, strength 0.6 along the tangent;
// 2. a dielectric of roughness 0.5, strength 0.9 rotated by 0.7 rad, with a normal map;
// 3. a metal of roughness 0.35, strength 1 x an anisotropyTexture (direction RG turning across the quad,
//    strength B), rotated by -0.4 rad;
// 4. material 1 without anisotropy.
Scene anisotropic_quads() {
  Scene s = test::empty_scene(false);
  const int directions = test::add_texture16(s, [](int x, int y) {
    const double a = 0.2 * x - 0.1 * y;
    return glm::dvec4(0.5 + 0.5 * std::cos(a), 0.5 + 0.5 * std::sin(a), 0.3 + 0.045 * y, 1.0);
  });
  const int normal = test::add_texture16(s, [](int x, int y) {
    return glm::dvec4(0.5 + 0.3 * std::cos(0.5 * y), 0.5 + 0.3 * std::sin(0.8 * x), 0.9, 1.0);
  });
  test::add_feature_quads(s, {{{0.9f, 0.7f, 0.5f}, {0.2f, 0.3f, 0.6f}, {0.8f, 0.8f, 0.85f}, {0.9f, 0.7f, 0.5f}}},
                          [&](int q, SceneMaterialInputs& in) {
                            in.metallic = q == 1 ? 0.0f : 1.0f;
                            in.roughness = q == 1 ? 0.5f : q == 2 ? 0.35f : 0.4f;
                            in.has_anisotropy = q < 3;
                            in.anisotropy_strength = q == 0 ? 0.6f : q == 1 ? 0.9f : q == 2 ? 1.0f : 0.0f;
                            in.anisotropy_rotation = q == 1 ? 0.7f : q == 2 ? -0.4f : 0.0f;
                            if (q == 1) {
                              in.slots[kSlotNormal].texture = normal, in.slots[kSlotNormal].texcoord = 0;
                              in.normal_scale = 0.7f;
                            }
                            if (q == 2)
                              in.slots[kSlotAnisotropy].texture = directions, in.slots[kSlotAnisotropy].texcoord = 0;
                          });
  return s;
}

Scene isotropic(Scene s) {
  for (SceneMaterialInputs& in : s.material_inputs) in.anisotropy_strength = 0.0f;
  return s;
}

// Under the point light (and the uniform environment) every shaded voxel is within 1% + 1e-3 of the
// reference, which reads the strength, rotation, texture and tangents itself; the isotropic reference
// is outside that bound on over a third of the voxels of each anisotropic quad (measured: 38% or more).
TEST(Anisotropy, EveryShadedVoxelMatchesTheReferenceUnderALight) {
  const Scene s = anisotropic_quads();
  const double worst =
      test::expect_feature_matches_reference(s, isotropic(s), {test::reference_light(s.lights[0])}, 4, 3);
  std::printf("[ aniso    ] largest error %.3f of the bound\n", worst);
}

// Under an environment image alone (a sky with a sun; the scene's light removed) the environment is
// reflected about the bent normal: every voxel within the bound of the reference, and the reflection
// about n instead is outside it on much of the anisotropic quads.
TEST(Anisotropy, TheEnvironmentIsReflectedAboutTheBentNormal) {
  const Scene s = anisotropic_quads();
  const test::FeatureCheck r = test::check_feature_under(s, isotropic(s), test::sky_environment(30.0, 1.0));
  EXPECT_EQ(r.check.bad, 0u);
  for (uint32_t material = 1; material <= 3; ++material)
    EXPECT_GT(r.changed.at(material), r.voxels.at(material) / 4) << "material " << material;
  std::printf("[ aniso    ] the sky: largest error %.3f of the bound\n", r.check.worst);
}

// Every path draws it alike (test::expect_paths_agree), and it changes the fused image.
TEST(Anisotropy, EveryPathShadesIt) {
  const Rig rig = test::small_rig(5, 48, 32);
  const Scene s = anisotropic_quads(), bare = isotropic(s);
  test::expect_paths_agree(s, rig, test::pbr_config(), &bare);
}

// The stretched distribution is normalized: the integral of D(h) (n.h) over the hemisphere of h is 1
// for every strength and roughness (by the reference's D: brdf_cos of a white metal head-on, whose
// F = 1, divided by Vis, is D n.l; here D alone, from its formula in the reference's terms). Checked by
// the midpoint rule on 1600 x 800 directions; and the lobe's albedo never exceeds 1.
TEST(Anisotropy, TheDistributionIsNormalized) {
  const glm::dvec3 n(0.0, 0.0, 1.0), t(1.0, 0.0, 0.0), b(0.0, 1.0, 0.0);
  for (double r : {0.3, 0.6}) {
    for (double s : {0.0, 0.5, 1.0}) {
      const double alpha = r * r, at = glm::mix(alpha, 1.0, s * s), ab = alpha;
      const int T = 1600, F = 800;
      double sum = 0.0, albedo = 0.0;
      const glm::dvec3 v = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
      for (int i = 0; i < T; ++i) {
        const double theta = (i + 0.5) * (kPi / 2.0) / T;
        for (int j = 0; j < F; ++j) {
          const double phi = (j + 0.5) * 2.0 * kPi / F, dw = std::sin(theta) * (kPi / 2.0 / T) * (2.0 * kPi / F);
          const glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
          const double x = glm::dot(t, h) / at, y = glm::dot(b, h) / ab, q = x * x + y * y + h.z * h.z;
          sum += h.z / (kPi * at * ab * q * q) * dw;
          // the white metal's f cos toward v for light from direction h (as l): its albedo
          albedo += ref::brdf_cos(glm::dvec3(1.0), 1.0, r, n, v, h, 1.5, 0.0, 1.0, glm::dvec3(1.0), s, t).x * dw;
        }
      }
      EXPECT_NEAR(sum, 1.0, 2e-3) << "r " << r << " s " << s;
      EXPECT_LE(albedo, 1.0) << "r " << r << " s " << s;
      EXPECT_GT(albedo, 0.4) << "r " << r << " s " << s;  // single scattering loses some: 0.497 at r 0.6, s 1
    }
  }
}

// The Khronos sample model AnisotropyStrengthTest (../shared/gltf) loads without the extension's
// warning, and every shaded voxel with roughness >= 0.2 matches the reference, many of them anisotropic.
TEST(Anisotropy, SampleModelMatchesTheReference) {
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: AnisotropyStrengthTest skipped";
  const Scene s = load_scene(dir + "/AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb");
  for (const std::string& w : s.warnings) EXPECT_EQ(w.find("KHR_materials_anisotropy"), std::string::npos) << w;
  glm::dvec3 lo, hi;
  ASSERT_TRUE(scene_bounds(s, lo, hi));
  RigConfig rc;
  rc.views = 5, rc.view_w = 128, rc.view_h = 96;
  const Rig rig = make_rig(rc, Display{}, lo, hi);
  const test::Rendered out = test::render_pbr(s, rig);
  const VoxelReference reference(s, rig, out);
  const test::ModelCheck r = test::check_model(
      reference, [](const ref::SurfacePoint& sp) { return sp.roughness >= 0.2; },
      [](const ref::SurfacePoint& sp) { return sp.anisotropy > 0.0; });
  EXPECT_EQ(r.check.bad, 0u);
  EXPECT_GT(r.compared, size_t(2000));
  EXPECT_GT(r.counted, r.compared / 2);
  std::printf("[ aniso    ] AnisotropyStrengthTest: %zu voxels (%zu anisotropic), largest error %.3f of the bound\n",
              r.compared, r.counted, r.check.worst);
}

// The error of the bent-normal approximation (docs/SHADING.md, "Anisotropy"): the environment term of a
// white metal (F = 1) under the studio, (A + B) P(reflect(-v, n'), r), against the brute-force integral
// of the stretched lobe, integral of L(l) D Vis (n.l) over the hemisphere (2000 x 1000 directions,
// the studio's radiance image bilinear). Printed per roughness, strength and view angle; strength 0
// measures the split-sum approximation itself, whose error the anisotropic one adds to. A guard on the
// documented figures rather than a bound the model promises.
TEST(Anisotropy, BentNormalErrorAgainstBruteForce) {
  const Environment studio = Environment::studio();
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.2, 0.5, 0.8));
  const glm::dvec3 t = glm::normalize(glm::cross(glm::dvec3(0.0, 1.0, 0.0), n)), b = glm::cross(n, t);
  double worst_iso = 0.0, worst_aniso = 0.0;
  for (double r : {0.3, 0.6})
    for (double angle : {0.0, 45.0})
      for (double s : {0.0, 0.5, 1.0}) {
        const double a = angle * kPi / 180.0;
        const glm::dvec3 v = std::cos(a) * n + std::sin(a) * (0.6 * t + 0.8 * b);
        const int T = 2000, F = 1000;
        glm::dvec3 brute(0.0);
        for (int i = 0; i < T; ++i) {
          const double theta = (i + 0.5) * (kPi / 2.0) / T;
          for (int j = 0; j < F; ++j) {
            const double phi = (j + 0.5) * 2.0 * kPi / F, dw = std::sin(theta) * (kPi / 2.0 / T) * (2.0 * kPi / F);
            const glm::dvec3 l = std::sin(theta) * (std::cos(phi) * t + std::sin(phi) * b) + std::cos(theta) * n;
            const double f = ref::brdf_cos(glm::dvec3(1.0), 1.0, r, n, v, l, 1.5, 0.0, 1.0, glm::dvec3(1.0), s, t).x;
            if (f > 0.0) brute += f * dw * studio.radiance(l);
          }
        }
        glm::dvec3 d = glm::reflect(-v, n);
        if (s > 0.0) {
          const glm::dvec3 bent_to = glm::cross(glm::cross(b, v), b);
          d = glm::reflect(-v, glm::normalize(glm::mix(bent_to, n, std::pow(1.0 - s * (1.0 - r), 4.0))));
        }
        const glm::dvec2 ab = split_sum(glm::dot(n, v), r);
        const glm::dvec3 approx = (ab.x + ab.y) * studio.prefiltered(d, r);
        const double lum_b = (brute.x + brute.y + brute.z) / 3.0, lum_a = (approx.x + approx.y + approx.z) / 3.0;
        const double err = std::abs(lum_a - lum_b) / lum_b;
        (s == 0.0 ? worst_iso : worst_aniso) = std::max(s == 0.0 ? worst_iso : worst_aniso, err);
        std::printf(
            "[ aniso    ] r %.1f, v at %2.0f deg, strength %.1f: brute force %.4f, approximation %.4f (%+.1f%%)\n", r,
            angle, s, lum_b, lum_a, 100.0 * (lum_a - lum_b) / lum_b);
      }
  // measured (docs/SHADING.md): the split-sum's own error up to 19%; with the bent normal up to +164% at
  // strength 1, where the stretched lobe's albedo falls far below the isotropic one the table holds
  EXPECT_LT(worst_iso, 0.25);
  EXPECT_LT(worst_aniso, 2.0);
}

}  // namespace
}  // namespace pmr
