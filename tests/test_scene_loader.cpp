// The glTF scene loader (host/scene): hand-written files with known answers, malformed files that must
// fail with a clear pmr::Error (never crash), and the shared sample-model corpus.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "pmr/scene.h"
#include "gltf_builder.h"
#include "reference/shade_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using namespace pmr::test::gltf_builder_detail;

bool any_warning(const Scene& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (contains(w, part)) return true;
  return false;
}

glm::vec3 corner(const Scene& s, size_t tri, int k) { return s.positions[s.triangles[tri].v[k]]; }
glm::vec3 vec3(const float* f) { return {f[0], f[1], f[2]}; }

#define EXPECT_VEC3_NEAR(a, b, tol)                                                           \
  do {                                                                                        \
    const glm::vec3 a_ = (a), b_ = (b);                                                       \
    EXPECT_NEAR(a_.x, b_.x, tol) << #a " = (" << a_.x << ", " << a_.y << ", " << a_.z << ")"; \
    EXPECT_NEAR(a_.y, b_.y, tol) << #a " = (" << a_.x << ", " << a_.y << ", " << a_.z << ")"; \
    EXPECT_NEAR(a_.z, b_.z, tol) << #a " = (" << a_.x << ", " << a_.y << ", " << a_.z << ")"; \
  } while (0)

class SceneLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pmr_scene_loader_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// One triangle (0,0,0) (1,0,0) (0,1,0) with normals, u16 indices, in mesh 0.
GltfFile unit_triangle(const std::vector<float>& normal = {0, 0, 1}) {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
  std::vector<float> normals;
  for (int i = 0; i < 3; ++i) normals.insert(normals.end(), normal.begin(), normal.end());
  const int nrm = g.data<float>(normals, kFloat, "VEC3");
  const int idx = g.data<uint16_t>({0, 1, 2}, kUShort, "SCALAR");
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}, {"indices", idx}}}));
  return g;
}

// ---- hand-made files with known answers ---------------------------------------------------------------

// Parent: matrix translating by (10,0,0). Child: T (0,0,5), R 90 deg about +Z, S (2,1,1).
// (1,0,0) -> S (2,0,0) -> R (0,2,0) -> T (0,2,5) -> parent (10,2,5); normals use R S^-1.
TEST_F(SceneLoaderTest, TrsChildUnderMatrixParentGivesExactWorldPositionsAndNormals) {
  const double h = std::sqrt(0.5);
  GltfFile g = unit_triangle({float(h), float(h), 0});
  g.add("nodes", {{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1}}, {"children", {1}}});
  g.add("nodes", {{"mesh", 0}, {"translation", {0, 0, 5}}, {"rotation", {0, 0, h, h}}, {"scale", {2, 1, 1}}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "trs"));
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_VEC3_NEAR(corner(s, 0, 0), glm::vec3(10, 0, 5), 1e-5);
  EXPECT_VEC3_NEAR(corner(s, 0, 1), glm::vec3(10, 2, 5), 1e-5);
  EXPECT_VEC3_NEAR(corner(s, 0, 2), glm::vec3(9, 0, 5), 1e-5);
  const glm::vec3 expected_normal = glm::normalize(glm::vec3(-1.0f, 0.5f, 0.0f));
  for (int k = 0; k < 3; ++k) EXPECT_VEC3_NEAR(vec3(s.attributes[s.triangles[0].v[k]].normal), expected_normal, 1e-6);
  EXPECT_EQ(s.triangles[0].has_normals, 1u);
  EXPECT_VEC3_NEAR(vec3(s.triangles[0].face_normal), glm::vec3(0, 0, 1), 1e-6);
  // No material: the default one (white, untextured, opaque, single-sided); no UVs (no set is read) or
  // colours: defaults.
  EXPECT_EQ(s.triangles[0].material, 0u);
  ASSERT_GE(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].base_color[0], 1.0f);
  ASSERT_GE(s.material_inputs.size(), 1u);
  EXPECT_EQ(s.material_inputs[0].slots[kSlotBaseColor].texture, -1);
  EXPECT_EQ(s.materials[0].alpha_mode, PMR_ALPHA_OPAQUE);
  EXPECT_EQ(s.materials[0].double_sided, 0u);
  EXPECT_TRUE(s.texcoords.empty());
  const PmrVertexAttr& a = s.attributes[s.triangles[0].v[0]];
  for (float c : a.color) EXPECT_EQ(c, 1.0f);
  glm::dvec3 lo, hi;
  scene_bounds(s, lo, hi);
  EXPECT_NEAR(lo.x, 9, 1e-5);
  EXPECT_NEAR(hi.y, 2, 1e-5);
  EXPECT_NEAR(lo.z, 5, 1e-5);
}

// The same mesh under a plain node and a mirroring node (scale -1 in x): both stay counter-clockwise
// seen from the front, so the mirrored copy lists its last two vertices swapped; instancing emits both.
TEST_F(SceneLoaderTest, MirroredNodeReversesWinding) {
  GltfFile g = unit_triangle();
  g.add("nodes", {{"mesh", 0}});
  g.add("nodes", {{"mesh", 0}, {"scale", {-1, 1, 1}}});
  g.scene({0, 1});
  const Scene s = load_scene(g.write(dir_, "mirror"));
  ASSERT_EQ(s.triangles.size(), 2u);
  ASSERT_EQ(s.positions.size(), 6u);
  const PmrTriangle& plain = s.triangles[0];
  const PmrTriangle& mirrored = s.triangles[1];
  EXPECT_EQ(plain.v[0], 0u);
  EXPECT_EQ(plain.v[1], 1u);
  EXPECT_EQ(plain.v[2], 2u);
  EXPECT_EQ(mirrored.v[0], 3u);
  EXPECT_EQ(mirrored.v[1], 5u);
  EXPECT_EQ(mirrored.v[2], 4u);
  EXPECT_VEC3_NEAR(corner(s, 1, 2), glm::vec3(-1, 0, 0), 0);
  // Both face +Z: the mirror in x keeps the z-facing normal (inverse transpose of diag(-1,1,1)).
  EXPECT_VEC3_NEAR(vec3(plain.face_normal), glm::vec3(0, 0, 1), 1e-7);
  EXPECT_VEC3_NEAR(vec3(mirrored.face_normal), glm::vec3(0, 0, 1), 1e-7);
  EXPECT_VEC3_NEAR(vec3(s.attributes[mirrored.v[0]].normal), glm::vec3(0, 0, 1), 1e-7);
}

// Quad (0,0) (1,0) (1,1) (0,1) drawn with u8, u16 and u32 indices, and without indices from a strided
// bufferView (16-byte stride, 4 bytes of padding per vertex).
TEST_F(SceneLoaderTest, IndexTypesAndNonIndexedGiveTheSameTriangles) {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, kFloat, "VEC3");
  const int i8 = g.data<uint8_t>({0, 1, 2, 0, 2, 3}, kUByte, "SCALAR");
  const int i16 = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, kUShort, "SCALAR");
  const int i32 = g.data<uint32_t>({0, 1, 2, 0, 2, 3}, kUInt, "SCALAR");
  const float pad = -99.0f;
  const int strided_view =
      g.view<float>({0, 0, 0, pad, 1, 0, 0, pad, 1, 1, 0, pad, 0, 0, 0, pad, 1, 1, 0, pad, 0, 1, 0, pad}, 16);
  const int strided = g.accessor(strided_view, kFloat, "VEC3", 6);
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", i8}},
                      {{"attributes", {{"POSITION", pos}}}, {"indices", i16}},
                      {{"attributes", {{"POSITION", pos}}}, {"indices", i32}},
                      {{"attributes", {{"POSITION", strided}}}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "indices"));
  ASSERT_EQ(s.triangles.size(), 8u);
  const glm::vec3 expected[2][3] = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  for (size_t t = 0; t < 8; ++t) {
    SCOPED_TRACE("triangle " + std::to_string(t));
    for (int k = 0; k < 3; ++k) EXPECT_VEC3_NEAR(corner(s, t, k), expected[t % 2][k], 0);
    EXPECT_EQ(s.triangles[t].has_normals, 0u);
    EXPECT_VEC3_NEAR(vec3(s.triangles[t].face_normal), glm::vec3(0, 0, 1), 1e-7);
  }
}

