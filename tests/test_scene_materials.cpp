// The loader's half of physically based shading (DESIGN 4b): every material input with its own UV set
// and KHR_texture_transform, textures stored once with their colour space, TEXCOORD_n and TANGENT
// (read, morphed, skinned or transformed, mirrored, generated), KHR_lights_punctual lights posed with
// their nodes and the turntable, the validation errors and warnings, and what `pmr info` prints.
// Files are written by the tests; the tangent comparison uses the shared corpus and skips without it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "gltf_builder.h"
#include "pipeline/material_tables.h"
#include "pmr/error.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pmr::test::gltf_builder_detail;

constexpr double kPi = 3.14159265358979323846;

class SceneMaterialsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pmr_scene_materials_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

size_t warnings_with(const Scene& s, const std::string& part) {
  return size_t(
      std::count_if(s.warnings.begin(), s.warnings.end(), [&](const std::string& w) { return contains(w, part); }));
}

std::string all_warnings(const Scene& s) {
  std::string out;
  for (const std::string& w : s.warnings) out += w + "\n";
  return out;
}

::testing::AssertionResult near3(const glm::dvec3& a, const glm::dvec3& b, double tol) {
  if (glm::length(a - b) < tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << "), expected (" << b.x << ", "
                                       << b.y << ", " << b.z << ")";
}
#define EXPECT_VEC_NEAR(a, b, tol) EXPECT_TRUE(near3(glm::dvec3(a), glm::dvec3(b), tol))

const std::vector<uint8_t> kPixel = make_png(1, 1, 6, 8, {128, 128, 255, 255});

// A unit quad in z = 0 facing +Z (CCW), UVs in glTF's convention: (0, 0) at the top-left, so u grows
// with +x and v with -y. Accessors: POSITION, NORMAL, TEXCOORD_0, indices; returns their indices.
struct Quad {
  int pos, nrm, uv0, idx;
};
Quad quad(GltfFile& g) {
  Quad q;
  q.pos = g.data<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, kFloat, "VEC3");
  q.nrm = g.data<float>({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, kFloat, "VEC3");
  q.uv0 = g.data<float>({0, 1, 1, 1, 1, 0, 0, 0}, kFloat, "VEC2");
  q.idx = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, kUShort, "SCALAR");
  return q;
}

