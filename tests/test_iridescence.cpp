// KHR_materials_iridescence (DESIGN 4c): the thin film's Fresnel term, in every path, against the
// double-precision reference (tests/reference/pbr_reference.cpp); the reference's film against its
// limits; and the Khronos sample model IridescenceSuzanne.
#include <gtest/gtest.h>

#include <cmath>

#include "pbr_support.h"
#include "reference/pbr_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::VoxelReference;

// test::add_feature_quads:
// 1. a grey dielectric (F0 0.04) under a film of ior 1.33 and 400 nm (the maximum, no texture);
// 2. a grey metal under a film of ior 1.8 and 250 nm, factor 0.8;
// 3. a dark dielectric with an iridescenceTexture and a thickness texture (200 to 600 nm) under a clear
//    coat (the film's outside is then the coat's ior 1.5);
// 4. material 1 without the film.
Scene iridescent_quads() {
  Scene s = test::empty_scene(false);
  const int factor = test::add_texture16(s, [](int x, int) { return glm::dvec4(0.3 + 0.045 * x, 0.0, 0.0, 1.0); });
  const int thickness =
      test::add_texture16(s, [](int x, int y) { return glm::dvec4(0.0, (x + 15 * y) / 240.0, 0, 1); });
  test::add_feature_quads(s, {{{0.4f, 0.4f, 0.4f}, {0.5f, 0.5f, 0.5f}, {0.05f, 0.05f, 0.1f}, {0.4f, 0.4f, 0.4f}}},
                          [&](int q, SceneMaterialInputs& in) {
                            in.metallic = q == 1 ? 1.0f : 0.0f;
                            in.roughness = 0.3f + 0.1f * float(q % 3);
                            in.has_iridescence = q < 3;
                            in.iridescence = q == 1 ? 0.8f : q < 3 ? 1.0f : 0.0f;
                            in.iridescence_ior = q == 1 ? 1.8f : 1.33f;
                            if (q == 1) in.iridescence_thickness[1] = 250.0f;
                            if (q == 2) {
                              in.iridescence_thickness[0] = 200.0f, in.iridescence_thickness[1] = 600.0f;
                              in.slots[kSlotIridescence].texture = factor;
                              in.slots[kSlotIridescenceThickness].texture = thickness;
                              in.has_clearcoat = true, in.clearcoat = 1.0f, in.clearcoat_roughness = 0.3f;
                            }
                          });
  return s;
}

Scene without_film(Scene s) {
  for (SceneMaterialInputs& in : s.material_inputs) in.iridescence = 0.0f;
  return s;
}

// Under a point light every shaded voxel is within 1% + 1e-3 of the reference, which evaluates the film
// from the scene's inputs itself; without the film the reference leaves that bound on over half of
// each iridescent quad's voxels.
TEST(Iridescence, EveryShadedVoxelMatchesTheReference) {
  const Scene s = iridescent_quads();
  const double worst =
      test::expect_feature_matches_reference(s, without_film(s), {test::reference_light(s.lights[0])}, 4, 2);
  std::printf("[ irid     ] largest error %.3f of the bound\n", worst);
}

TEST(Iridescence, EveryPathShadesIt) {
  const Rig rig = test::small_rig(5, 48, 32);
  const Scene s = iridescent_quads(), bare = without_film(s);
  test::expect_paths_agree(s, rig, test::pbr_config(), &bare);
}