// Strip v0..v4 -> (0,1,2) (1,3,2) (2,3,4): every other triangle reversed so all face +Z.
// Fan v0..v4 -> (1,2,0) (2,3,0) (3,4,0) (the spec's order).
TEST_F(SceneLoaderTest, StripAndFanBecomeCounterClockwiseTriangles) {
  GltfFile g;
  const int strip = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0}, kFloat, "VEC3");
  const int fan = g.data<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0}, kFloat, "VEC3");
  const int fan_idx = g.data<uint16_t>({0, 1, 2, 3, 4}, kUShort, "SCALAR");
  g.mesh(json::array({{{"attributes", {{"POSITION", strip}}}, {"mode", 5}},
                      {{"attributes", {{"POSITION", fan}}}, {"indices", fan_idx}, {"mode", 6}},
                      {{"attributes", {{"POSITION", fan}}}, {"mode", 1}}}));  // LINES: skipped
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "strips"));
  ASSERT_EQ(s.triangles.size(), 6u);
  const uint32_t expected[6][3] = {{0, 1, 2}, {1, 3, 2}, {2, 3, 4}, {6, 7, 5}, {7, 8, 5}, {8, 9, 5}};
  for (size_t t = 0; t < 6; ++t) {
    SCOPED_TRACE("triangle " + std::to_string(t));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.triangles[t].v[k], expected[t][k]);
    EXPECT_VEC3_NEAR(vec3(s.triangles[t].face_normal), glm::vec3(0, 0, 1), 1e-7);
  }
  EXPECT_TRUE(any_warning(s, "line primitive")) << "LINES must be skipped with a warning";
}

// tinygltf parses `sparse` but does not apply it. Here it replaces vertices 1 and 3 of a buffer-backed
// accessor, and fills an accessor that has no bufferView (zeros).
TEST_F(SceneLoaderTest, SparseAccessorsAreApplied) {
  GltfFile g;
  const int base_view = g.view<float>({0, 0, 0, 9, 9, 9, 1, 1, 0, 9, 9, 9});
  const int sparse_idx = g.view<uint8_t>({1, 3});
  const int sparse_val = g.view<float>({1, 0, 0, 0, 1, 0});
  const int sparse_idx16 = g.view<uint16_t>({1, 2});
  const int pos = g.accessor(base_view, kFloat, "VEC3", 4);
  g.doc["accessors"][pos]["sparse"] = {{"count", 2},
                                       {"indices", {{"bufferView", sparse_idx}, {"componentType", kUByte}}},
                                       {"values", {{"bufferView", sparse_val}}}};
  const int zeros = g.accessor(-1, kFloat, "VEC3", 3);
  g.doc["accessors"][zeros]["sparse"] = {{"count", 2},
                                         {"indices", {{"bufferView", sparse_idx16}, {"componentType", kUShort}}},
                                         {"values", {{"bufferView", sparse_val}}}};
  const int idx = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, kUShort, "SCALAR");
  g.mesh(
      json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}, {{"attributes", {{"POSITION", zeros}}}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "sparse"));
  ASSERT_EQ(s.positions.size(), 7u);
  const glm::vec3 expected[7] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (size_t v = 0; v < 7; ++v) {
    SCOPED_TRACE("vertex " + std::to_string(v));
    EXPECT_VEC3_NEAR(s.positions[v], expected[v], 0);
  }
  EXPECT_EQ(s.triangles.size(), 3u);
}

// Normalized integers map per the glTF formulas: u8 c/255, u16 c/65535, i8 max(c/127, -1).
TEST_F(SceneLoaderTest, NormalizedColoursTexcoordsAndNormals) {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
  const int col8 = g.data<uint8_t>({255, 128, 0, 51, 0, 0, 0, 0, 255, 255, 255, 255}, kUByte, "VEC4", true);
  const int col16 = g.data<uint16_t>({65535, 0, 32768, 0, 0, 0, 13107, 13107, 13107}, kUShort, "VEC3", true);
  const int uv16 = g.data<uint16_t>({65535, 32768, 0, 0, 13107, 65535}, kUShort, "VEC2", true);
  const int nrm8 = g.data<int8_t>({0, 0, 127, 0, 0, -128, -127, 0, 0, 0, 0, 0}, kByte, "VEC3", true);  // padded to 4
  g.doc["accessors"][nrm8]["count"] = 3;
  // a base colour texture, so that TEXCOORD_0 is read
  g.add("images", {{"uri", png_uri(make_png(1, 1, 6, 8, {255, 255, 255, 255}))}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}, {"COLOR_0", col8}, {"TEXCOORD_0", uv16}, {"NORMAL", nrm8}}},
                       {"material", 0}},
                      {{"attributes", {{"POSITION", pos}, {"COLOR_0", col16}}}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "normalized"));
  ASSERT_EQ(s.attributes.size(), 6u);
  const PmrVertexAttr* a = s.attributes.data();
  EXPECT_FLOAT_EQ(a[0].color[0], 1.0f);
  EXPECT_FLOAT_EQ(a[0].color[1], 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(a[0].color[2], 0.0f);
  EXPECT_FLOAT_EQ(a[0].color[3], 0.2f);
  EXPECT_FLOAT_EQ(a[2].color[3], 1.0f);
  ASSERT_EQ(s.texcoords.size(), 1u);
  EXPECT_FLOAT_EQ(s.texcoords[0][0].x, 1.0f);
  EXPECT_FLOAT_EQ(s.texcoords[0][0].y, 32768.0f / 65535.0f);
  EXPECT_FLOAT_EQ(s.texcoords[0][2].x, 0.2f);
  EXPECT_FLOAT_EQ(s.texcoords[0][2].y, 1.0f);
  EXPECT_VEC3_NEAR(vec3(a[0].normal), glm::vec3(0, 0, 1), 0);
  EXPECT_VEC3_NEAR(vec3(a[1].normal), glm::vec3(0, 0, -1), 0);  // -128 clamps to -1
  EXPECT_VEC3_NEAR(vec3(a[2].normal), glm::vec3(-1, 0, 0), 0);
  EXPECT_EQ(s.triangles[0].has_normals, 1u);
  // VEC3 u16 colour: alpha 1.
  EXPECT_FLOAT_EQ(a[3].color[0], 1.0f);
  EXPECT_FLOAT_EQ(a[3].color[2], 32768.0f / 65535.0f);
  EXPECT_FLOAT_EQ(a[3].color[3], 1.0f);
  EXPECT_FLOAT_EQ(a[5].color[1], 0.2f);
  EXPECT_EQ(s.triangles[1].has_normals, 0u);
}

