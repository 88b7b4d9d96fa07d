// KHR_materials_specular (DESIGN 4c): the dielectric's Fresnel weight and colour, in every path, against
// the double-precision reference (tests/reference/pbr_reference.cpp); the white furnace of a material
// whose specular weight is 0; and the Khronos sample model SpecularTest.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <functional>
#include <map>
#include <memory>

#include "pbr_support.h"
#include "reference/pbr_reference.h"
#include "reference/shade_reference.h"
#include "shading/environment.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::BoundCheck;
using test::VoxelReference;

using test::add_texture16;
using test::render_pbr;

// test::add_feature_quads, roughness 0.3 .. 0.5:
// 1. a dark dielectric (where the specular term shows), specular weight 0.5 and colour (1, 0.6, 0.2) times
//    one texture holding both (sRGB colour, weight in alpha: the kernels read it once);
// 2. a grey dielectric of ior 1.8 whose colour (3, 10, 30) clips F0 to 1 in green and blue;
// 3. a half-metal with a specularTexture (A) and an sRGB specularColorTexture on TEXCOORD_0;
// 4. material 1 without the extension.
Scene specular_quads() {
  Scene s = test::empty_scene(false);
  const int weight =
      add_texture16(s, [](int x, int y) { return glm::dvec4(0.0, 0.0, 0.0, 0.1 + 0.05 * x + 0.01 * y); });
  const int colour = add_texture16(s, [](int x, int y) { return glm::dvec4(x / 15.0, 0.3 + 0.04 * y, 0.8, 1.0); });
  const int packed =
      add_texture16(s, [](int x, int y) { return glm::dvec4(0.6 + 0.02 * y, 1.0, 0.5 + x / 30.0, 0.5 + 0.03 * x); });
  test::add_feature_quads(s, {{{0.1f, 0.1f, 0.1f}, {0.4f, 0.4f, 0.4f}, {0.7f, 0.3f, 0.2f}, {0.1f, 0.1f, 0.1f}}},
                          [&](int q, SceneMaterialInputs& in) {
                            in.metallic = q == 2 ? 0.5f : 0.0f;
                            in.roughness = 0.3f + 0.1f * float(q % 3);
                            in.has_specular = q < 3;
                            if (q == 0) {
                              in.specular = 0.5f, in.specular_color[1] = 0.6f, in.specular_color[2] = 0.2f;
                              in.slots[kSlotSpecular].texture = in.slots[kSlotSpecularColor].texture = packed;
                            }
                            if (q == 1) {
                              in.ior = 1.8f;
                              in.specular_color[0] = 3.0f, in.specular_color[1] = 10.0f, in.specular_color[2] = 30.0f;
                            }
                            if (q == 2) {
                              in.slots[kSlotSpecular].texture = weight, in.slots[kSlotSpecular].texcoord = 0;
                              in.slots[kSlotSpecularColor].texture = colour, in.slots[kSlotSpecularColor].texcoord = 0;
                            }
                          });
  return s;
}

Scene without_specular(Scene s) {
  for (SceneMaterialInputs& in : s.material_inputs) {
    in.specular = 1.0f;
    for (float& c : in.specular_color) c = 1.0f;
    in.slots[kSlotSpecular].texture = in.slots[kSlotSpecularColor].texture = -1;
  }
  return s;
}

// Every shaded voxel within 1% + 1e-3 of the reference, which reads the extension's inputs from the
// scene's material inputs itself; the reference without them is outside that bound on most voxels of
// the three quads that have them, so a kernel ignoring the weight, the colour or a texture fails.
TEST(Specular, EveryShadedVoxelMatchesTheReference) {
  const Scene s = specular_quads();
  // measured: all voxels of materials 1 and 2, 80% of 3's
  const double worst =
      test::expect_feature_matches_reference(s, without_specular(s), {test::reference_light(s.lights[0])}, 4, 2);
  std::printf("[ specular ] largest error %.3f of the bound\n", worst);
}