// The quad drawn once with each of glTF materials 0 .. n - 1 (POSITION, NORMAL, TEXCOORD_0), one node:
// the file's mesh and scene.
void quad_per_material(GltfFile& g, const Quad& q, int n) {
  json prims = json::array();
  for (int m = 0; m < n; ++m)
    prims.push_back({{"attributes", {{"POSITION", q.pos}, {"NORMAL", q.nrm}, {"TEXCOORD_0", q.uv0}}},
                     {"indices", q.idx},
                     {"material", m}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
}

// ---- materials -------------------------------------------------------------------------------------------

TEST_F(SceneMaterialsTest, EveryMaterialInputWithItsOwnSetAndTransform) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_materials_unlit",
                             "KHR_materials_diffuse_transmission"};
  const Quad q = quad(g);
  const int uv1 = g.data<float>({0, 2, 2, 2, 2, 0, 0, 0}, kFloat, "VEC2");
  write_bytes(dir_ / "normal.png", make_png(1, 1, 2, 8, {128, 128, 255}));
  write_bytes(dir_ / "diffuse.png", make_png(1, 1, 0, 8, {7}));
  g.add("images", {{"uri", png_uri(make_png(1, 1, 6, 8, {200, 100, 50, 255}))}});  // 0 base colour
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {255, 128, 64}))}});       // 1 ORM
  g.add("images", {{"uri", "normal.png"}});                                        // 2 normal (a file)
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {10, 20, 30}))}});         // 3 emissive
  g.add("images", {{"uri", "diffuse.png"}});  // 4 only KHR_materials_diffuse_transmission samples it
  for (int i : {0, 1, 2, 3, 1, 4}) g.add("textures", {{"source", i}});  // texture 4 = image 1 again
  json mr_transform = {{"offset", {0.5, 0}}, {"rotation", 0.25}, {"scale", {2, 3}}};
  g.add("materials",
        {{"name", "Everything"},
         {"pbrMetallicRoughness",
          {{"baseColorTexture", {{"index", 0}}},
           {"metallicFactor", 0.3},
           {"roughnessFactor", 0.6},
           {"metallicRoughnessTexture",
            {{"index", 1}, {"texCoord", 1}, {"extensions", {{"KHR_texture_transform", mr_transform}}}}}}},
         {"normalTexture", {{"index", 2}, {"texCoord", 1}, {"scale", 0.5}}},
         {"occlusionTexture", {{"index", 4}, {"strength", 0.25}}},
         {"emissiveTexture", {{"index", 3}, {"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}}},
         {"emissiveFactor", {1, 0.5, 0.25}},
         {"extensions",
          {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}},
           {"KHR_materials_diffuse_transmission",
            {{"diffuseTransmissionFactor", 1}, {"diffuseTransmissionColorTexture", {{"index", 5}}}}}}}});
  g.add("materials", {{"name", "Flat"}, {"extensions", {{"KHR_materials_unlit", json::object()}}}});
  g.mesh(json::array(
      {{{"attributes", {{"POSITION", q.pos}, {"NORMAL", q.nrm}, {"TEXCOORD_0", q.uv0}, {"TEXCOORD_1", uv1}}},
        {"indices", q.idx},
        {"material", 0}},
       {{"attributes", {{"POSITION", q.pos}, {"TEXCOORD_0", q.uv0}}}, {"indices", q.idx}, {"material", 1}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "materials"));

  ASSERT_EQ(s.material_inputs.size(), s.materials.size());
  ASSERT_EQ(s.material_inputs.size(), 3u);
  const SceneMaterialInputs& m = s.material_inputs[1];
  EXPECT_EQ(m.name, "Everything");
  EXPECT_FLOAT_EQ(m.metallic, 0.3f);
  EXPECT_FLOAT_EQ(m.roughness, 0.6f);
  EXPECT_FLOAT_EQ(m.normal_scale, 0.5f);
  EXPECT_FLOAT_EQ(m.occlusion_strength, 0.25f);
  EXPECT_EQ(glm::vec3(m.emissive[0], m.emissive[1], m.emissive[2]), glm::vec3(1, 0.5f, 0.25f));
  EXPECT_EQ(m.emissive_strength, 4.0f);
  EXPECT_FALSE(m.unlit);
  EXPECT_EQ(m.unimplemented, std::vector<std::string>{"KHR_materials_diffuse_transmission"});
  EXPECT_TRUE(s.material_inputs[2].unlit);
  EXPECT_EQ(s.material_inputs[2].slots[kSlotBaseColor].texture, -1);
  // defaults of the glTF default material
  EXPECT_EQ(s.material_inputs[0].metallic, 1.0f);
  EXPECT_EQ(s.material_inputs[0].emissive_strength, 1.0f);

  const auto& sl = m.slots;
  EXPECT_GE(sl[kSlotBaseColor].texture, 0);
  EXPECT_EQ(sl[kSlotBaseColor].texcoord_set, 0);
  EXPECT_TRUE(sl[kSlotBaseColor].srgb);
  EXPECT_FALSE(sl[kSlotBaseColor].transform);
  EXPECT_EQ(sl[kSlotMetallicRoughness].texcoord_set, 1);
  EXPECT_FALSE(sl[kSlotMetallicRoughness].srgb);
  EXPECT_TRUE(sl[kSlotMetallicRoughness].transform);
  EXPECT_EQ(sl[kSlotMetallicRoughness].offset[0], 0.5f);
  EXPECT_EQ(sl[kSlotMetallicRoughness].offset[1], 0.0f);
  EXPECT_EQ(sl[kSlotMetallicRoughness].rotation, 0.25f);
  EXPECT_EQ(sl[kSlotMetallicRoughness].scale[0], 2.0f);
  EXPECT_EQ(sl[kSlotMetallicRoughness].scale[1], 3.0f);
  EXPECT_EQ(sl[kSlotNormal].texcoord_set, 1);
  EXPECT_FALSE(sl[kSlotNormal].srgb);
  EXPECT_FALSE(sl[kSlotNormal].transform);
  EXPECT_EQ(sl[kSlotOcclusion].texcoord_set, 0);
  EXPECT_FALSE(sl[kSlotOcclusion].srgb);
  EXPECT_EQ(sl[kSlotEmissive].texcoord_set, 1) << "the transform's texCoord overrides the textureInfo's";
  EXPECT_TRUE(sl[kSlotEmissive].srgb);
  EXPECT_TRUE(sl[kSlotEmissive].transform);
  EXPECT_EQ(sl[kSlotEmissive].scale[0], 1.0f);

  // Images: one texture per (image, wrap modes); the ORM image serves two textures and two slots; the
  // diffuse transmission image is neither decoded nor read.
  ASSERT_EQ(s.textures.size(), 4u);
  EXPECT_EQ(sl[kSlotOcclusion].texture, sl[kSlotMetallicRoughness].texture);
  EXPECT_EQ(s.textures[size_t(sl[kSlotOcclusion].texture)].slots,
            (1u << kSlotMetallicRoughness) | (1u << kSlotOcclusion));
  EXPECT_EQ(s.textures[size_t(sl[kSlotOcclusion].texture)].rgba, (std::vector<uint8_t>{255, 128, 64, 255}));
  EXPECT_EQ(s.textures[size_t(sl[kSlotNormal].texture)].rgba, (std::vector<uint8_t>{128, 128, 255, 255}));
  EXPECT_EQ(s.textures[size_t(sl[kSlotEmissive].texture)].slots, 1u << kSlotEmissive);
  std::vector<std::string> read;
  for (const SceneInputFile& f : s.input_files) read.push_back(f.path);
  EXPECT_EQ(read, (std::vector<std::string>{"materials.bin", "normal.png"}))
      << "the normal map is a file read, the diffuse transmission image is not";

  // TEXCOORD_0 and _1 as stored, for every vertex; the second primitive has no TEXCOORD_1 (its material
  // samples none): zeros.
  ASSERT_EQ(s.positions.size(), 8u);
  ASSERT_EQ(s.texcoords.size(), 2u);
  for (const auto& set : s.texcoords) ASSERT_EQ(set.size(), 8u);
  EXPECT_EQ(s.texcoords[0][1], glm::vec2(1, 1));
  EXPECT_EQ(s.texcoords[1][1], glm::vec2(2, 2));
  EXPECT_EQ(s.texcoords[0][5], glm::vec2(0, 0)) << "its material samples no texture";
  EXPECT_EQ(s.texcoords[1][5], glm::vec2(0, 0));

  // The normal texture needs tangents; the file has none: generated (u grows along +x; v up = +y is a
  // right-handed frame with the +Z normal: w = +1). The unlit primitive has no normal texture.
  ASSERT_EQ(s.tangents.size(), 8u);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(s.tangents[size_t(v)], glm::vec4(1, 0, 0, 1)) << v;
  for (int v = 4; v < 8; ++v) EXPECT_EQ(s.tangents[size_t(v)], glm::vec4(0, 0, 0, 0)) << v;
  EXPECT_EQ(s.structure.generated_tangent_primitives, 1u);

  EXPECT_EQ(warnings_with(s, "KHR_materials_diffuse_transmission"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_diffuse_transmission (1 material): drawn without diffuse transmission"), 1u)
      << all_warnings(s);
}

TEST_F(SceneMaterialsTest, OutOfRangeFactorsAreClampedWithAWarning) {
  GltfFile g;
  const Quad q = quad(g);
  g.add("materials", {{"pbrMetallicRoughness", {{"metallicFactor", 2}, {"roughnessFactor", -1}}},
                      {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -3}}}}}});
  g.mesh(json::array({{{"attributes", {{"POSITION", q.pos}}}, {"indices", q.idx}, {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "clamped"));
  EXPECT_EQ(s.material_inputs[1].metallic, 1.0f);
  EXPECT_EQ(s.material_inputs[1].roughness, 0.0f);
  EXPECT_EQ(s.material_inputs[1].emissive_strength, 0.0f);
  EXPECT_EQ(warnings_with(s, "material 0 metallicFactor is outside [0.0, 1.0]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 0 emissiveStrength"), 1u) << all_warnings(s);
}

// KHR_materials_transmission, _volume and _ior (DESIGN 4c): their factors read and checked (absent:
// the extensions' defaults), invalid ones replaced with a warning; ior sets the dielectric's F0,
// transmission and volume are still drawn by 4b, and warned so.
TEST_F(SceneMaterialsTest, TransmissionVolumeAndIorFactorsAreRead) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"};
  const Quad q = quad(g);
  g.add("materials",
        {{"name", "Glass"},
         {"extensions",
          {{"KHR_materials_transmission", {{"transmissionFactor", 0.75}}},
           {"KHR_materials_volume",
            {{"thicknessFactor", 2.5}, {"attenuationDistance", 0.4}, {"attenuationColor", {0.1, 0.5, 0.9}}}},
           {"KHR_materials_ior", {{"ior", 1.33}}}}}});
  g.add("materials", {{"name", "Defaults"},
                      {"extensions",
                       {{"KHR_materials_transmission", json::object()},
                        {"KHR_materials_volume", json::object()},
                        {"KHR_materials_ior", json::object()}}}});
  g.add("materials", {{"name", "Bad"},
                      {"extensions",
                       {{"KHR_materials_transmission", {{"transmissionFactor", 3}}},
                        {"KHR_materials_volume", {{"attenuationDistance", 0}, {"attenuationColor", {1, 2}}}},
                        {"KHR_materials_ior", {{"ior", 0.5}}}}}});
  g.add("materials", {{"name", "Compat"}, {"extensions", {{"KHR_materials_ior", {{"ior", 0}}}}}});
  json prims = json::array();
  for (int m = 0; m < 4; ++m)
    prims.push_back({{"attributes", {{"POSITION", q.pos}}}, {"indices", q.idx}, {"material", m}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "layers"));
  ASSERT_EQ(s.material_inputs.size(), 5u);
  const SceneMaterialInputs &glass = s.material_inputs[1], &defaults = s.material_inputs[2],
                            &bad = s.material_inputs[3];
  EXPECT_EQ(glass.transmission, 0.75f);
  EXPECT_EQ(glass.thickness, 2.5f);
  EXPECT_EQ(glass.attenuation_distance, 0.4f);
  EXPECT_EQ(glm::vec3(glass.attenuation_color[0], glass.attenuation_color[1], glass.attenuation_color[2]),
            glm::vec3(0.1f, 0.5f, 0.9f));
  EXPECT_EQ(glass.ior, 1.33f);
  EXPECT_EQ(defaults.transmission, 0.0f);
  EXPECT_EQ(defaults.thickness, 0.0f);
  EXPECT_TRUE(std::isinf(defaults.attenuation_distance));
  EXPECT_EQ(defaults.attenuation_color[1], 1.0f);
  EXPECT_EQ(defaults.ior, 1.5f);
  EXPECT_EQ(bad.transmission, 1.0f) << "clamped";
  EXPECT_TRUE(std::isinf(bad.attenuation_distance));
  EXPECT_EQ(bad.attenuation_color[0], 1.0f);
  EXPECT_EQ(bad.ior, 1.5f);
  EXPECT_EQ(s.material_inputs[4].ior, 0.0f) << "0 is the extension's compatibility mode";
  // ior is drawn (the dielectric's F0), transmission and volume too (DESIGN 4c: no warning)
  EXPECT_NEAR(s.materials[1].f0_dielectric, (0.33 / 2.33) * (0.33 / 2.33), 1e-7);
  EXPECT_EQ(s.materials[2].f0_dielectric, 0.04f);
  EXPECT_EQ(s.materials[4].f0_dielectric, 1.0f);
  EXPECT_EQ(warnings_with(s, "KHR_materials_ior ("), 0u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 transmissionFactor is outside [0.0, 1.0]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 attenuationDistance must be positive"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 KHR_materials_volume has no valid attenuationColor"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 ior 0.5 is neither 0 nor at least 1; using 1.5"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_transmission ("), 0u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_volume ("), 0u) << all_warnings(s);
}

// KHR_materials_clearcoat (DESIGN 4c): its factors, its three textures (each with its own set and
// transform) and the coat normal's scale read; absent factors are the extension's 0; bad ones replaced
// with a warning; drawn, so not warned as unimplemented. The coat normal map alone makes the loader
// generate tangents, on the coat normal's set.
TEST_F(SceneMaterialsTest, ClearcoatFactorsAndTexturesAreRead) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_texture_transform"};
  g.doc["extensionsRequired"] = {"KHR_materials_clearcoat"};
  const Quad q = quad(g);
  const int uv1 = g.data<float>({0, 2, 2, 2, 2, 0, 0, 0}, kFloat, "VEC2");
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {200, 100, 50}))}});
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {128, 128, 255}))}});
  g.add("textures", {{"source", 0}});
  g.add("textures", {{"source", 1}});
  g.add("materials", {{"name", "Lacquer"},
                      {"extensions",
                       {{"KHR_materials_clearcoat",
                         {{"clearcoatFactor", 0.75},
                          {"clearcoatTexture", {{"index", 0}}},
                          {"clearcoatRoughnessFactor", 0.3},
                          {"clearcoatRoughnessTexture",
                           {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0}}}}}}}},
                          {"clearcoatNormalTexture", {{"index", 1}, {"texCoord", 1}, {"scale", 0.4}}}}}}}});
  g.add("materials", {{"name", "Defaults"}, {"extensions", {{"KHR_materials_clearcoat", json::object()}}}});
  g.add("materials",
        {{"name", "Bad"},
         {"extensions",
          {{"KHR_materials_clearcoat",
            {{"clearcoatFactor", 2}, {"clearcoatRoughnessFactor", "x"}, {"clearcoatTexture", {{"index", 9}}}}}}}});
  json prims = json::array();
  prims.push_back({{"attributes", {{"POSITION", q.pos}, {"NORMAL", q.nrm}, {"TEXCOORD_0", q.uv0}, {"TEXCOORD_1", uv1}}},
                   {"indices", q.idx},
                   {"material", 0}});
  for (int m : {1, 2}) prims.push_back({{"attributes", {{"POSITION", q.pos}}}, {"indices", q.idx}, {"material", m}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "coat"));
  ASSERT_EQ(s.material_inputs.size(), 4u);
  const SceneMaterialInputs &lacquer = s.material_inputs[1], &defaults = s.material_inputs[2],
                            &bad = s.material_inputs[3];
  EXPECT_TRUE(lacquer.has_clearcoat);
  EXPECT_EQ(lacquer.clearcoat, 0.75f);
  EXPECT_EQ(lacquer.clearcoat_roughness, 0.3f);
  EXPECT_EQ(lacquer.clearcoat_normal_scale, 0.4f);
  const auto& sl = lacquer.slots;
  EXPECT_GE(sl[kSlotClearcoat].texture, 0);
  EXPECT_EQ(sl[kSlotClearcoatRoughness].texture, sl[kSlotClearcoat].texture);
  EXPECT_TRUE(sl[kSlotClearcoatRoughness].transform);
  EXPECT_EQ(sl[kSlotClearcoatRoughness].offset[0], 0.5f);
  EXPECT_FALSE(sl[kSlotClearcoat].transform);
  EXPECT_EQ(sl[kSlotClearcoatNormal].texcoord_set, 1);
  EXPECT_FALSE(sl[kSlotClearcoat].srgb || sl[kSlotClearcoatRoughness].srgb || sl[kSlotClearcoatNormal].srgb);
  EXPECT_EQ(s.textures[size_t(sl[kSlotClearcoatNormal].texture)].rgba, (std::vector<uint8_t>{128, 128, 255, 255}));
  EXPECT_EQ(s.materials[1].clearcoat, 0.75f) << "the kernels' copy";
  EXPECT_EQ(s.materials[1].clearcoat_normal_scale, 0.4f);
  EXPECT_TRUE(defaults.has_clearcoat);
  EXPECT_EQ(defaults.clearcoat, 0.0f);
  EXPECT_EQ(defaults.clearcoat_roughness, 0.0f);
  EXPECT_EQ(bad.clearcoat, 1.0f) << "clamped";
  EXPECT_EQ(bad.clearcoat_roughness, 0.0f);
  EXPECT_EQ(bad.slots[kSlotClearcoat].texture, -1);
  EXPECT_EQ(warnings_with(s, "material 2 clearcoatFactor is outside [0.0, 1.0]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 KHR_materials_clearcoat has no valid clearcoatRoughnessFactor"), 1u)
      << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 clearcoatTexture names no texture of the file"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "drawn without"), 0u) << all_warnings(s);
  // tangents for the coat's normal map, generated on its set (TEXCOORD_1 runs along +x and up +y too)
  ASSERT_EQ(s.tangents.size(), s.positions.size());
  EXPECT_EQ(s.tangents[0], glm::vec4(1, 0, 0, 1));
  EXPECT_EQ(s.structure.generated_tangent_primitives, 1u);
}