// Materials, textures (PNG in every channel layout and 16 bits), samplers and KHR_texture_transform.
TEST_F(SceneLoaderTest, MaterialsTexturesSamplersAndTextureTransform) {
  GltfFile g;
  g.doc["extensionsUsed"] = {"KHR_texture_transform", "KHR_materials_foo"};
  g.doc["extensionsRequired"] = {"KHR_texture_transform"};
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, kFloat, "VEC3");
  const int uv0 = g.data<float>({9, 9, 9, 9, 9, 9, 9, 9}, kFloat, "VEC2");
  const int uv1 = g.data<float>({0, 0, 1, 0, 1, 1, 0, 1}, kFloat, "VEC2");
  const int idx = g.data<uint8_t>({0, 1, 2, 0, 2, 3}, kUByte, "SCALAR");
  g.add("images", {{"uri", png_uri(make_png(2, 1, 6, 8, {255, 0, 0, 255, 0, 0, 255, 128}))}});
  g.add("images", {{"uri", png_uri(make_png(1, 2, 0, 16, {0xff, 0xff, 0x80, 0x00}))}});
  g.add("images", {{"uri", png_uri(make_png(2, 1, 4, 8, {10, 20, 30, 40}))}});
  g.add("images", {{"uri", png_uri(make_png(1, 1, 2, 8, {1, 2, 3}))}});
  g.add("images", {{"uri", "nope.png"}});
  g.add("images", {{"uri", "data:image/png;base64,AAAAAAAA"}});
  g.add("samplers", {{"wrapS", 33648}, {"wrapT", 33071}});
  for (int i = 0; i < 6; ++i) g.add("textures", {{"source", i}, {"sampler", 0}});
  json tt = {{"offset", {0, 1}}, {"rotation", 1.57079632679}, {"scale", {0.5, 0.5}}, {"texCoord", 1}};
  g.add("materials",
        {{"pbrMetallicRoughness",
          {{"baseColorFactor", {0.5, 0.25, 1, 1}},
           {"baseColorTexture", {{"index", 0}, {"texCoord", 0}, {"extensions", {{"KHR_texture_transform", tt}}}}}}},
         {"alphaMode", "MASK"},
         {"alphaCutoff", 0.25},
         {"doubleSided", true}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}, {"alphaMode", "BLEND"}});
  for (int t = 2; t < 6; ++t) g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", t}}}}}});
  json prims = json::array();
  for (int m = 0; m < 6; ++m)
    prims.push_back({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}, {"TEXCOORD_1", uv1}}},
                     {"indices", idx},
                     {"material", m}});
  g.mesh(prims);
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "materials"));
  ASSERT_EQ(s.materials.size(), 7u);  // default + 6
  const PmrMaterial& m0 = s.materials[1];
  EXPECT_EQ(m0.base_color[0], 0.5f);
  EXPECT_EQ(m0.base_color[1], 0.25f);
  EXPECT_EQ(m0.alpha_mode, PMR_ALPHA_MASK);
  EXPECT_EQ(m0.alpha_cutoff, 0.25f);
  EXPECT_EQ(m0.double_sided, 1u);
  EXPECT_EQ(s.materials[2].alpha_mode, PMR_ALPHA_BLEND);
  EXPECT_EQ(s.materials[3].alpha_cutoff, 0.5f);
  ASSERT_EQ(s.textures.size(), 4u);  // the missing and the undecodable image give none
  auto texture = [&](int material) -> const SceneTexture& {
    return s.textures[size_t(s.material_inputs[size_t(material)].slots[kSlotBaseColor].texture)];
  };
  ASSERT_GE(s.material_inputs[1].slots[kSlotBaseColor].texture, 0);
  EXPECT_EQ(texture(1).width, 2);
  EXPECT_EQ(texture(1).height, 1);
  EXPECT_EQ(texture(1).rgba, (std::vector<uint8_t>{255, 0, 0, 255, 0, 0, 255, 128}));
  EXPECT_EQ(texture(1).wrap_s, PMR_WRAP_MIRROR);
  EXPECT_EQ(texture(1).wrap_t, PMR_WRAP_CLAMP);
  EXPECT_EQ(texture(2).rgba, (std::vector<uint8_t>{255, 255, 255, 255, 128, 128, 128, 255}));  // 16-bit grey
  EXPECT_EQ(texture(3).rgba, (std::vector<uint8_t>{10, 10, 10, 20, 30, 30, 30, 40}));          // grey + alpha
  EXPECT_EQ(texture(4).rgba, (std::vector<uint8_t>{1, 2, 3, 255}));                            // RGB
  EXPECT_EQ(s.material_inputs[5].slots[kSlotBaseColor].texture, -1);
  EXPECT_EQ(s.material_inputs[6].slots[kSlotBaseColor].texture, -1);
  EXPECT_TRUE(any_warning(s, "nope.png")) << "a missing image is a warning naming it";
  EXPECT_TRUE(any_warning(s, "cannot decode"));
  EXPECT_FALSE(any_warning(s, "alphaMode BLEND")) << "BLEND is composited (DESIGN 4c step 3), not warned";
  EXPECT_TRUE(any_warning(s, "KHR_materials_foo"));
  EXPECT_FALSE(any_warning(s, "KHR_texture_transform"));
  // The extension's own example: offset (0,1), rotation pi/2, scale 0.5 maps the unit square onto the
  // lower-left quadrant of the image, (0,0) -> (0,1), (1,0) -> (0,0.5), (1,1) -> (0.5,0.5),
  // (0,1) -> (0.5,1); its texCoord (1) overrides the textureInfo's (0). The slot keeps the extension's
  // values and the sets stay as stored: the kernels apply the transform.
  const SceneTextureSlot& slot = s.material_inputs[1].slots[kSlotBaseColor];
  EXPECT_EQ(slot.texcoord, 1);
  EXPECT_TRUE(slot.transform);
  EXPECT_EQ(slot.offset[0], 0.0f);
  EXPECT_EQ(slot.offset[1], 1.0f);
  EXPECT_FLOAT_EQ(slot.rotation, 1.57079632679f);
  EXPECT_EQ(slot.scale[0], 0.5f);
  EXPECT_EQ(slot.scale[1], 0.5f);
  const float stored_uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}},
              expected_uv[4][2] = {{0, 1}, {0, 0.5f}, {0.5f, 0.5f}, {0.5f, 1}};
  ASSERT_EQ(s.triangles[0].material, 1u);
  ASSERT_EQ(s.texcoords.size(), 2u);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(s.texcoords[1][size_t(v)], glm::vec2(stored_uv[v][0], stored_uv[v][1])) << "vertex " << v;
    const glm::dvec2 uv = ref::transformed_uv(slot, glm::dvec2(s.texcoords[1][size_t(v)]));
    EXPECT_NEAR(uv.x, expected_uv[v][0], 1e-6) << "vertex " << v;
    EXPECT_NEAR(uv.y, expected_uv[v][1], 1e-6) << "vertex " << v;
  }
  // material 2 reads TEXCOORD_0 untransformed
  EXPECT_EQ(s.material_inputs[2].slots[kSlotBaseColor].texcoord, 0);
  EXPECT_FALSE(s.material_inputs[2].slots[kSlotBaseColor].transform);
  EXPECT_EQ(s.texcoords[0][4], glm::vec2(9.0f));
}

// The container is recognised by its magic bytes: a GLB named .gltf and JSON named .glb both load.
// The GLB also stores an image in a bufferView.
// An empty IDAT chunk is legal PNG and carries no data; first among the IDATs it once made the image
// decoder pass a null buffer to memcpy (found by the glTF fuzzer). The image decodes as without it.
TEST_F(SceneLoaderTest, EmptyIdatChunksDecodeAsWithoutThem) {
  const std::vector<uint8_t> rgba = {255, 0, 0, 255, 0, 0, 255, 128, 9, 8, 7, 6, 5, 4, 3, 2};
  const std::vector<uint8_t> plain = make_png(2, 2, 6, 8, rgba);
  // 8-byte signature, then IHDR (12 + 13 bytes): an empty IDAT right before the real one, one after it
  const size_t first_idat = 8 + 12 + 13;
  std::vector<uint8_t> body = {'I', 'D', 'A', 'T'};
  std::vector<uint8_t> empty = {0, 0, 0, 0, 'I', 'D', 'A', 'T'};
  put_be32(empty, crc32(body.data(), body.size()));
  std::vector<uint8_t> with_empty(plain.begin(), plain.begin() + long(first_idat));
  with_empty.insert(with_empty.end(), empty.begin(), empty.end());
  with_empty.insert(with_empty.end(), plain.begin() + long(first_idat), plain.end() - 12);
  with_empty.insert(with_empty.end(), empty.begin(), empty.end());
  with_empty.insert(with_empty.end(), plain.end() - 12, plain.end());  // IEND
  for (const auto& png : {plain, with_empty}) {
    GltfFile g;
    const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 1, 1, 0}, kFloat, "VEC3");
    const int uv = g.data<float>({0, 0, 1, 0, 1, 1}, kFloat, "VEC2");
    g.add("images", {{"uri", png_uri(png)}});
    g.add("textures", {{"source", 0}});
    g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    g.mesh({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}}});
    g.add("nodes", {{"mesh", 0}});
    g.scene({0});
    const Scene s = load_scene(g.write(dir_, png.size() == plain.size() ? "plain" : "empty_idat"));
    ASSERT_EQ(s.textures.size(), 1u) << "the image was not decoded";
    EXPECT_EQ(s.textures[0].rgba, rgba);
  }
}