// The reference's film against its limits: total internal reflection gives 1; a thick film (50 um)
// loses its interference (the Fourier terms vanish) and reflects the incoherent sum R12 + T^2 R23 /
// (1 - R12 R23) of its two interfaces; over a grid of angles, thicknesses, iors and base F0s the term
// stays within [0, 1.25] (the analytic spectral integration is not bounded by 1: up to 1.232).
TEST(Iridescence, TheFilmMeetsItsLimits) {
  EXPECT_EQ(ref::thin_film_fresnel(1.5, 1.2, 0.2, 300.0, glm::dvec3(0.04)), glm::dvec3(1.0));
  for (double cos1 : {1.0, 0.6, 0.2}) {
    const double ior = 1.4, f0 = 0.3;
    const double R12 = std::pow((ior - 1.0) / (ior + 1.0), 2.0) +
                       (1.0 - std::pow((ior - 1.0) / (ior + 1.0), 2.0)) * std::pow(1.0 - cos1, 5.0);
    const double cos2 = std::sqrt(1.0 - (1.0 - cos1 * cos1) / (ior * ior));
    const double base = (1.0 + std::sqrt(f0)) / (1.0 - std::sqrt(f0)), r1 = std::pow((base - ior) / (base + ior), 2.0);
    const double R23 = r1 + (1.0 - r1) * std::pow(1.0 - cos2, 5.0);
    const double incoherent = R12 + (1.0 - R12) * (1.0 - R12) * R23 / (1.0 - R12 * R23);
    const glm::dvec3 F = ref::thin_film_fresnel(1.0, ior, cos1, 50000.0, glm::dvec3(f0));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(F[c], incoherent, 1e-6) << "cos " << cos1;
  }
  double lo = 1e9, hi = -1e9;
  for (double cos1 = 0.05; cos1 <= 1.0; cos1 += 0.05)
    for (double d = 0.0; d <= 1000.0; d += 25.0)
      for (double ior : {1.0, 1.3, 1.8, 2.5})
        for (double f0 : {0.02, 0.04, 0.3, 0.9}) {
          const glm::dvec3 F = ref::thin_film_fresnel(1.0, ior, cos1, d, glm::dvec3(f0));
          lo = std::min(lo, std::min(F.x, std::min(F.y, F.z))), hi = std::max(hi, std::max(F.x, std::max(F.y, F.z)));
        }
  EXPECT_GE(lo, 0.0);
  EXPECT_LE(hi, 1.25);  // measured: 1.232
  std::printf("[ irid     ] the film's Fresnel term over the grid: %.4f to %.4f\n", lo, hi);
}

// The Khronos sample model IridescenceSuzanne (../shared/gltf) loads without the extension's warning.
// Its materials are smooth (roughness 0.1), so it is lit by an environment of radiance 1 alone (its
// directional light removed):
// every opaque voxel (the glass one needs the transmission source, which the reference lacks) matches
// the reference, most of them iridescent.
TEST(Iridescence, SampleModelMatchesTheReference) {
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: IridescenceSuzanne skipped";
  Scene s = load_scene(dir + "/IridescenceSuzanne/glTF/IridescenceSuzanne.gltf");
  s.lights.clear();  // its sun would put sub-voxel highlights on the smooth surfaces
  for (const std::string& w : s.warnings) EXPECT_EQ(w.find("KHR_materials_iridescence"), std::string::npos) << w;
  glm::dvec3 lo, hi;
  ASSERT_TRUE(scene_bounds(s, lo, hi));
  RigConfig rc;
  rc.views = 5, rc.view_w = 160, rc.view_h = 96;
  const Rig rig = make_rig(rc, Display{}, lo, hi);
  const test::Rendered out = test::render_pbr(s, rig, Method::Pmr, TextureFilter::Bilinear, test::white_environment());
  VoxelReference reference(s, rig, out);
  reference.lights.clear();
  reference.env = test::uniform_environment(1.0);
  const test::ModelCheck r = test::check_model(
      reference, [](const ref::SurfacePoint& sp) { return sp.transmission == 0.0; },
      [](const ref::SurfacePoint& sp) { return sp.iridescence > 0.0; });
  EXPECT_EQ(r.check.bad, 0u);
  EXPECT_GT(r.compared, size_t(1000));
  EXPECT_GT(r.counted, r.compared / 2);
  std::printf("[ irid     ] IridescenceSuzanne: %zu voxels (%zu iridescent), largest error %.3f of the bound\n",
              r.compared, r.counted, r.check.worst);
}

}  // namespace
}  // namespace pmr