// KHR_materials_specular (DESIGN 4c): the weight and colour factors and their textures (the colour's
// sRGB-decoded) read; absent factors are 1; bad ones replaced with a warning; drawn, so not warned.
TEST_F(SceneMaterialsTest, SpecularFactorsAndTexturesAreRead) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_materials_specular"};
  g.doc["extensionsRequired"] = {"KHR_materials_specular"};
  const Quad q = quad(g);
  g.add("images", {{"uri", png_uri(make_png(1, 1, 6, 8, {200, 100, 50, 128}))}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"name", "Tinted"},
                      {"extensions",
                       {{"KHR_materials_specular",
                         {{"specularFactor", 0.5},
                          {"specularTexture", {{"index", 0}}},
                          {"specularColorFactor", {2, 1, 0.25}},
                          {"specularColorTexture", {{"index", 0}, {"texCoord", 0}}}}}}}});
  g.add("materials", {{"name", "Defaults"}, {"extensions", {{"KHR_materials_specular", json::object()}}}});
  g.add("materials",
        {{"name", "Bad"},
         {"extensions", {{"KHR_materials_specular", {{"specularFactor", -1}, {"specularColorFactor", {1, 2}}}}}}});
  json prims = json::array();
  prims.push_back({{"attributes", {{"POSITION", q.pos}, {"TEXCOORD_0", q.uv0}}}, {"indices", q.idx}, {"material", 0}});
  for (int m : {1, 2}) prims.push_back({{"attributes", {{"POSITION", q.pos}}}, {"indices", q.idx}, {"material", m}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "specular"));
  ASSERT_EQ(s.material_inputs.size(), 4u);
  const SceneMaterialInputs &tinted = s.material_inputs[1], &defaults = s.material_inputs[2],
                            &bad = s.material_inputs[3];
  EXPECT_TRUE(tinted.has_specular);
  EXPECT_EQ(tinted.specular, 0.5f);
  EXPECT_EQ(glm::vec3(tinted.specular_color[0], tinted.specular_color[1], tinted.specular_color[2]),
            glm::vec3(2.0f, 1.0f, 0.25f));
  EXPECT_GE(tinted.slots[kSlotSpecular].texture, 0);
  EXPECT_FALSE(tinted.slots[kSlotSpecular].srgb);
  EXPECT_EQ(tinted.slots[kSlotSpecularColor].texture, tinted.slots[kSlotSpecular].texture);
  EXPECT_TRUE(tinted.slots[kSlotSpecularColor].srgb);
  EXPECT_EQ(s.materials[1].specular, 0.5f) << "the kernels' copy";
  EXPECT_EQ(s.materials[1].specular_color[0], 2.0f);
  EXPECT_EQ(defaults.specular, 1.0f);
  EXPECT_EQ(defaults.specular_color[2], 1.0f);
  EXPECT_EQ(bad.specular, 0.0f) << "clamped";
  EXPECT_EQ(bad.specular_color[1], 1.0f);
  EXPECT_EQ(warnings_with(s, "material 2 specularFactor is outside [0.0, 1.0]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 KHR_materials_specular has no valid specularColorFactor"), 1u)
      << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "drawn with"), 0u) << all_warnings(s);
}