TEST_F(SceneLoaderTest, GlbDetectedByContentNotExtension) {
  GltfFile g = unit_triangle();
  const std::vector<uint8_t> png = make_png(1, 1, 6, 8, {1, 2, 3, 4});
  const int png_view = g.view(png);
  g.add("images", {{"bufferView", png_view}, {"mimeType", "image/png"}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  // (a textured material needs the texture's UV set: docs/SHADING.md)
  g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = g.data<float>({0, 0, 1, 0, 0, 1}, kFloat, "VEC2");
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  write_bytes(dir_ / "binary.gltf", g.glb());
  const Scene s = load_scene((dir_ / "binary.gltf").string());
  EXPECT_EQ(s.triangles.size(), 1u);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].rgba, (std::vector<uint8_t>{1, 2, 3, 4}));
  g.write(dir_, "text", /*embed=*/true);
  fs::rename(dir_ / "text.gltf", dir_ / "text.glb");
  EXPECT_EQ(load_scene((dir_ / "text.glb").string()).triangles.size(), 1u);
}

// Cameras: kept in glTF order; placed by the first node using them, with that node's world matrix; a
// further node using one gets an entry of its own after them, with its own matrix.
TEST_F(SceneLoaderTest, CamerasArePlacedByTheirNodes) {
  GltfFile g = unit_triangle();
  g.add("cameras", {{"type", "perspective"}, {"name", "main"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}});
  g.add("cameras",
        {{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}});
  g.add("cameras",
        {{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 1}, {"zfar", 50}, {"aspectRatio", 2}}}});
  g.add("nodes", {{"mesh", 0}, {"translation", {1, 0, 0}}, {"children", {1}}});
  g.add("nodes", {{"camera", 0}, {"translation", {0, 0, 5}}});
  g.add("nodes", {{"camera", 1}});
  g.add("nodes", {{"camera", 0}, {"translation", {7, 7, 7}}});  // second user of camera 0: entry 3
  g.scene({0, 2, 3});
  const Scene s = load_scene(g.write(dir_, "cameras"));
  ASSERT_EQ(s.cameras.size(), 4u);
  EXPECT_EQ(s.cameras[3].shared_with, 0);
  EXPECT_EQ(s.cameras[3].world_from_camera[3], glm::dvec4(7, 7, 7, 1));
  EXPECT_DOUBLE_EQ(s.cameras[3].yfov, 0.8);
  EXPECT_EQ(s.cameras[0].shared_with, -1);
  EXPECT_TRUE(s.cameras[0].placed);
  EXPECT_TRUE(s.cameras[0].perspective);
  EXPECT_EQ(s.cameras[0].name, "main");
  EXPECT_DOUBLE_EQ(s.cameras[0].yfov, 0.8);
  EXPECT_DOUBLE_EQ(s.cameras[0].znear, 0.1);
  EXPECT_EQ(s.cameras[0].zfar, 0.0);
  EXPECT_EQ(s.cameras[0].aspect, 0.0);
  EXPECT_EQ(s.cameras[0].world_from_camera[3], glm::dvec4(1, 0, 5, 1));
  EXPECT_TRUE(s.cameras[1].placed);
  EXPECT_FALSE(s.cameras[1].perspective);
  EXPECT_FALSE(s.cameras[2].placed);  // no node uses it
  EXPECT_DOUBLE_EQ(s.cameras[2].aspect, 2.0);
}

// A placed camera whose yfov cannot drive the rig is reported as that: a warning naming yfov, and
// --camera refused with the same reason (not as "not placed").
TEST_F(SceneLoaderTest, ACameraWithABadYfovSaysSo) {
  GltfFile g = unit_triangle();
  g.add("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 4.0}, {"znear", 0.1}}}});
  g.add("nodes", {{"mesh", 0}});
  g.add("nodes", {{"camera", 0}, {"translation", {0, 0, 5}}});
  g.scene({0, 1});
  const std::string path = g.write(dir_, "bad_yfov");
  const Scene s = load_scene(path);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_TRUE(s.cameras[0].placed);
  EXPECT_EQ(s.cameras[0].invalid, "its yfov must lie between 0 and pi radians");
  EXPECT_TRUE(any_warning(s, "camera 0 has invalid perspective parameters (its yfov must lie between 0 and pi"));
  const test::CliRun r =
      test::run("render " + path + " --camera '#0' --views 2 --view-size 16x8 --out " + (dir_ / "bad_yfov_out").string());
  test::expect_one_error_line(r, "--camera 0 has invalid perspective parameters: its yfov must lie between 0 and pi");
}

// Animated nodes: a camera node moving (LINEAR translation) is followed by the pose; a mesh whose scale
// steps to (-1, 1, 1) is mirrored in that frame and keeps counter-clockwise front faces (winding
// reversed, face normal still +Z, vertex normals by the inverse transpose: (0, 0, 1) stays).
TEST_F(SceneLoaderTest, AnimatedCameraAndMirroringScale) {
  GltfFile g = unit_triangle();
  g.add("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}});
  g.add("nodes", {{"mesh", 0}});
  g.add("nodes", {{"camera", 0}, {"translation", {0, 0, 5}}});
  g.scene({0, 1});
  const int times = g.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
  const int scales = g.data<float>({1, 1, 1, -1, 1, 1}, kFloat, "VEC3");
  const int moves = g.data<float>({0, 0, 5, 2, 0, 5}, kFloat, "VEC3");
  g.doc["animations"] = {
      {{"samplers",
        {{{"input", times}, {"output", scales}, {"interpolation", "STEP"}}, {{"input", times}, {"output", moves}}}},
       {"channels",
        {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "scale"}}}},
         {{"sampler", 1}, {"target", {{"node", 1}, {"path", "translation"}}}}}}}};
  const Scene s = load_scene(g.write(dir_, "animated_camera"));
  PoseRequest r;
  r.animation = 0;
  r.time = 0.5;
  Scene p;
  pose_scene(s, r, p);
  EXPECT_EQ(p.cameras[0].world_from_camera[3], glm::dvec4(1, 0, 5, 1));
  EXPECT_EQ(p.triangles[0].v[1], s.triangles[0].v[1]) << "not mirrored before t = 1";
  r.time = 2.0;
  pose_scene(s, r, p);
  EXPECT_EQ(p.cameras[0].world_from_camera[3], glm::dvec4(2, 0, 5, 1));
  EXPECT_EQ(p.positions[1], glm::vec3(-1, 0, 0));
  EXPECT_EQ(p.triangles[0].v[1], s.triangles[0].v[2]) << "winding reversed under the mirror";
  EXPECT_EQ(p.triangles[0].v[2], s.triangles[0].v[1]);
  EXPECT_EQ(glm::vec3(p.triangles[0].face_normal[0], p.triangles[0].face_normal[1], p.triangles[0].face_normal[2]),
            glm::vec3(0, 0, 1));
  EXPECT_EQ(glm::vec3(p.attributes[0].normal[0], p.attributes[0].normal[1], p.attributes[0].normal[2]),
            glm::vec3(0, 0, 1));
}

// Without scenes, every root node is drawn (with its children).
TEST_F(SceneLoaderTest, NoScenesDrawsAllRootNodes) {
  GltfFile g = unit_triangle();
  g.add("nodes", {{"mesh", 0}, {"children", {1}}});
  g.add("nodes", {{"mesh", 0}, {"translation", {0, 0, 1}}});
  g.add("nodes", {{"mesh", 0}, {"translation", {0, 0, 2}}});
  const Scene s = load_scene(g.write(dir_, "noscene"));
  ASSERT_EQ(s.triangles.size(), 3u);
  EXPECT_EQ(corner(s, 1, 0).z, 1.0f);
  EXPECT_EQ(corner(s, 2, 0).z, 2.0f);
}