// The white furnace where it holds: a specular weight of 0 leaves a white dielectric purely diffuse,
// so under an environment of radiance 1 everywhere (no lights) every voxel is 1 (Lambert's c_diff I);
// with the default weight it reflects more (the glTF model's specular lobe adds to the diffuse one).
TEST(Specular, AWeightOfZeroIsAWhiteFurnace) {
  const Rig rig = test::small_rig(3, 32, 24);
  const auto one = test::white_environment();
  for (float weight : {0.0f, 1.0f}) {
    Scene s = test::empty_scene(false);
    SceneMaterialInputs in;
    for (int slot = 0; slot < kTextureSlots; ++slot) in.slots[size_t(slot)].srgb = texture_slot_is_srgb(slot);
    in.metallic = 0.0f, in.roughness = 0.5f, in.has_specular = true, in.specular = weight;
    s.material_inputs = {in};
    test::quad(s, -2.0f, -2.0f, 2.0f, 2.0f, 0.0f, 0);
    const test::Rendered out = render_pbr(s, rig, Method::Pmr, TextureFilter::Bilinear, one);
    double lo = 1e9, hi = -1e9;
    for (size_t v = 0; v < out.key.size(); ++v) {
      if (out.key[v] == PMR_NO_KEY) continue;
      for (int c = 0; c < 3; ++c) {
        half h;
        h.setBits(out.volume[v * 4 + size_t(c)]);
        lo = std::min(lo, double(float(h))), hi = std::max(hi, double(float(h)));
      }
    }
    if (weight == 0.0f) {
      EXPECT_NEAR(lo, 1.0, 2e-3);
      EXPECT_NEAR(hi, 1.0, 2e-3);
    } else {
      EXPECT_GT(lo, 1.02) << "the default specular lobe reflects on top of the diffuse one";
    }
  }
}

// Every path (test::expect_paths_agree), and the extension changes the fused image.
TEST(Specular, EveryPathShadesIt) {
  const Rig rig = test::small_rig(5, 48, 32);
  const Scene s = specular_quads(), bare = without_specular(s);
  test::expect_paths_agree(s, rig, test::pbr_config(), &bare);
}

// The Khronos sample model SpecularTest (../shared/gltf) loads without the extension's warning. Its
// materials are mirror-like (roughness 0), so it is lit by an environment of radiance 1 everywhere and no
// light (no highlight narrower than a voxel): every shaded voxel matches the reference, most of them with
// a weight or colour other than 1.
TEST(Specular, SampleModelMatchesTheReference) {
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: SpecularTest skipped";
  const Scene s = load_scene(dir + "/SpecularTest/glTF/SpecularTest.gltf");
  for (const std::string& w : s.warnings) EXPECT_EQ(w.find("KHR_materials_specular"), std::string::npos) << w;
  glm::dvec3 lo, hi;
  ASSERT_TRUE(scene_bounds(s, lo, hi));
  RigConfig rc;
  rc.views = 5, rc.view_w = 128, rc.view_h = 96;
  const Rig rig = make_rig(rc, Display{}, lo, hi);
  const auto one = test::white_environment();
  const test::Rendered out = render_pbr(s, rig, Method::Pmr, TextureFilter::Bilinear, one);
  VoxelReference reference(s, rig, out);
  reference.lights.clear();
  reference.env = test::uniform_environment(1.0);
  const test::ModelCheck r = test::check_model(
      reference, [](const ref::SurfacePoint&) { return true; },
      [](const ref::SurfacePoint& sp) { return sp.specular != 1.0 || sp.specular_color != glm::dvec3(1.0); });
  EXPECT_EQ(r.check.bad, 0u);
  EXPECT_GT(r.compared, size_t(2000));
  EXPECT_GT(r.counted, r.compared / 4);
  std::printf("[ specular ] SpecularTest: %zu voxels (%zu with the extension), largest error %.3f of the bound\n",
              r.compared, r.counted, r.check.worst);
}

}  // namespace
}  // namespace pmr