// KHR_materials_anisotropy (DESIGN 4c): strength, rotation and texture read; bad values replaced with a
// warning; drawn, so not warned. An anisotropic material without a normal map gets tangents (from
// TEXCOORD_0, which no slot samples), and its strength and rotation reach the kernels' material.
TEST_F(SceneMaterialsTest, AnisotropyIsReadAndGetsTangents) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_materials_anisotropy"};
  g.doc["extensionsRequired"] = {"KHR_materials_anisotropy"};
  const Quad q = quad(g);
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {255, 128, 200}))}});
  g.add("textures", {{"source", 0}});
  g.add("materials",
        {{"name", "Brushed"},
         {"extensions", {{"KHR_materials_anisotropy", {{"anisotropyStrength", 0.8}, {"anisotropyRotation", 1.5}}}}}});
  g.add("materials",
        {{"name", "Textured"},
         {"extensions",
          {{"KHR_materials_anisotropy", {{"anisotropyStrength", 1}, {"anisotropyTexture", {{"index", 0}}}}}}}});
  g.add("materials",
        {{"name", "Bad"},
         {"extensions", {{"KHR_materials_anisotropy", {{"anisotropyStrength", 3}, {"anisotropyRotation", "x"}}}}}});
  quad_per_material(g, q, 3);
  const Scene s = load_scene(g.write(dir_, "aniso"));
  ASSERT_EQ(s.material_inputs.size(), 4u);
  EXPECT_TRUE(s.material_inputs[1].has_anisotropy);
  EXPECT_EQ(s.material_inputs[1].anisotropy_strength, 0.8f);
  EXPECT_EQ(s.material_inputs[1].anisotropy_rotation, 1.5f);
  EXPECT_FLOAT_EQ(s.materials[1].anisotropy[1], std::cos(1.5f));
  EXPECT_FLOAT_EQ(s.materials[1].anisotropy[2], std::sin(1.5f));
  EXPECT_GE(s.material_inputs[2].slots[kSlotAnisotropy].texture, 0);
  EXPECT_FALSE(s.material_inputs[2].slots[kSlotAnisotropy].srgb);
  EXPECT_EQ(s.material_inputs[3].anisotropy_strength, 1.0f) << "clamped";
  EXPECT_EQ(s.material_inputs[3].anisotropy_rotation, 0.0f);
  EXPECT_EQ(warnings_with(s, "material 2 anisotropyStrength is outside [0.0, 1.0]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 KHR_materials_anisotropy has no valid anisotropyRotation"), 1u)
      << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "isotropic"), 0u) << all_warnings(s);
  ASSERT_EQ(s.tangents.size(), s.positions.size());
  for (size_t v = 0; v < s.tangents.size(); ++v) EXPECT_EQ(s.tangents[v], glm::vec4(1, 0, 0, 1)) << v;
  EXPECT_EQ(s.structure.generated_tangent_primitives, 3u);
}

// KHR_materials_iridescence (DESIGN 4c): factor, film ior, thickness range and both textures read;
// absent values are the extension's defaults (0, 1.3, 100 and 400 nm); bad ones replaced with a warning.
TEST_F(SceneMaterialsTest, IridescenceIsRead) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_materials_iridescence"};
  const Quad q = quad(g);
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {255, 128, 0}))}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"name", "Film"},
                      {"extensions",
                       {{"KHR_materials_iridescence",
                         {{"iridescenceFactor", 0.9},
                          {"iridescenceIor", 1.8},
                          {"iridescenceThicknessMinimum", 150},
                          {"iridescenceThicknessMaximum", 700},
                          {"iridescenceTexture", {{"index", 0}}},
                          {"iridescenceThicknessTexture", {{"index", 0}}}}}}}});
  g.add("materials", {{"name", "Defaults"}, {"extensions", {{"KHR_materials_iridescence", json::object()}}}});
  g.add("materials",
        {{"name", "Bad"},
         {"extensions",
          {{"KHR_materials_iridescence", {{"iridescenceIor", 0.5}, {"iridescenceThicknessMaximum", -1}}}}}});
  quad_per_material(g, q, 3);
  const Scene s = load_scene(g.write(dir_, "film"));
  ASSERT_EQ(s.material_inputs.size(), 4u);
  const SceneMaterialInputs &film = s.material_inputs[1], &defaults = s.material_inputs[2], &bad = s.material_inputs[3];
  EXPECT_TRUE(film.has_iridescence);
  EXPECT_FLOAT_EQ(film.iridescence, 0.9f);
  EXPECT_FLOAT_EQ(film.iridescence_ior, 1.8f);
  EXPECT_EQ(film.iridescence_thickness[0], 150.0f);
  EXPECT_EQ(film.iridescence_thickness[1], 700.0f);
  EXPECT_GE(film.slots[kSlotIridescence].texture, 0);
  EXPECT_GE(film.slots[kSlotIridescenceThickness].texture, 0);
  EXPECT_EQ(s.materials[1].iridescence[3], 700.0f) << "the kernels' copy";
  EXPECT_EQ(defaults.iridescence, 0.0f);
  EXPECT_FLOAT_EQ(defaults.iridescence_ior, 1.3f);
  EXPECT_EQ(defaults.iridescence_thickness[0], 100.0f);
  EXPECT_EQ(defaults.iridescence_thickness[1], 400.0f);
  EXPECT_EQ(bad.iridescence_ior, 1.0f) << "clamped";
  EXPECT_EQ(bad.iridescence_thickness[1], 0.0f) << "clamped";
  EXPECT_EQ(warnings_with(s, "material 2 iridescenceIor is outside [1.0, inf]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 iridescenceThicknessMaximum is outside [0.0, inf]; clamped"), 1u)
      << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "drawn without"), 0u) << all_warnings(s);
}

// KHR_materials_sheen (DESIGN 4c): colour and roughness factors and both textures read (the colour
// sRGB, the roughness linear: the alpha of one packed texture); absent values are the extension's
// defaults (colour 0: no sheen, roughness 0); bad ones replaced with a warning. The kernels' copy and
// their feature flag (a colour of 0 turns the layer off).
TEST_F(SceneMaterialsTest, SheenIsRead) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_materials_sheen"};
  const Quad q = quad(g);
  g.add("images", {{"uri", png_uri(make_png(1, 1, 6, 8, {255, 128, 0, 200}))}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"name", "Velvet"},
                      {"extensions",
                       {{"KHR_materials_sheen",
                         {{"sheenColorFactor", {0.9, 0.5, 0.25}},
                          {"sheenRoughnessFactor", 0.6},
                          {"sheenColorTexture", {{"index", 0}}},
                          {"sheenRoughnessTexture", {{"index", 0}}}}}}}});
  g.add("materials", {{"name", "Defaults"}, {"extensions", {{"KHR_materials_sheen", json::object()}}}});
  g.add("materials",
        {{"name", "Bad"},
         {"extensions", {{"KHR_materials_sheen", {{"sheenColorFactor", {2, 0.5}}, {"sheenRoughnessFactor", 3}}}}}});
  quad_per_material(g, q, 3);
  const Scene s = load_scene(g.write(dir_, "sheen"));
  ASSERT_EQ(s.material_inputs.size(), 4u);
  const SceneMaterialInputs &velvet = s.material_inputs[1], &defaults = s.material_inputs[2],
                            &bad = s.material_inputs[3];
  EXPECT_TRUE(velvet.has_sheen);
  EXPECT_EQ(glm::vec3(velvet.sheen_color[0], velvet.sheen_color[1], velvet.sheen_color[2]),
            glm::vec3(0.9f, 0.5f, 0.25f));
  EXPECT_FLOAT_EQ(velvet.sheen_roughness, 0.6f);
  EXPECT_GE(velvet.slots[kSlotSheenColor].texture, 0);
  EXPECT_TRUE(velvet.slots[kSlotSheenColor].srgb);
  EXPECT_GE(velvet.slots[kSlotSheenRoughness].texture, 0);
  EXPECT_FALSE(velvet.slots[kSlotSheenRoughness].srgb);
  EXPECT_EQ(s.materials[1].sheen[3], 0.6f) << "the kernels' copy";
  EXPECT_TRUE(defaults.has_sheen);
  EXPECT_EQ(glm::vec3(defaults.sheen_color[0], defaults.sheen_color[1], defaults.sheen_color[2]), glm::vec3(0.0f));
  EXPECT_EQ(defaults.sheen_roughness, 0.0f);
  EXPECT_EQ(glm::vec3(bad.sheen_color[0], bad.sheen_color[1], bad.sheen_color[2]), glm::vec3(0.0f))
      << "two numbers are no colour";
  EXPECT_EQ(bad.sheen_roughness, 1.0f) << "clamped";
  EXPECT_EQ(warnings_with(s, "material 2 KHR_materials_sheen has no valid sheenColorFactor"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "material 2 sheenRoughnessFactor is outside [0.0, 1.0]; clamped"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "drawn without"), 0u) << all_warnings(s);
  const MaterialTables t = make_material_tables(s, true);
  EXPECT_NE(t.materials[1].flags & PMR_MATERIAL_SHEEN, 0u);
  EXPECT_EQ(t.materials[2].flags & PMR_MATERIAL_SHEEN, 0u) << "a colour of 0 turns the layer off";
  EXPECT_EQ(t.materials[1].maps[PMR_MAP_SHEEN_ROUGHNESS].texture, t.materials[1].maps[PMR_MAP_SHEEN_COLOR].texture)
      << "the packed roughness reads the colour's chain (the same alpha)";
}