// A NaN position (or one beyond float range after the transform) drops the triangles that use it.
TEST_F(SceneLoaderTest, NonFinitePositionsSkipTheirTriangles) {
  GltfFile g;
  const float nan = std::nanf("");
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, nan, 0, 0, 3e38f, 0, 0}, kFloat, "VEC3");
  const int idx = g.data<uint16_t>({0, 1, 2, 0, 3, 2, 0, 1, 4}, kUShort, "SCALAR");
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}}));
  g.add("nodes", {{"mesh", 0}, {"scale", {10, 1, 1}}});
  g.scene({0});
  const Scene s = load_scene(g.write(dir_, "nan"));
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_VEC3_NEAR(corner(s, 0, 1), glm::vec3(10, 0, 0), 0);
  EXPECT_TRUE(any_warning(s, "2 triangle(s) with non-finite"));
  for (const glm::vec3& p : s.positions) EXPECT_TRUE(std::isfinite(p.x));
}

// ---- malformed files: each must throw pmr::Error with a specific message -----------------------------

// An edit that replaces the file's animations with `text` (JSON), after adding accessors 3 (2 float
// key times), 4 (2 VEC3) and 5 (2 VEC4) for it to use (no bufferView: implicit zeros).
std::function<void(GltfFile&)> set_animations(const char* text) {
  return [text](GltfFile& g) {
    for (const char* type : {"SCALAR", "VEC3", "VEC4"}) g.accessor(-1, kFloat, type, 2);
    g.doc["animations"] = nlohmann::json::parse(text);
  };
}

struct BadCase {
  const char* name;
  std::function<void(GltfFile&)> edit;  // applied to a valid one-triangle file
  const char* message;                  // must appear in the error
};