TEST_F(SceneMaterialsTest, ATexCoordSetTheMeshLacksIsAnError) {
  GltfFile g;
  const Quad q = quad(g);
  g.add("images", {{"uri", png_uri(kPixel)}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"name", "Bumpy"}, {"normalTexture", {{"index", 0}, {"texCoord", 2}}}});
  g.add("meshes",
        {{"name", "Plate"},
         {"primitives",
          {{{"attributes", {{"POSITION", q.pos}, {"TEXCOORD_0", q.uv0}}}, {"indices", q.idx}, {"material", 0}}}}});
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const std::string path = g.write(dir_, "noset");
  const std::string e = load_error(path);
  EXPECT_EQ(
      e,
      path + ": material 0 'Bumpy' normalTexture samples TEXCOORD_2, which mesh 0 'Plate' primitive 0 does not have");
}

// ---- tangents ------------------------------------------------------------------------------------------------

// The file's TANGENT (1, 0, 0, +1): turned by a node's rotation, mirrored by a node's negative scale
// (xyz by the matrix, w by sign(det)), morphed by a TANGENT target, turned by the turntable.
TEST_F(SceneMaterialsTest, FileTangentsFollowNodesMorphsMirrorsAndTheTurntable) {
  GltfFile g;
  const Quad q = quad(g);
  const int tan = g.data<float>({1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, kFloat, "VEC4");
  const int dtan = g.data<float>({-1, 1, 0, -1, 1, 0, -1, 1, 0, -1, 1, 0}, kFloat, "VEC3");
  g.add("images", {{"uri", png_uri(kPixel)}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"normalTexture", {{"index", 0}}}});
  g.add("meshes", {{"primitives",
                    {{{"attributes", {{"POSITION", q.pos}, {"NORMAL", q.nrm}, {"TEXCOORD_0", q.uv0}, {"TANGENT", tan}}},
                      {"targets", {{{"TANGENT", dtan}}}},
                      {"indices", q.idx},
                      {"material", 0}}}},
                   {"weights", {0}}});
  const double h = std::sqrt(0.5);
  g.add("nodes", {{"mesh", 0}, {"rotation", {0, 0, h, h}}});  // 90 degrees about +Z
  g.add("nodes", {{"mesh", 0}, {"scale", {-1, 1, 1}}});
  g.scene({0, 1});
  const int times = g.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
  const int weights = g.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
  g.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", weights}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}}}}};
  const Scene s = load_scene(g.write(dir_, "tangents"));
  ASSERT_EQ(s.tangents.size(), 8u);
  EXPECT_EQ(s.structure.generated_tangent_primitives, 0u);
  for (int v = 0; v < 4; ++v) {
    EXPECT_VEC_NEAR(glm::vec3(s.tangents[size_t(v)]), glm::vec3(0, 1, 0), 1e-6);
    EXPECT_EQ(s.tangents[size_t(v)].w, 1.0f);
    EXPECT_VEC_NEAR(glm::vec3(s.tangents[size_t(4 + v)]), glm::vec3(-1, 0, 0), 1e-6);
    EXPECT_EQ(s.tangents[size_t(4 + v)].w, -1.0f) << "a mirroring node flips the handedness";
  }
  // At t = 1 the target's full weight: local (0, 1, 0), turned by the node to (-1, 0, 0).
  PoseRequest r;
  r.animation = 0;
  r.time = 1.0;
  Scene p;
  pose_scene(s, r, p);
  ASSERT_EQ(p.tangents.size(), 8u);
  EXPECT_VEC_NEAR(glm::vec3(p.tangents[0]), glm::vec3(-1, 0, 0), 1e-6);
  EXPECT_EQ(p.tangents[4], s.tangents[4]) << "the other instance does not move";
  // Turntable 90 degrees: +X goes to -Z, w stays.
  r.turntable = true;
  r.turntable_deg = 90.0;
  pose_scene(s, r, p);
  EXPECT_VEC_NEAR(glm::vec3(p.tangents[0]), glm::vec3(0, 0, 1), 1e-6);
  EXPECT_VEC_NEAR(glm::vec3(p.tangents[4]), glm::vec3(0, 0, 1), 1e-6);
  EXPECT_EQ(p.tangents[4].w, -1.0f);
  // Back to rest after an animated pose: the moved instance's tangents are the rest ones again.
  r.turntable = false;
  Scene fresh;
  pose_scene(s, r, fresh);
  pose_scene(s, PoseRequest{}, fresh);
  EXPECT_EQ(fresh.tangents, s.tangents);
}

// A skinned mesh's tangents take the blended joint matrix (not the node's): a joint mirrored by
// scale (-1, 1, 1) gives (-1, 0, 0) with w = -1; its animated 90 degree turn about +Z then (0, -1, 0).
TEST_F(SceneMaterialsTest, SkinnedTangentsFollowTheJointMatrices) {
  GltfFile g;
  const Quad q = quad(g);
  const int tan = g.data<float>({1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, kFloat, "VEC4");
  const int joints = g.data<uint8_t>(std::vector<uint8_t>(16, 0), kUByte, "VEC4");
  const int weights = g.data<float>({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, kFloat, "VEC4");
  g.add("images", {{"uri", png_uri(kPixel)}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"normalTexture", {{"index", 0}}}});
  g.mesh(json::array({{{"attributes",
                        {{"POSITION", q.pos},
                         {"NORMAL", q.nrm},
                         {"TEXCOORD_0", q.uv0},
                         {"TANGENT", tan},
                         {"JOINTS_0", joints},
                         {"WEIGHTS_0", weights}}},
                       {"indices", q.idx},
                       {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}});  // ignored: skinned
  g.add("nodes", {{"scale", {-1, 1, 1}}});
  g.add("skins", {{"joints", {1}}});
  g.scene({0, 1});
  const double h = std::sqrt(0.5);
  const int times = g.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
  const int turns = g.data<float>({0, 0, 0, 1, 0, 0, float(h), float(h)}, kFloat, "VEC4");
  g.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", turns}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}}}}}};
  const Scene s = load_scene(g.write(dir_, "skinned"));
  ASSERT_EQ(s.tangents.size(), 4u);
  for (const glm::vec4& t : s.tangents) {
    EXPECT_VEC_NEAR(glm::vec3(t), glm::vec3(-1, 0, 0), 1e-6);
    EXPECT_EQ(t.w, -1.0f);
  }
  PoseRequest r;
  r.animation = 0;
  r.time = 1.0;
  Scene p;
  pose_scene(s, r, p);
  for (const glm::vec4& t : p.tangents) {
    EXPECT_VEC_NEAR(glm::vec3(t), glm::vec3(0, -1, 0), 1e-6);
    EXPECT_EQ(t.w, -1.0f);
  }
}

// Generated tangents: u along +x gives t = +x; mirroring u or v flips what it must.
TEST_F(SceneMaterialsTest, GeneratedTangentsFollowTheUvDirections) {
  GltfFile g;
  const Quad q = quad(g);
  const int flip_u = g.data<float>({1, 1, 0, 1, 0, 0, 1, 0}, kFloat, "VEC2");
  const int flip_v = g.data<float>({0, 0, 1, 0, 1, 1, 0, 1}, kFloat, "VEC2");
  g.add("images", {{"uri", png_uri(kPixel)}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"normalTexture", {{"index", 0}}}});
  json prims = json::array();
  for (int uv : {q.uv0, flip_u, flip_v})
    prims.push_back({{"attributes", {{"POSITION", q.pos}, {"NORMAL", q.nrm}, {"TEXCOORD_0", uv}}},
                     {"indices", q.idx},
                     {"material", 0}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "generated"));
  ASSERT_EQ(s.tangents.size(), 12u);
  EXPECT_EQ(s.structure.generated_tangent_primitives, 3u);
  const glm::vec4 expected[3] = {{1, 0, 0, 1}, {-1, 0, 0, -1}, {1, 0, 0, -1}};
  for (int p = 0; p < 3; ++p)
    for (int v = 0; v < 4; ++v) {
      const glm::vec4 t = s.tangents[size_t(4 * p + v)];
      EXPECT_VEC_NEAR(glm::vec3(t), glm::vec3(expected[p]), 1e-6) << "primitive " << p << " vertex " << v;
      EXPECT_EQ(t.w, expected[p].w) << "primitive " << p << " vertex " << v;
      // The bitangent w * cross(n, t) points where the image's up (decreasing glTF v) lies.
      const glm::vec3 b = t.w * glm::cross(glm::vec3(0, 0, 1), glm::vec3(t));
      EXPECT_VEC_NEAR(b, p == 2 ? glm::vec3(0, -1, 0) : glm::vec3(0, 1, 0), 1e-6) << "primitive " << p;
    }
}

// ---- lights ----------------------------------------------------------------------------------------------------

GltfFile lights_file() {
  GltfFile g;
  const Quad q = quad(g);
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"name", "Sun"}, {"type", "directional"}, {"color", {1, 0.5, 0.25}}, {"intensity", 3}},
      {{"name", "Bulb"}, {"type", "point"}, {"range", 10}, {"intensity", 40}},
      {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}}};
  g.mesh(json::array({{{"attributes", {{"POSITION", q.pos}}}, {"indices", q.idx}}}));
  const double h = std::sqrt(0.5);
  auto light = [](int i) { return json{{"KHR_lights_punctual", {{"light", i}}}}; };
  g.add("nodes", {{"mesh", 0}});                                                                 // 0
  g.add("nodes", {{"name", "Arm"}, {"translation", {0, 2, 0}}, {"children", {2}}});              // 1
  g.add("nodes", {{"name", "BulbNode"}, {"translation", {1, 0, 0}}, {"extensions", light(1)}});  // 2
  g.add("nodes", {{"rotation", {-h, 0, 0, h}}, {"extensions", light(0)}});                       // 3: -90 deg about X
  g.add("nodes", {{"translation", {0, 0, 5}}, {"extensions", light(2)}});                        // 4
  g.add("nodes", {{"translation", {-3, 0, 0}}, {"extensions", light(1)}});                       // 5: the bulb again
  g.scene({0, 1, 3, 4, 5});
  return g;
}

TEST_F(SceneMaterialsTest, LightsArePlacedByTheirNodes) {
  const Scene s = load_scene(lights_file().write(dir_, "lights"));
  ASSERT_EQ(s.lights.size(), 4u);
  const SceneLight& bulb = s.lights[0];  // traversal order: node 2 (under 1), 3, 4, 5
  EXPECT_EQ(bulb.type, SceneLightType::Point);
  EXPECT_EQ(bulb.name, "Bulb");
  EXPECT_EQ(bulb.node, 2);
  EXPECT_EQ(bulb.node_name, "BulbNode");
  EXPECT_EQ(bulb.light, 1);
  EXPECT_EQ(bulb.range, 10.0f);
  EXPECT_EQ(bulb.intensity, 40.0f);
  EXPECT_EQ(bulb.position, glm::dvec3(1, 2, 0));
  const SceneLight& sun = s.lights[1];
  EXPECT_EQ(sun.type, SceneLightType::Directional);
  EXPECT_EQ(glm::vec3(sun.color[0], sun.color[1], sun.color[2]), glm::vec3(1, 0.5f, 0.25f));
  EXPECT_EQ(sun.intensity, 3.0f);
  EXPECT_EQ(sun.range, 0.0f) << "no range given";
  EXPECT_VEC_NEAR(sun.direction, glm::dvec3(0, -1, 0), 1e-12);
  const SceneLight& spot = s.lights[2];
  EXPECT_EQ(spot.type, SceneLightType::Spot);
  EXPECT_EQ(spot.inner_cone, 0.2f);
  EXPECT_EQ(spot.outer_cone, 0.5f);
  EXPECT_EQ(spot.position, glm::dvec3(0, 0, 5));
  EXPECT_EQ(spot.direction, glm::dvec3(0, 0, -1));
  EXPECT_EQ(s.lights[3].light, 1);
  EXPECT_EQ(s.lights[3].position, glm::dvec3(-3, 0, 0));
  EXPECT_EQ(warnings_with(s, "KHR_lights_punctual"), 0u) << all_warnings(s);
}

TEST_F(SceneMaterialsTest, LightsMoveWithTheirNodesAnimationAndTheTurntable) {
  GltfFile g = lights_file();
  const int times = g.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
  const int moves = g.data<float>({0, 2, 0, 0, 4, 0}, kFloat, "VEC3");
  const double h = std::sqrt(0.5);
  const int turns = g.data<float>({0, 0, 0, 1, 0, float(h), 0, float(h)}, kFloat, "VEC4");  // 0 -> 90 deg about +Y
  g.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", moves}}, {{"input", times}, {"output", turns}}}},
                          {"channels",
                           {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}},
                            {{"sampler", 1}, {"target", {{"node", 4}, {"path", "rotation"}}}}}}}};
  const Scene s = load_scene(g.write(dir_, "animated_lights"));
  PoseRequest r;
  r.animation = 0;
  r.time = 1.0;
  Scene p;
  pose_scene(s, r, p);
  ASSERT_EQ(p.lights.size(), 4u);
  EXPECT_VEC_NEAR(p.lights[0].position, glm::dvec3(1, 4, 0), 1e-12) << "the parent's animation carries the bulb";
  EXPECT_VEC_NEAR(p.lights[2].direction, glm::dvec3(-1, 0, 0), 1e-12) << "-Z turned 90 deg about +Y";
  EXPECT_EQ(p.lights[3].position, s.lights[3].position);
  // The turntable (90 degrees about +Y through (0, 0, 1)) turns the lights with the geometry.
  r.turntable = true;
  r.turntable_deg = 90.0;
  r.pivot = glm::dvec3(0, 0, 1);
  pose_scene(s, r, p);
  EXPECT_VEC_NEAR(p.lights[0].position, glm::dvec3(-1, 4, 0), 1e-12);  // (1, 4, 0) - pivot = (1, 4, -1) -> (-1, 4, -1)
  EXPECT_VEC_NEAR(p.lights[1].direction, glm::dvec3(0, -1, 0), 1e-12) << "straight down stays down";
  EXPECT_VEC_NEAR(p.lights[2].direction, glm::dvec3(0, 0, 1), 1e-12) << "-X turned 90 deg: +Z";
  EXPECT_VEC_NEAR(p.lights[2].position, glm::dvec3(4, 0, 1), 1e-12);
  // Turntable alone, no animation: rest placement turned.
  PoseRequest still;
  still.turntable = true;
  still.turntable_deg = 90.0;
  pose_scene(s, still, p);
  EXPECT_VEC_NEAR(p.lights[2].direction, glm::dvec3(-1, 0, 0), 1e-12);
  pose_scene(s, PoseRequest{}, p);
  EXPECT_EQ(p.lights[0].position, s.lights[0].position);
}

// A light on a node scaled to zero (hidden) has no direction: it loads, shining along -Z, with a warning.
TEST_F(SceneMaterialsTest, ALightOnAZeroScaleNodeWarns) {
  GltfFile g = lights_file();
  g.doc["nodes"][3]["scale"] = {0, 0, 0};
  const Scene s = load_scene(g.write(dir_, "hidden"));
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_EQ(s.lights[1].direction, glm::dvec3(0, 0, -1));
  EXPECT_EQ(warnings_with(s, "node 3 places a light with a degenerate matrix"), 1u) << all_warnings(s);
}

struct LightCase {
  const char* name;
  std::function<void(json&)> edit;  // on the document of lights_file()
  const char* message;
};

const std::vector<LightCase>& light_cases() {
  static const std::vector<LightCase> cases = {
      {"negative intensity", [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = -1; },
       "KHR_lights_punctual light 0 'Sun' has a negative intensity (-1)"},
      {"non-numeric intensity",
       [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = "bright"; },
       "KHR_lights_punctual light 0 'Sun' intensity is not a number"},
      {"negative colour",
       [](json& d) {
         d["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {1, -0.5, 0};
       },
       "KHR_lights_punctual light 0 'Sun' color has a negative value (-0.5)"},
      {"short colour",
       [](json& d) {
         d["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {1, 1};
       },
       "color is not an array of 3 numbers"},
      {"zero range", [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][1]["range"] = 0; },
       "KHR_lights_punctual light 1 'Bulb' range must be positive (is 0)"},
      {"negative range", [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][1]["range"] = -2.5; },
       "range must be positive (is -2.5)"},
      {"inner cone = outer cone",
       [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][2]["spot"]["innerConeAngle"] = 0.5; },
       "KHR_lights_punctual light 2 spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2 (inner "
       "0.500000, outer 0.500000)"},
      {"outer cone beyond pi/2",
       [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][2]["spot"]["outerConeAngle"] = 2; },
       "(inner 0.200000, outer 2.000000)"},
      {"negative inner cone",
       [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][2]["spot"]["innerConeAngle"] = -0.1; },
       "(inner -0.100000, outer 0.500000)"},
      {"unknown type", [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][1]["type"] = "area"; },
       "KHR_lights_punctual light 1 'Bulb' has unknown type 'area' (directional, point or spot expected)"},
      {"no type", [](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][1].erase("type"); },
       "KHR_lights_punctual light 1 'Bulb' has no type"},
      {"light index out of range", [](json& d) { d["nodes"][5]["extensions"]["KHR_lights_punctual"]["light"] = 7; },
       "node 5 KHR_lights_punctual refers to light 7, which does not exist (the file has 3)"},
      {"negative light index", [](json& d) { d["nodes"][5]["extensions"]["KHR_lights_punctual"]["light"] = -1; },
       "node 5 KHR_lights_punctual refers to light -1"},
  };
  return cases;
}