TEST_F(SceneLoaderTest, MalformedFilesThrowClearErrors) {
  const std::vector<BadCase> cases = {
      {"index out of range", [](GltfFile& g) { g.bin[g.doc["bufferViews"][2]["byteOffset"].get<size_t>() + 4] = 7; },
       "accessor 2 (indices of mesh 0 primitive 0) reads index 7 but POSITION has 3 vertices"},
      {"accessor overruns bufferView", [](GltfFile& g) { g.doc["accessors"][0]["count"] = 4; },
       "accessor 0 (POSITION of mesh 0 primitive 0) overruns bufferView 0"},
      {"accessor offset overruns bufferView", [](GltfFile& g) { g.doc["accessors"][1]["byteOffset"] = 4; },
       "overruns bufferView 1"},
      {"huge count", [](GltfFile& g) { g.doc["accessors"][0]["count"] = 1000000000000ull; }, "count 1000000000000"},
      {"huge count without bufferView",
       [](GltfFile& g) {
         g.doc["accessors"][0].erase("bufferView");
         g.doc["accessors"][0]["count"] = 1000000000000ull;
       },
       "implicit zero elements"},
      {"count overflowing 64 bits", [](GltfFile& g) { g.doc["accessors"][0]["count"] = 0xffffffffffffffffull; },
       "overruns bufferView"},
      {"bufferView overruns buffer", [](GltfFile& g) { g.doc["bufferViews"][1]["byteLength"] = 1000; },
       "bufferView 1 (byteOffset 36, byteLength 1000) overruns buffer 0"},
      {"bufferView offset overflow", [](GltfFile& g) { g.doc["bufferViews"][1]["byteOffset"] = 0xfffffffffffffff0ull; },
       "overruns buffer 0"},
      {"bufferView index out of range", [](GltfFile& g) { g.doc["accessors"][1]["bufferView"] = 9; },
       "refers to bufferView 9"},
      {"buffer index out of range", [](GltfFile& g) { g.doc["bufferViews"][0]["buffer"] = 3; },
       "bufferView 0 refers to buffer 3"},
      {"accessor index out of range",
       [](GltfFile& g) { g.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 42; }, "refers to accessor 42"},
      {"mesh index out of range", [](GltfFile& g) { g.doc["nodes"][0]["mesh"] = 5; }, "node 0 refers to mesh 5"},
      {"material index out of range", [](GltfFile& g) { g.doc["meshes"][0]["primitives"][0]["material"] = 2; },
       "refers to material 2"},
      {"texture index out of range",
       [](GltfFile& g) {
         g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 4}}}}}});
         g.doc["meshes"][0]["primitives"][0]["material"] = 0;
       },
       "material 0 baseColorTexture refers to texture 4"},
      {"image index out of range",
       [](GltfFile& g) {
         g.add("textures", {{"source", 3}});
         g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
       },
       "texture 0 refers to image 3"},
      {"sampler index out of range",
       [](GltfFile& g) {
         g.add("textures", {{"sampler", 2}});
         g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
       },
       "texture 0 refers to sampler 2"},
      {"camera index out of range", [](GltfFile& g) { g.doc["nodes"][0]["camera"] = 0; }, "node 0 refers to camera 0"},
      {"child index out of range", [](GltfFile& g) { g.doc["nodes"][0]["children"] = {7}; },
       "node 0 children refers to node 7"},
      {"scene node out of range", [](GltfFile& g) { g.scene({3}); }, "scene 0 refers to node 3"},
      {"default scene out of range", [](GltfFile& g) { g.doc["scene"] = 4; }, "refers to scene 4"},
      {"node cycle",
       [](GltfFile& g) {
         g.doc["nodes"][0]["children"] = {1};
         g.add("nodes", {{"children", {0}}});
       },
       "node cycle through node 0"},
      {"node is its own child", [](GltfFile& g) { g.doc["nodes"][0]["children"] = {0}; }, "node cycle through node 0"},
      {"node with two parents",
       [](GltfFile& g) {
         g.doc["nodes"][0]["children"] = {2};
         g.add("nodes", {{"children", {2}}});
         g.add("nodes", {{"mesh", 0}});
         g.scene({0, 1});
       },
       "node 2 has two parents"},
      {"scene root that is a child",
       [](GltfFile& g) {
         g.doc["nodes"][0]["children"] = {1};
         g.add("nodes", {{"mesh", 0}});
         g.scene({0, 1});
       },
       "lists node 1 as a root, but it is a child of node 0"},
      {"matrix of 15 values", [](GltfFile& g) { g.doc["nodes"][0]["matrix"] = std::vector<double>(15, 1.0); },
       "16 expected"},
      {"matrix value beyond double range",
       [](GltfFile& g) {
         std::vector<double> m = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
         m[12] = HUGE_VAL;  // written as 1e999 below
         g.doc["nodes"][0]["matrix"] = m;
       },
       "invalid JSON: number overflow"},
      {"zero quaternion",
       [](GltfFile& g) {
         g.doc["nodes"][0]["rotation"] = {0, 0, 0, 0};
       },
       "zero-length rotation"},
      {"overflowing world matrix",
       [](GltfFile& g) {
         g.doc["nodes"][0]["scale"] = {1e300, 1, 1};
         g.doc["nodes"][0]["children"] = {1};
         g.add("nodes", {{"scale", {1e300, 1, 1}}, {"mesh", 0}});
       },
       "node 1 has a world matrix that overflows"},
      {"POSITION as UNSIGNED_INT", [](GltfFile& g) { g.doc["accessors"][0]["componentType"] = kUInt; },
       "componentType UNSIGNED_INT, which POSITION does not allow"},
      {"POSITION as VEC2", [](GltfFile& g) { g.doc["accessors"][0]["type"] = "VEC2"; },
       "type VEC2, which POSITION does not allow"},
      {"normalized float", [](GltfFile& g) { g.doc["accessors"][1]["normalized"] = true; }, "FLOAT (normalized)"},
      {"float indices", [](GltfFile& g) { g.doc["accessors"][2]["componentType"] = kFloat; },
       "which indices does not allow"},
      {"byteStride below element size", [](GltfFile& g) { g.doc["bufferViews"][0]["byteStride"] = 4; },
       "has byteStride 4"},
      {"NORMAL count differs", [](GltfFile& g) { g.doc["accessors"][1]["count"] = 2; },
       "has 2 elements but POSITION has 3"},
      {"sparse index out of range",
       [](GltfFile& g) {
         g.doc["accessors"][0]["sparse"] = {
             {"count", 1},
             {"indices", {{"bufferView", 2}, {"componentType", kUShort}, {"byteOffset", 4}}},
             {"values", {{"bufferView", 0}}}};
         g.bin[g.doc["bufferViews"][2]["byteOffset"].get<size_t>() + 4] = 200;
       },
       "sparse index 200 but only 3 elements"},
      {"sparse values overrun",
       [](GltfFile& g) {
         g.doc["accessors"][0]["sparse"] = {{"count", 3},
                                            {"indices", {{"bufferView", 2}, {"componentType", kUShort}}},
                                            {"values", {{"bufferView", 2}}}};
       },
       "sparse values overruns bufferView 2"},
      {"instancing past the triangle limit",
       [](GltfFile& g) {  // 5592405 implicit triangles x 25 nodes; must fail before allocating
         g.doc["accessors"][0].erase("bufferView");
         g.doc["accessors"][0]["count"] = 16777215;
         g.doc["meshes"][0]["primitives"][0].erase("indices");
         std::vector<int> roots;
         for (int i = 0; i < 25; ++i) roots.push_back(g.add("nodes", {{"mesh", 0}}));
         g.scene(roots);
       },
       "triangles; the renderer supports at most 134217727"},
      {"primitive mode 9", [](GltfFile& g) { g.doc["meshes"][0]["primitives"][0]["mode"] = 9; }, "mode 9"},
      {"Draco required",
       [](GltfFile& g) {
         g.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
         g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
       },
       "requires KHR_draco_mesh_compression (Draco-compressed meshes), which this renderer does not support"},
      {"unknown required extension", [](GltfFile& g) { g.doc["extensionsRequired"] = {"EXT_foo_bar"}; },
       "requires extension EXT_foo_bar, which this renderer does not support"},
      {"glTF 1.0", [](GltfFile& g) { g.doc["asset"]["version"] = "1.0"; }, "glTF version 1.0 is not supported"},
      {"no asset", [](GltfFile& g) { g.doc.erase("asset"); }, "asset.version is missing"},
      {"accessor without componentType", [](GltfFile& g) { g.doc["accessors"][0].erase("componentType"); },
       "not a valid glTF file"},
      // the schema's minimums, which tinygltf would coerce (gltf_schema.cpp)
      {"negative bufferView byteOffset", [](GltfFile& g) { g.doc["bufferViews"][1]["byteOffset"] = -4; },
       "bufferView 1 byteOffset is -4, which the glTF schema does not allow (minimum 0)"},
      {"negative accessor byteOffset", [](GltfFile& g) { g.doc["accessors"][1]["byteOffset"] = -12; },
       "accessor 1 byteOffset is -12"},
      {"zero accessor count", [](GltfFile& g) { g.doc["accessors"][0]["count"] = 0; }, "accessor 0 count is 0"},
      {"zero bufferView byteLength", [](GltfFile& g) { g.doc["bufferViews"][0]["byteLength"] = 0; },
       "bufferView 0 byteLength is 0"},
      {"byteStride not a multiple of 4", [](GltfFile& g) { g.doc["bufferViews"][0]["byteStride"] = 14; },
       "bufferView 0 byteStride is 14"},
      {"byteStride above 252", [](GltfFile& g) { g.doc["bufferViews"][0]["byteStride"] = 256; }, "from 4 to 252"},
      {"fractional index", [](GltfFile& g) { g.doc["nodes"][0]["mesh"] = 0.5; }, "node 0 mesh is not an integer"},
      {"negative mesh index", [](GltfFile& g) { g.doc["nodes"][0]["mesh"] = -1; }, "node 0 mesh is -1"},
      {"negative attribute accessor",
       [](GltfFile& g) { g.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = -2; },
       "mesh 0 primitive 0 attribute NORMAL is -2"},
      {"animation sampler out of range",
       set_animations(
           R"([{"samplers":[{"input":3,"output":4}],"channels":[{"sampler":1,"target":{"node":0,"path":"translation"}}]}])"),
       "animation 0 channel 0 sampler refers to sampler 1, but the file has 1"},
      {"animation target node out of range",
       set_animations(
           R"([{"samplers":[{"input":3,"output":4}],"channels":[{"sampler":0,"target":{"node":9,"path":"translation"}}]}])"),
       "animation 0 channel 0 target node refers to node 9"},
      {"animation path unknown",
       set_animations(
           R"([{"samplers":[{"input":3,"output":4}],"channels":[{"sampler":0,"target":{"node":0,"path":"colour"}}]}])"),
       "animation 0 channel 0 target path is 'colour'; the glTF schema allows translation, rotation, scale, weights"},
      {"animation interpolation unknown",
       set_animations(
           R"([{"samplers":[{"input":3,"output":4,"interpolation":"CUBIC"}],"channels":[{"sampler":0,"target":{"node":0,"path":"scale"}}]}])"),
       "animation 0 sampler 0 interpolation is 'CUBIC'"},
      {"animation input accessor out of range",
       set_animations(
           R"([{"samplers":[{"input":30,"output":4}],"channels":[{"sampler":0,"target":{"node":0,"path":"scale"}}]}])"),
       "animation 0 sampler 0 input refers to accessor 30"},
      {"animation without channels", set_animations(R"([{"samplers":[{"input":3,"output":4}]}])"),
       "animation 0 has no channels"},
      {"animation input not float scalars",
       set_animations(
           R"([{"samplers":[{"input":4,"output":4}],"channels":[{"sampler":0,"target":{"node":0,"path":"scale"}}]}])"),
       "animation 0 sampler 0 input (accessor 4) must hold float scalars"},
      {"animation output type for the path",
       set_animations(
           R"([{"samplers":[{"input":3,"output":4}],"channels":[{"sampler":0,"target":{"node":0,"path":"rotation"}}]}])"),
       "animates rotation but its sampler's output (accessor 4) has type VEC3, VEC4 expected"},
      {"animation CUBICSPLINE key count",
       set_animations(
           R"([{"samplers":[{"input":3,"output":5,"interpolation":"CUBICSPLINE"}],"channels":[{"sampler":0,"target":{"node":0,"path":"rotation"}}]}])"),
       "sampler 0 has 2 key times but 2 output elements (6 expected)"},
      {"animated weights without morph targets",
       set_animations(
           R"([{"samplers":[{"input":3,"output":3}],"channels":[{"sampler":0,"target":{"node":0,"path":"weights"}}]}])"),
       "animates weights of a node without morph targets"},
      {"animation key times not increasing",
       [](GltfFile& g) {
         const int times = g.data<float>({0.0f, 0.5f, 0.5f}, kFloat, "SCALAR");
         const int values = g.data<float>(std::vector<float>(9, 1.0f), kFloat, "VEC3");
         g.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", values}}}},
                                 {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}};
       },
       "animation 0 sampler 0 key times are not strictly increasing (key 2: 0.500000 after 0.500000)"},
      {"skin joint out of range", [](GltfFile& g) { g.doc["skins"] = nlohmann::json::parse(R"([{"joints":[0,5]}])"); },
       "skin 0 joints refers to node 5"},
      {"node skin out of range", [](GltfFile& g) { g.doc["nodes"][0]["skin"] = 2; }, "node 0 skin refers to skin 2"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    GltfFile g = unit_triangle();
    g.add("nodes", {{"mesh", 0}});
    g.scene({0});
    c.edit(g);
    std::string path = g.write(dir_, "bad");
    if (std::string(c.name) ==
        "matrix value beyond double range") {  // nlohmann cannot write an infinity; patch the text
      std::ifstream in(path);
      std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      const size_t at = text.find("null");
      ASSERT_NE(at, std::string::npos);
      std::ofstream(path) << text.replace(at, 4, "1e999");
    }
    const std::string error = load_error(path);
    EXPECT_TRUE(contains(error, c.message)) << "error: " << error << "\nexpected: " << c.message;
    EXPECT_TRUE(contains(error, path)) << "the message names the file: " << error;
  }
}