TEST_F(SceneMaterialsTest, InvalidLightsAreOneLineErrors) {
  for (const LightCase& c : light_cases()) {
    SCOPED_TRACE(c.name);
    GltfFile g = lights_file();
    c.edit(g.doc);
    const std::string path = g.write(dir_, "bad");
    const std::string e = load_error(path);
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
    EXPECT_TRUE(contains(e, c.message)) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

// A non-finite number cannot be written in JSON except as an overflowing literal.
TEST_F(SceneMaterialsTest, OverflowingLightNumbersAreErrors) {
  GltfFile g = lights_file();
  std::string text = g.finished("data:application/octet-stream;base64," + base64(g.bin)).dump();
  const std::string from = "\"intensity\":40";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "\"intensity\":1e999");
  std::ofstream(dir_ / "inf.gltf") << text;
  const std::string e = load_error((dir_ / "inf.gltf").string());
  EXPECT_TRUE(contains(e, "intensity is not finite") || contains(e, "invalid JSON")) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

// The same for a colour value and a range (today the JSON parser itself refuses the overflowing literal,
// before the loader's own finiteness checks).
TEST_F(SceneMaterialsTest, OverflowingLightColourAndRangeAreErrors) {
  const struct {
    const char *from, *to, *message;
  } cases[] = {{"\"color\":[1,0.5,0.25]", "\"color\":[1,1e999,0.25]", "color has a non-finite or non-numeric value"},
               {"\"range\":10", "\"range\":1e999", "range is not finite"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.to);
    std::string text =
        lights_file().finished("data:application/octet-stream;base64," + base64(lights_file().bin)).dump();
    ASSERT_NE(text.find(c.from), std::string::npos) << text;
    text.replace(text.find(c.from), std::string(c.from).size(), c.to);
    std::ofstream(dir_ / "inf.gltf") << text;
    const std::string e = load_error((dir_ / "inf.gltf").string());
    EXPECT_TRUE(contains(e, c.message) || contains(e, "invalid JSON")) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos);
  }
}

// ---- warnings --------------------------------------------------------------------------------------------------

TEST_F(SceneMaterialsTest, OneWarningPerUnimplementedMaterialExtension) {
  GltfFile g;
  const Quad q = quad(g);
  g.doc["extensionsUsed"] = {"KHR_materials_transmission",
                             "KHR_materials_volume",
                             "KHR_materials_diffuse_transmission",
                             "KHR_materials_pbrSpecularGlossiness",
                             "KHR_materials_foo",
                             "KHR_lights_punctual",
                             "KHR_materials_dispersion"};
  g.doc["extensionsRequired"] = {"KHR_materials_transmission", "KHR_materials_pbrSpecularGlossiness",
                                 "KHR_materials_dispersion"};
  const json transmission = {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}};
  g.add("materials", {{"extensions", transmission}});
  g.add("materials", {{"extensions", transmission}});
  g.add("materials",
        {{"extensions", {{"KHR_materials_transmission", json::object()}, {"KHR_materials_volume", json::object()}}}});
  g.add("materials", {{"extensions",
                       {{"KHR_materials_pbrSpecularGlossiness", {{"glossinessFactor", 0.5}}},
                        {"KHR_materials_dispersion", {{"dispersion", 0.1}}}}}});
  g.add("materials", {{"extensions", {{"KHR_materials_diffuse_transmission", json::object()}}}});  // no primitive
                                                                                                   // uses it
  json prims = json::array();
  for (int m = 0; m < 4; ++m)
    prims.push_back({{"attributes", {{"POSITION", q.pos}}}, {"indices", q.idx}, {"material", m}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "extensions"));
  EXPECT_EQ(warnings_with(s, "KHR_materials_transmission"), 0u) << "drawn (DESIGN 4c)\n" << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_volume"), 0u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_pbrSpecularGlossiness (1 material): drawn from their metallic-roughness"),
            1u)
      << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_diffuse_transmission"), 0u) << "no drawn material uses it\n"
                                                                        << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_materials_dispersion (1 material): drawn without dispersion"), 1u)
      << "drawn without it, even when required\n"
      << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "extensions used but not implemented, ignored: KHR_materials_foo"), 1u) << all_warnings(s);
  EXPECT_EQ(warnings_with(s, "KHR_lights_punctual"), 0u) << all_warnings(s);
  // An unknown required extension is still refused.
  g.doc["extensionsRequired"] = {"KHR_materials_foo"};
  EXPECT_TRUE(contains(load_error(g.write(dir_, "required")), "requires extension KHR_materials_foo"))
      << "unknown stays refused";
}

// ---- the command line ------------------------------------------------------------------------------------------

TEST_F(SceneMaterialsTest, CliRefusesInvalidLightsWithoutWritingFiles) {
  for (size_t k : {size_t(0), size_t(6)}) {  // negative intensity; spot cones
    const LightCase& c = light_cases()[k];
    SCOPED_TRACE(c.name);
    GltfFile g = lights_file();
    c.edit(g.doc);
    const std::string path = g.write(dir_, "bad_light");
    const std::string out = test::temp_dir("bad_light_" + std::to_string(k));
    const test::CliRun r = test::run("render '" + path + "' --view-size 32x16 --display 64x36 --out '" + out + "'");
    test::expect_one_error_line(r, c.message);
    EXPECT_EQ(test::count_entries(out), 0u) << "no output for a refused scene";
  }
}

TEST_F(SceneMaterialsTest, InfoListsLightsAndMaterialFeatures) {
  GltfFile g = lights_file();
  const int uv1 = g.data<float>({0, 2, 2, 2, 2, 0, 0, 0}, kFloat, "VEC2");
  g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] =
      g.data<float>({0, 1, 1, 1, 1, 0, 0, 0}, kFloat, "VEC2");
  g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = uv1;
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.add("images", {{"uri", png_uri(make_png(2, 1, 6, 8, {1, 2, 3, 4, 5, 6, 7, 8}))}});
  g.add("textures", {{"source", 0}});
  g.add("materials",
        {{"name", "Shiny\x1b[31m"},
         {"alphaMode", "MASK"},
         {"doubleSided", true},
         {"pbrMetallicRoughness",
          {{"metallicRoughnessTexture",
            {{"index", 0}, {"texCoord", 1}, {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0}}}}}}}}}},
         {"emissiveFactor", {1, 0.5, 0.25}},
         {"extensions",
          {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}, {"KHR_materials_unlit", json::object()}}}});
  g.add("materials",
        {{"name", "Layers"},
         {"extensions",
          {{"KHR_materials_transmission", {{"transmissionFactor", 0.5}, {"transmissionTexture", {{"index", 0}}}}},
           {"KHR_materials_clearcoat",
            {{"clearcoatFactor", 1},
             {"clearcoatRoughnessFactor", 0.2},
             {"clearcoatNormalTexture", {{"index", 0}, {"scale", 0.5}}}}},
           {"KHR_materials_specular", {{"specularFactor", 0.5}, {"specularColorFactor", {1, 0.5, 0.25}}}},
           {"KHR_materials_anisotropy", {{"anisotropyStrength", 0.3}, {"anisotropyRotation", 1}}},
           {"KHR_materials_iridescence", {{"iridescenceFactor", 1}}},
           {"KHR_materials_sheen",
            {{"sheenColorFactor", {0.5, 0.25, 1}},
             {"sheenRoughnessFactor", 0.7},
             {"sheenRoughnessTexture", {{"index", 0}}}}}}}});
  g.doc["asset"]["generator"] = "Exporter\x1b[2J";
  const std::string path = g.write(dir_, "info");
  const test::CliRun r = test::run("info '" + path + "'");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* part :
       {"lights: 4",
        "0 'Bulb' (light 1): point, node 2 'BulbNode', color (1, 1, 1), intensity 40 cd, range 10, at (1, 2, 0)",
        "1 'Sun' (light 0): directional, node 3 (unnamed), color (1, 0.5, 0.25), intensity 3 lux, toward (0, -1, 0)",
        "spot, node 4", "cones inner 11.4592 deg outer 28.6479 deg",
        "1 'Shiny\\x1b[31m': alpha MASK (cutoff 0.5), double sided, unlit",
        "metallic 1, roughness 1, emissive (1, 0.5, 0.25) x strength 4",
        "metallic-roughness (texture 0 2x1, linear, set 1, transform offset (0.5, 0) rotation 0 scale (1, 1))",
        "0 (default): alpha OPAQUE, single sided", "(generator: Exporter\\x1b[2J)",
        "transmission (texture 0 2x1, linear, set 0)", "clear coat 1 roughness 0.2 normal scale 0.5",
        "clear coat normal (texture 0 2x1, linear, set 0)", "specular 0.5 colour (1, 0.5, 0.25)",
        "anisotropy 0.3 rotation 1", "iridescence 1 ior 1.3 thickness 100-400 nm", "sheen (0.5, 0.25, 1) roughness 0.7",
        "sheen roughness (texture 0 2x1, linear, set 0)"})
    EXPECT_NE(r.output.find(part), std::string::npos) << part << "\n" << r.output;
  EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << "names are printed sanitized";
}