// A scene with nothing to draw loads with a warning: a sequence must not stop on it (its frames are
// transparent).
TEST_F(SceneLoaderTest, SceneWithoutTrianglesLoadsWithWarning) {
  for (int lines = 0; lines < 2; ++lines) {
    GltfFile g = unit_triangle();
    g.add("nodes", {{"mesh", 0}});
    if (lines) g.doc["meshes"][0]["primitives"][0]["mode"] = 1, g.scene({0});
    else g.scene({});
    const Scene s = load_scene(g.write(dir_, "empty"));
    EXPECT_TRUE(s.triangles.empty());
    bool warned = false;
    for (const std::string& w : s.warnings) warned |= w.find("no triangles to render") != std::string::npos;
    EXPECT_TRUE(warned) << lines;
    glm::dvec3 lo, hi;
    EXPECT_FALSE(scene_bounds(s, lo, hi));
  }
}

// A well-formed animation passes every check and drives its node: STEP scale keys 1, 2, 3 at t = 0, 0.5, 1.
TEST_F(SceneLoaderTest, ValidAnimationLoads) {
  GltfFile g = unit_triangle();
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const int times = g.data<float>({0.0f, 0.5f, 1.0f}, kFloat, "SCALAR");
  const int values = g.data<float>({1, 1, 1, 2, 2, 2, 3, 3, 3}, kFloat, "VEC3");
  g.doc["animations"] = {{{"name", "grow"},
                          {"samplers", {{{"input", times}, {"output", values}, {"interpolation", "STEP"}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "scale"}}}}}}}};
  const Scene s = load_scene(g.write(dir_, "animated"));
  EXPECT_EQ(s.triangles.size(), 1u);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_EQ(s.animations[0].name, "grow");
  EXPECT_EQ(s.animations[0].start, 0.0);
  EXPECT_EQ(s.animations[0].end, 1.0);
  PoseRequest r;
  r.animation = 0;
  for (const auto& [t, scale] : std::vector<std::pair<double, float>>{{0.3, 1.0f}, {0.6, 2.0f}, {7.0, 3.0f}}) {
    r.time = t;
    Scene p;
    EXPECT_TRUE(pose_scene(s, r, p));
    for (size_t v = 0; v < s.positions.size(); ++v) EXPECT_EQ(p.positions[v], s.positions[v] * scale) << t;
  }
}

// Broken files and containers that never reach the glTF structure.
TEST_F(SceneLoaderTest, BrokenFilesThrowClearErrors) {
  const fs::path d = dir_;
  auto text_file = [&](const std::string& name, const std::string& text) {
    std::ofstream(d / name) << text;
    return (d / name).string();
  };
  EXPECT_TRUE(contains(load_error((d / "absent.gltf").string()), "file not found"));
  EXPECT_TRUE(contains(load_error(d.string()), "is a directory"));
  EXPECT_TRUE(contains(load_error(text_file("empty.gltf", "")), "file is empty"));
  EXPECT_TRUE(contains(load_error(text_file("bad.gltf", "{ \"asset\": { \"version\": \"2.0\" }, ")), "invalid JSON"));
  EXPECT_TRUE(contains(load_error(text_file("array.gltf", "[1, 2]")), "top level is not an object"));
  EXPECT_TRUE(contains(
      load_error(text_file("deep.gltf", "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + std::string(100000, '[') +
                                            std::string(100000, ']') + "}")),
      "nested more than"));

  // External buffer problems name the file.
  GltfFile g = unit_triangle();
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const std::string path = g.write(d, "ext");
  fs::rename(d / "ext.bin", d / "elsewhere.bin");
  std::string e = load_error(path);
  EXPECT_TRUE(contains(e, "file 'ext.bin' not found")) << e;
  fs::rename(d / "elsewhere.bin", d / "ext.bin");
  fs::resize_file(d / "ext.bin", 10);
  e = load_error(path);
  EXPECT_TRUE(contains(e, "file 'ext.bin' has 10 bytes but byteLength is")) << e;
  json doc = g.finished("data:foo/bar;base64,AAAA");
  e = load_error(text_file("datauri.gltf", doc.dump()));
  EXPECT_TRUE(contains(e, "unsupported data URI")) << e;

  // GLB container: truncated at every length, wrong version, BIN chunk past the end.
  const std::vector<uint8_t> glb = g.glb();
  for (size_t cut : {size_t(0), size_t(3), size_t(11), size_t(19), size_t(40), glb.size() / 2, glb.size() - 1}) {
    std::vector<uint8_t> part(glb.begin(), glb.begin() + long(cut));
    if (cut < 4) part = {'g', 'l', 'T', 'F'};
    write_bytes(d / "cut.glb", part);
    e = load_error((d / "cut.glb").string());
    EXPECT_TRUE(contains(e, "truncated GLB")) << "cut at " << cut << ": " << e;
  }
  std::vector<uint8_t> v1 = glb;
  v1[4] = 1;
  write_bytes(d / "v1.glb", v1);
  EXPECT_TRUE(contains(load_error((d / "v1.glb").string()), "GLB container version 1"));
  std::vector<uint8_t> long_bin = glb;
  const size_t json_len = size_t(glb[12]) | size_t(glb[13]) << 8;
  long_bin[20 + json_len] += 8;  // BIN chunk length 8 bytes too long
  write_bytes(d / "longbin.glb", long_bin);
  e = load_error((d / "longbin.glb").string());
  EXPECT_TRUE(contains(e, "truncated GLB: the BIN chunk")) << e;
}

// A GLB image whose bufferView runs past the buffer is refused before its bytes are read.
TEST_F(SceneLoaderTest, GlbImageBufferViewOutsideBufferIsAnError) {
  GltfFile g = unit_triangle();
  const int png_view = g.view(make_png(1, 1, 6, 8, {1, 2, 3, 4}));
  g.doc["bufferViews"][png_view]["byteLength"] = 100000;
  g.add("images", {{"bufferView", png_view}, {"mimeType", "image/png"}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  write_bytes(dir_ / "img.glb", g.glb());
  const std::string e = load_error((dir_ / "img.glb").string());
  EXPECT_TRUE(contains(e, "overruns buffer 0")) << e;
}

// ---- the shared sample-model corpus -------------------------------------------------------------------

std::string corpus() {
  const fs::path p = fs::path(PMR_SOURCE_DIR) / ".." / "shared" / "gltf";
  return fs::is_directory(p) ? p.lexically_normal().string() : std::string();
}

#define REQUIRE_CORPUS()            \
  const std::string dir = corpus(); \
  if (dir.empty()) GTEST_SKIP() << PMR_SOURCE_DIR "/../shared/gltf not found"

// Triangle counts from the corpus's own README table (one per model, the same for all its variants):
// rows "| Model | variants | size | 97,240 | ...". Read from the file so that models added to the corpus
// are checked without editing this test.
// The README's tables: every table whose header has a "triangles" column gives its models' counts.
std::map<std::string, size_t> corpus_triangles(const std::string& dir) {
  std::map<std::string, size_t> counts;
  std::ifstream in(dir + "/README.md");
  std::string line;
  size_t column = 0;  // the current table's triangle column (0: none)
  auto trim = [](std::string t) {
    t.erase(0, t.find_first_not_of(' '));
    t.erase(t.find_last_not_of(' ') + 1);
    return t;
  };
  while (std::getline(in, line)) {
    if (line.rfind("| ", 0) != 0) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line.substr(1));
    std::string cell;
    while (std::getline(ss, cell, '|')) cells.push_back(trim(cell));
    if (!cells.empty() && cells[0] == "model") {
      const auto at = std::find(cells.begin(), cells.end(), "triangles");
      column = at == cells.end() ? 0 : size_t(at - cells.begin());
      continue;
    }
    if (column == 0 || cells.size() <= column) continue;
    std::string n = cells[column];
    n.erase(std::remove(n.begin(), n.end(), ','), n.end());
    if (n.empty() || n.find_first_not_of("0123456789") != std::string::npos) continue;
    counts[trim(cells[0])] = std::stoul(n);
  }
  return counts;
}

TEST(SceneLoaderCorpus, EveryModelLoadsWithTheReadmeTriangleCount) {
  REQUIRE_CORPUS();
  const std::map<std::string, size_t> kCorpusTriangles = corpus_triangles(dir);
  ASSERT_GE(kCorpusTriangles.size(), 22u) << "the corpus README's table could not be read";
  size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    ++files;
    const std::string path = entry.path().string();
    const std::string model = fs::relative(entry.path(), dir).begin()->string();
    SCOPED_TRACE(path);
    if (contains(path, "glTF-Draco")) {
      const std::string e = load_error(path);
      EXPECT_TRUE(contains(
          e, "requires KHR_draco_mesh_compression (Draco-compressed meshes), which this renderer does not support"))
          << e;
      continue;
    }
    ASSERT_TRUE(kCorpusTriangles.count(model)) << "model not in the README table: " << model;
    Scene s;
    try {
      s = load_scene(path);
    } catch (const Error& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    EXPECT_EQ(s.triangles.size(), kCorpusTriangles.at(model));
    EXPECT_EQ(s.positions.size(), s.attributes.size());
    for (const PmrTriangle& t : s.triangles) {
      ASSERT_LT(t.material, s.materials.size());
      for (uint32_t v : t.v) ASSERT_LT(v, s.positions.size());
      const float n2 = t.face_normal[0] * t.face_normal[0] + t.face_normal[1] * t.face_normal[1] +
                       t.face_normal[2] * t.face_normal[2];
      ASSERT_NEAR(n2, 1.0f, 1e-5f);
    }
    for (const SceneMaterialInputs& in : s.material_inputs)
      for (const SceneTextureSlot& slot : in.slots) ASSERT_LT(slot.texture, int(s.textures.size()));
    for (const SceneTexture& t : s.textures) ASSERT_EQ(t.rgba.size(), size_t(t.width) * size_t(t.height) * 4);
  }
  EXPECT_GE(files, kCorpusTriangles.size()) << "every model in the README has at least one file";
}

TEST(SceneLoaderCorpus, BoxTexturedHasIts256x256TextureInEveryVariant) {
  REQUIRE_CORPUS();
  for (const char* variant :
       {"glTF/BoxTextured.gltf", "glTF-Binary/BoxTextured.glb", "glTF-Embedded/BoxTextured.gltf"}) {
    SCOPED_TRACE(variant);
    const Scene s = load_scene(dir + "/BoxTextured/" + variant);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.textures[0].width, 256);
    EXPECT_EQ(s.textures[0].height, 256);
    EXPECT_EQ(s.material_inputs[s.triangles[0].material].slots[kSlotBaseColor].texture, 0);
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  }
}

TEST(SceneLoaderCorpus, TextureSettingsTestHasClampAndMirrorWrapModes) {
  REQUIRE_CORPUS();
  const Scene s = load_scene(dir + "/TextureSettingsTest/glTF/TextureSettingsTest.gltf");
  std::set<int> modes;
  for (const SceneTexture& t : s.textures) modes.insert(t.wrap_s), modes.insert(t.wrap_t);
  EXPECT_TRUE(modes.count(PMR_WRAP_CLAMP));
  EXPECT_TRUE(modes.count(PMR_WRAP_MIRROR));
  EXPECT_TRUE(modes.count(PMR_WRAP_REPEAT));
  bool double_sided = false;
  for (const PmrMaterial& m : s.materials) double_sided |= m.double_sided != 0;
  EXPECT_TRUE(double_sided);
}

// KHR_mesh_quantization: u16 positions scaled by the node, i8 normals, u16 UVs dequantized by
// KHR_texture_transform. World bounds match the float Duck within one quantization step (the node
// scale, 1.01e-4); UV bounds within one step of the transform's scale (2.35e-4).
TEST(SceneLoaderCorpus, QuantizedDuckMatchesTheFloatDuck) {
  REQUIRE_CORPUS();
  const Scene plain = load_scene(dir + "/Duck/glTF/Duck.gltf");
  const Scene quant = load_scene(dir + "/Duck/glTF-Quantized/Duck.gltf");
  ASSERT_EQ(plain.triangles.size(), quant.triangles.size());
  glm::dvec3 lo0, hi0, lo1, hi1;
  scene_bounds(plain, lo0, hi0);
  scene_bounds(quant, lo1, hi1);
  const double step = 1.01006161e-4;
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(lo1[c], lo0[c], step) << "axis " << c;
    EXPECT_NEAR(hi1[c], hi0[c], step) << "axis " << c;
  }
  auto uv_bounds = [](const Scene& s) {  // the base colour texture's, after its transform
    const SceneTextureSlot& slot = s.material_inputs.at(s.triangles[0].material).slots[kSlotBaseColor];
    glm::dvec4 b(1e9, 1e9, -1e9, -1e9);
    for (const glm::vec2& stored : s.texcoords.at(size_t(slot.texcoord))) {
      const glm::dvec2 uv = ref::transformed_uv(slot, glm::dvec2(stored));
      b.x = std::min(b.x, uv.x), b.y = std::min(b.y, uv.y);
      b.z = std::max(b.z, uv.x), b.w = std::max(b.w, uv.y);
    }
    return b;
  };
  const glm::dvec4 uv0 = uv_bounds(plain), uv1 = uv_bounds(quant);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(uv1[c], uv0[c], 2.35e-4) << "uv bound " << c;
  // Normals are unit length after the i8 dequantization and the node transform.
  for (const PmrTriangle& t : quant.triangles) {
    ASSERT_EQ(t.has_normals, 1u);
    ASSERT_NEAR(glm::length(vec3(quant.attributes[t.v[0]].normal)), 1.0f, 1e-5f);
  }
  ASSERT_EQ(quant.cameras.size(), 1u);
  EXPECT_TRUE(quant.cameras[0].placed);
}

// The sparse accessor lifts 3 of the 14 vertices to y = 4 (the accessor's max); unapplied, y stays <= 2.
TEST(SceneLoaderCorpus, SimpleSparseAccessorIsApplied) {
  REQUIRE_CORPUS();
  const Scene s = load_scene(dir + "/SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf");
  glm::dvec3 lo, hi;
  scene_bounds(s, lo, hi);
  EXPECT_EQ(hi.y, 4.0);
  EXPECT_EQ(hi.x, 6.0);
  EXPECT_EQ(lo.y, 0.0);
}

TEST(SceneLoaderCorpus, CamerasAndInstancing) {
  REQUIRE_CORPUS();
  const Scene cams = load_scene(dir + "/Cameras/glTF/Cameras.gltf");
  ASSERT_EQ(cams.cameras.size(), 2u);
  EXPECT_TRUE(cams.cameras[0].placed && cams.cameras[0].perspective);
  EXPECT_DOUBLE_EQ(cams.cameras[0].yfov, 0.7);
  EXPECT_DOUBLE_EQ(cams.cameras[0].zfar, 100.0);
  EXPECT_EQ(cams.cameras[0].world_from_camera[3], glm::dvec4(0.5, 0.5, 3.0, 1.0));
  EXPECT_TRUE(cams.cameras[1].placed && !cams.cameras[1].perspective);
  // SimpleMeshes: one mesh, two nodes; the second copy is translated by (1, 0, 0).
  const Scene s = load_scene(dir + "/SimpleMeshes/glTF/SimpleMeshes.gltf");
  ASSERT_EQ(s.triangles.size(), 2u);
  for (int k = 0; k < 3; ++k) EXPECT_VEC3_NEAR(corner(s, 1, k), corner(s, 0, k) + glm::vec3(1, 0, 0), 1e-6);
}

}  // namespace
}  // namespace pmr