// ---- corpus: generated tangents against the files' own --------------------------------------------------------

// The file with every primitive's material given a normal texture (where it has TANGENT; the others
// get a material without one, so only vertices with file tangents get any), and, with strip, without
// TANGENT attributes (generated instead).
json tangent_test_doc(json doc, bool strip, int set) {
  json& images = doc["images"];
  if (!images.is_array()) images = json::array();
  images.push_back({{"uri", png_uri(kPixel)}});
  json& textures = doc["textures"];
  if (!textures.is_array()) textures = json::array();
  textures.push_back({{"source", images.size() - 1}});
  const size_t normal_texture = textures.size() - 1;
  json& materials = doc["materials"];
  if (!materials.is_array()) materials = json::array();
  materials.push_back(json::object());  // the plain material
  const size_t plain = materials.size() - 1;
  materials.push_back(json::object());  // for primitives without a material
  const size_t bumpy = materials.size() - 1;
  for (json& m : materials)
    if (&m != &materials[plain]) m["normalTexture"] = {{"index", normal_texture}, {"texCoord", set}};
  const std::string uv = "TEXCOORD_" + std::to_string(set);
  for (json& mesh : doc["meshes"])
    for (json& p : mesh["primitives"]) {
      if (!p["attributes"].contains("TANGENT") || !p["attributes"].contains(uv)) {
        p["material"] = plain;
        continue;
      }
      if (!p.contains("material")) p["material"] = bumpy;
      if (!strip) continue;
      p["attributes"].erase("TANGENT");
      if (p.contains("targets"))
        for (json& t : p["targets"]) t.erase("TANGENT");
    }
  return doc;
}

// Writes the edited model beside links to its folder's other files (so relative URIs resolve).
std::string write_variant(const fs::path& model, const json& doc, const fs::path& dir, const std::string& name,
                          const std::vector<uint8_t>& glb_bin, bool glb) {
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(model.parent_path()))
    if (e.path() != model && !fs::exists(dir / e.path().filename()))
      fs::create_symlink(e.path(), dir / e.path().filename());
  if (!glb) {
    const fs::path out = dir / (name + ".gltf");
    std::ofstream(out) << doc.dump();
    return out.string();
  }
  GltfFile g;
  g.doc = doc;
  g.doc.erase("buffers");
  g.bin = glb_bin;
  const fs::path out = dir / (name + ".glb");
  write_bytes(out, g.glb());
  return out.string();
}

TEST(SceneMaterialsCorpus, GeneratedTangentsMatchTheFilesTangents) {
  const std::string corpus = test::corpus_dir();
  if (corpus.empty()) GTEST_SKIP() << "../shared/gltf not found: tangent comparison skipped";
  // Every corpus file with TANGENT. mikk: its exporter made them with MikkTSpace (Blender's); the
  // others (Unity's glTF tools, the VKTS exporter, which also flips w) are reported, not required to
  // match. set: the UV set they follow (Blender's active UV map: MultiUVTest's is its second).
  // min_w: VertexColorTest's 2018 export stores w = +1 on the 4 vertices of one back face whose tiny
  // UV patch is mirrored (MikkTSpace, and Blender's exporter today, give -1 there).
  struct Model {
    std::string path;
    bool mikk;
    int set;
    double min_w;
  };
  const std::vector<Model> models = {
      {"AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf", true, 0, 0.99},
      {"MultiUVTest/glTF/MultiUVTest.gltf", true, 1, 0.99},
      {"VertexColorTest/glTF/VertexColorTest.gltf", true, 0, 0.92},
      {"AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb", true, 0, 0.99},
      {"Avocado/glTF/Avocado.gltf", false, 0, 0.0},
      {"Suzanne/glTF/Suzanne.gltf", false, 0, 0.0},
      {"AnimatedCube/glTF/AnimatedCube.gltf", false, 0, 0.0},
  };
  const fs::path tmp = fs::temp_directory_path() / ("pmr_tangents_" + std::to_string(getpid()));
  for (const auto& [rel, mikk, set, min_w] : models) {
    const fs::path model = fs::path(corpus) / rel;
    SCOPED_TRACE(rel);
    if (!fs::exists(model)) {
      ADD_FAILURE() << "missing from the corpus";
      continue;
    }
    std::ifstream in(model, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const bool glb = model.extension() == ".glb";
    json doc;
    std::vector<uint8_t> bin;
    if (glb) {  // JSON chunk, then the BIN chunk
      auto u32 = [&](size_t o) {
        return uint32_t(bytes[o]) | uint32_t(bytes[o + 1]) << 8 | uint32_t(bytes[o + 2]) << 16 |
               uint32_t(bytes[o + 3]) << 24;
      };
      const uint32_t json_length = u32(12);
      doc = json::parse(bytes.begin() + 20, bytes.begin() + 20 + json_length);
      const size_t b = 20 + json_length;
      bin.assign(bytes.begin() + long(b + 8), bytes.begin() + long(b + 8 + u32(b)));
    } else {
      doc = json::parse(bytes.begin(), bytes.end());
    }
    const fs::path dir = tmp / model.parent_path().filename() / model.stem();
    // the variants' folder links to the model's files, which lie outside it
    InputLimits linked;
    linked.allow_outside_scene_folder = true;
    const Scene file =
        load_scene(write_variant(model, tangent_test_doc(doc, false, set), dir, "file", bin, glb), linked);
    const Scene gen =
        load_scene(write_variant(model, tangent_test_doc(doc, true, set), dir, "generated", bin, glb), linked);
    ASSERT_EQ(file.tangents.size(), gen.tangents.size());
    ASSERT_GT(gen.structure.generated_tangent_primitives, 0u);
    // Vertices where no triangle has a UV area (all its UVs on a line) have no defined tangent, and
    // files store anything there (VertexColorTest: (1, 0, 0) beside a (1, 0, 0) normal): not compared.
    std::vector<uint8_t> defined(gen.positions.size(), 0);
    const std::vector<glm::vec2>& uv = gen.texcoords[size_t(set)];
    for (const PmrTriangle& t : gen.triangles) {
      const glm::dvec2 a(uv[t.v[0]]), b(uv[t.v[1]]), c(uv[t.v[2]]);
      const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      if (std::abs(area) > 1e-10)
        for (uint32_t v : t.v) defined[v] = 1;
    }
    std::vector<double> angles;
    size_t same_w = 0, undefined = 0;
    for (size_t v = 0; v < file.tangents.size(); ++v) {
      const glm::dvec3 a(file.tangents[v]), b(gen.tangents[v]);
      if (a == glm::dvec3(0.0)) continue;
      if (!defined[v]) {
        ++undefined;
        continue;
      }
      angles.push_back(std::acos(std::min(1.0, std::max(-1.0, glm::dot(a, b)))) * 180.0 / kPi);
      same_w += file.tangents[v].w == gen.tangents[v].w;
    }
    ASSERT_FALSE(angles.empty());
    std::sort(angles.begin(), angles.end());
    auto pct = [&](double p) { return angles[std::min(angles.size() - 1, size_t(p * double(angles.size())))]; };
    const double within =
        double(std::upper_bound(angles.begin(), angles.end(), 1.0) - angles.begin()) / double(angles.size());
    std::printf(
        "[ tangents ] %-62s %7zu vertices (%zu without UV area): median %.4f, p90 %.4f, p99 %.4f, max %.2f deg; "
        "%.2f%% within 1 deg; w agrees on %.2f%%\n",
        rel.c_str(), angles.size(), undefined, pct(0.5), pct(0.9), pct(0.99), angles.back(), 100.0 * within,
        100.0 * double(same_w) / double(angles.size()));
    if (!mikk) continue;  // other exporters' tangents are reported, not required to match
    EXPECT_GE(within, 0.99) << "generated tangents within 1 degree of the file's on 99% of the vertices";
    EXPECT_GE(double(same_w) / double(angles.size()), min_w) << "handedness";
  }
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace pmr
