// --shading pbr against the double-precision reference of the model (tests/reference/pbr_reference.cpp):
// every shaded voxel of small renders, the highlight's motion across the views (specular parallax), the
// exposure, and the rendering paths agreeing with each other.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <unistd.h>

#include "environment_maps.h"
#include "gltf_builder.h"
#include "pbr_support.h"
#include "reference/material_reference.h"
#include "reference/pbr_reference.h"
#include "reference/shade_reference.h"
#include "sequence/frame_renderer.h"
#include "shading/environment.h"
#include "shading/lights.h"
#include "test_util.h"

namespace pmr {
namespace {

test::Rendered render_pbr(const Scene& scene, const Rig& rig, double exposure_ev = 0.0, Method method = Method::Pmr,
                          Shading shading = Shading::Pbr) {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.method = method;
  pc.shading = shading;
  pc.exposure_ev = exposure_ev;
  return test::render_with(scene, rig, pc);
}

using test::BoundCheck;
using test::default_light;
using test::surface_at;
using test::uniform_environment;

using test::VoxelReference;

// Quads with curved normals and vertex colours, one material each: metals and dielectrics over
// roughness 0.2 .. 1, an emissive one, an unlit one, a double-sided back face.
Scene material_quads() {
  Scene s = test::empty_scene(true);
  const float metal[6] = {1.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.5f}, rough[6] = {0.25f, 0.2f, 0.6f, 1.0f, 0.5f, 0.5f};
  for (int q = 0; q < 6; ++q) {
    PmrMaterial m = s.materials[0];
    m.metallic = metal[q], m.roughness = rough[q];
    m.base_color[0] = 0.9f - 0.12f * q, m.base_color[1] = 0.5f + 0.08f * q, m.base_color[2] = 0.3f;
    if (q == 4) m.emissive[0] = 0.6f, m.emissive[1] = 0.3f, m.emissive[2] = 1.5f;  // with an emissive strength
    if (q == 5) m.unlit = 1;
    s.materials.push_back(m);
    const float x0 = -1.3f + 0.44f * q, x1 = x0 + 0.4f, z = 0.3f * (q % 2) - 0.15f;
    test::add_triangle(s, {x0, -0.9f, z + 0.3f}, {x1, -0.8f, z - 0.3f}, {x1, 0.9f, z}, uint32_t(q + 1));
    test::add_triangle(s, {x0, -0.9f, z + 0.3f}, {x1, 0.9f, z}, {x0, 1.0f, z + 0.2f}, uint32_t(q + 1));
  }
  for (size_t k = 0; k < s.attributes.size(); ++k) {  // curved normals, vertex colours
    PmrVertexAttr& a = s.attributes[k];
    const glm::vec3 n = glm::normalize(glm::vec3(0.5f * float(k % 3) - 0.5f, 0.4f * float(k % 2) - 0.2f, 1.0f));
    a.normal[0] = n.x, a.normal[1] = n.y, a.normal[2] = n.z;
    a.color[0] = 1.0f - 0.1f * float(k % 4), a.color[1] = 0.8f + 0.05f * float(k % 3);
  }
  // a back-facing double-sided triangle behind, without normals
  test::add_triangle(s, {-1.0f, -1.0f, -0.9f}, {-0.2f, 0.6f, -0.9f}, {0.8f, -0.9f, -0.8f}, 2);
  s.triangles.back().has_normals = 0;
  return s;
}

// The bound of the model's tests: 1% relative plus 1e-3 absolute per channel (roughness >= 0.2), on
// top of the half-float output (2^-11 relative).
TEST(Pbr, EveryShadedVoxelMatchesTheReference) {
  const Rig rig = test::small_rig(7, 72, 40);
  const Scene s = material_quads();
  const test::Rendered out = render_pbr(s, rig);
  const VoxelReference reference(s, rig, out);
  size_t compared = 0, back = 0;
  std::map<uint32_t, size_t> per_material;
  BoundCheck check;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    ASSERT_NE(m, nullptr) << "no MTA for key " << out.key[v];
    back += (m->flags & PMR_MTA_BACK) != 0;
    const glm::dvec3 want = reference.colour(v, *m);
    check.voxel(out, v, want);
    ++compared;
    ++per_material[s.triangles[m->tri].material];
  }
  EXPECT_EQ(check.bad, 0u);
  EXPECT_GT(compared, size_t(3000));
  for (uint32_t material = 1; material <= 6; ++material)  // every quad, the emissive and unlit ones too
    EXPECT_GT(per_material[material], size_t(100)) << "material " << material;
  EXPECT_GT(back, 0u) << "the scene should contain a back face";
  std::printf("[ pbr      ] %zu voxels, largest error %.3f of the bound\n", compared, check.worst);
}

// Two quads whose materials use every map: metallic-roughness, normal (scale 0.8) and occlusion
// (strength 0.7) on the left, sampled on TEXCOORD_1 through a texture transform and TEXCOORD_0; an
// emissive map and a mirrored normal map (tangent w = -1, tangents not orthogonal to the normals) on the
// right. Procedural 16x16 textures, curved normals.
Scene mapped_quads() {
  Scene s = test::empty_scene(false);
  s.material_inputs.resize(1);
  auto texture = [&](const std::function<glm::dvec4(int, int)>& texel_of) { return test::add_texture16(s, texel_of); };
  const int mr = texture([](int x, int y) { return glm::dvec4(0.0, 0.3 + 0.045 * x, y / 15.0, 1.0); });
  const int normal = texture([](int x, int y) {
    return glm::dvec4(0.5 + 0.35 * std::sin(0.8 * x), 0.5 + 0.35 * std::cos(0.6 * y), 0.85, 1.0);
  });
  const int occlusion = texture([](int x, int y) { return glm::dvec4(0.25 + 0.05 * ((x + y) % 16), 0.0, 0.0, 1.0); });
  const int emissive = texture([](int x, int y) { return glm::dvec4(x / 15.0, 0.5, 1.0 - y / 15.0, 1.0); });
  for (int q = 0; q < 2; ++q) {
    PmrMaterial m = s.materials[0];
    m.base_color[0] = 0.8f, m.base_color[1] = 0.6f - 0.2f * q, m.base_color[2] = 0.4f + 0.3f * q;
    m.metallic = 0.9f, m.roughness = 0.8f;
    s.materials.push_back(m);
    SceneMaterialInputs in;
    in.metallic = m.metallic, in.roughness = m.roughness;
    in.slots[kSlotBaseColor].srgb = in.slots[kSlotEmissive].srgb = true;
    SceneTextureSlot& n = in.slots[kSlotNormal];
    n.texture = normal, n.texcoord = 1 - q;
    in.normal_scale = 0.8f;
    if (q == 0) {
      SceneTextureSlot& a = in.slots[kSlotMetallicRoughness];
      a.texture = mr, a.texcoord = 1, a.transform = true;
      a.offset[0] = 0.1f, a.offset[1] = -0.2f, a.rotation = 0.4f, a.scale[0] = 1.5f, a.scale[1] = 0.7f;
      in.slots[kSlotOcclusion].texture = occlusion, in.slots[kSlotOcclusion].texcoord = 0;
      in.occlusion_strength = 0.7f;
    } else {
      in.slots[kSlotEmissive].texture = emissive, in.slots[kSlotEmissive].texcoord = 1;
      in.emissive[0] = in.emissive[1] = in.emissive[2] = 0.5f;
      in.emissive_strength = 2.0f;
      in.metallic = 0.0f, in.roughness = 0.5f;
    }
    s.material_inputs.push_back(in);
    const float x0 = -1.2f + 1.2f * q, x1 = x0 + 1.1f;
    test::add_triangle(s, {x0, -0.9f, 0.2f}, {x1, -0.8f, -0.2f}, {x1, 0.9f, 0.0f}, uint32_t(q + 1));
    test::add_triangle(s, {x0, -0.9f, 0.2f}, {x1, 0.9f, 0.0f}, {x0, 1.0f, 0.1f}, uint32_t(q + 1));
  }
  s.texcoords.assign(2, std::vector<glm::vec2>(s.positions.size()));
  s.tangents.resize(s.positions.size());
  for (size_t k = 0; k < s.positions.size(); ++k) {
    const glm::vec3 p = s.positions[k];
    s.texcoords[0][k] = glm::vec2(0.5f * p.x + 0.6f, 0.5f - 0.5f * p.y);
    s.texcoords[1][k] = glm::vec2(0.9f * p.y + 0.3f * p.x, 0.4f * p.x - 0.2f);
    const bool right = s.triangles[k / 3].material == 2;
    s.tangents[k] = right ? glm::vec4(0.8f, 0.5f, 0.3f, -1.0f) : glm::vec4(1.0f, 0.1f * float(k % 3), 0.0f, 1.0f);
    PmrVertexAttr& a = s.attributes[k];
    const glm::vec3 nk = glm::normalize(glm::vec3(0.4f * float(k % 3) - 0.4f, 0.3f * float(k % 2) - 0.15f, 1.0f));
    a.normal[0] = nk.x, a.normal[1] = nk.y, a.normal[2] = nk.z;
  }
  return s;
}

// Every map against the reference; the reference itself must see the maps (so a kernel that ignored
// them would fail).
TEST(Pbr, MaterialMapsMatchTheReference) {
  const Rig rig = test::small_rig(5, 72, 40);
  const Scene s = mapped_quads();
  Scene plain = s;
  plain.material_inputs.clear();
  const test::Rendered out = render_pbr(s, rig);
  const VoxelReference reference(s, rig, out), without_maps(plain, rig, out);
  size_t compared = 0, changed = 0;
  std::map<uint32_t, size_t> per_material;
  BoundCheck check;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    ASSERT_NE(m, nullptr);
    const glm::dvec3 want = reference.colour(v, *m), plain_colour = without_maps.colour(v, *m);
    changed += glm::length(want - plain_colour) > 0.05 * glm::length(plain_colour);
    check.voxel(out, v, want);
    ++compared;
    ++per_material[s.triangles[m->tri].material];
  }
  EXPECT_EQ(check.bad, 0u);
  EXPECT_GT(per_material[1], size_t(1000));
  EXPECT_GT(per_material[2], size_t(1000));
  EXPECT_GT(changed, compared * 3 / 4) << "the maps should change most voxels";
  std::printf("[ pbr maps ] %zu voxels, %zu changed by the maps, largest error %.3f of the bound\n", compared, changed,
              check.worst);
}

// An opaque quad and an alphaMode MASK quad (over a background) whose base colour texture is sampled on
// TEXCOORD_1 through a KHR_texture_transform (offset, rotation, scale); TEXCOORD_0 holds other values.
Scene transformed_base_colour() {
  Scene s = test::empty_scene(false);
  SceneTexture t;  // RGB gradients, alpha in 2x2-texel blocks of 0 and 1
  t.width = t.height = 8;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c : {20 + 33 * x, 20 + 33 * y, 40 + 25 * ((3 * x + 5 * y) % 8), (x / 2 + y / 2) % 2 ? 0 : 255})
        t.rgba.push_back(uint8_t(c));
  s.textures.push_back(t);
  for (uint32_t k = 1; k <= 2; ++k) {
    PmrMaterial m = s.materials[0];
    m.base_color[0] = 0.9f, m.base_color[1] = 0.8f, m.base_color[2] = 0.7f;
    m.metallic = 0.0f, m.roughness = 0.6f;
    if (k == 2) m.alpha_mode = PMR_ALPHA_MASK, m.alpha_cutoff = 0.5f;
    s.materials.push_back(m);
    SceneTextureSlot& slot = test::base_colour_texture(s, k, 0, 1);
    slot.transform = true;
    slot.offset[0] = 0.2f, slot.offset[1] = -0.1f, slot.rotation = 0.5f, slot.scale[0] = 2.0f, slot.scale[1] = 1.5f;
  }
  auto quad = [&](float x0, float x1, float z, uint32_t material) {
    test::add_triangle(s, {x0, -0.9f, z}, {x1, -0.8f, z - 0.1f}, {x1, 0.9f, z}, material);
    test::add_triangle(s, {x0, -0.9f, z}, {x1, 0.9f, z}, {x0, 1.0f, z + 0.1f}, material);
  };
  quad(-1.2f, -0.05f, 0.1f, 1);  // opaque
  quad(0.05f, 1.2f, -0.4f, 0);   // untextured, seen through the mask's holes
  quad(0.05f, 1.2f, 0.3f, 2);    // masked
  for (size_t v = 0; v < s.positions.size(); ++v) {
    const glm::vec3 p = s.positions[v];
    test::texcoord(s, 0, v) = glm::vec2(0.3f * p.y + 0.1f, 0.7f * p.x);
    test::texcoord(s, 1, v) = glm::vec2(0.5f * p.x + 0.6f, 0.5f - 0.5f * p.y);
  }
  return s;
}

// The transformed base colour in both models, and the mask's alpha test at the transformed alpha,
// against the reference; the reference must tell the transform from none and from one applied twice
// (a set baked on the host and transformed again), so a kernel doing either would fail.
TEST(Pbr, BaseColourTextureTransformMatchesTheReferenceInBothModels) {
  const Rig rig = test::small_rig(5, 72, 40);
  const Scene s = transformed_base_colour();
  Scene ignored = s, twice = s;
  for (uint32_t k : {1u, 2u}) ignored.material_inputs[k].slots[kSlotBaseColor].transform = false;
  for (glm::vec2& uv : twice.texcoords[1])
    uv = glm::vec2(ref::transformed_uv(s.material_inputs[1].slots[kSlotBaseColor], glm::dvec2(uv)));
  auto material = [&](uint32_t key) { return s.triangles[key >> PMR_KEY_SUB_BITS].material; };
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  for (const Shading shading : {Shading::Lambert, Shading::Pbr}) {
    SCOPED_TRACE(shading == Shading::Pbr ? "pbr" : "lambert");
    const test::Rendered out = render_pbr(s, rig, 0.0, Method::Pmr, shading);
    const VoxelReference reference(s, rig, out);
    BoundCheck check;
    size_t textured = 0, distinct = 0, masked = 0, moved_without = 0, moved_twice = 0;
    for (size_t v = 0; v < out.key.size(); ++v) {
      if (out.key[v] == PMR_NO_KEY) continue;
      const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
      const PmrMta* m = reference.mta(v);
      ASSERT_NE(m, nullptr);
      const glm::dvec3 b = ref::source_barycentrics(*m, px, py, view);
      check.voxel(out, v,
                  shading == Shading::Pbr
                      ? reference.colour(v, *m)
                      : glm::dvec3(ref::shade(s, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, rig.light_world())));
      if (material(out.key[v]) == 1) {
        const glm::dvec3 want(ref::base_color(s, m->tri, b));
        ++textured;
        distinct += glm::length(want - glm::dvec3(ref::base_color(ignored, m->tri, b))) > 0.05 &&
                    glm::length(want - glm::dvec3(ref::base_color(twice, m->tri, b))) > 0.05;
        continue;
      }
      for (const auto& [key, mask] : reference.by_key) {  // the masked quad's alpha at this voxel
        if (material(key) != 2 || view < mask.view_lo || view > mask.view_hi) continue;
        const glm::dvec3 bm = ref::source_barycentrics(mask, px, py, view);
        if (bm.x < 0 || bm.y < 0 || bm.z < 0) continue;  // not this half of the quad
        const double alpha = ref::base_color(s, mask.tri, bm).w;
        if (std::abs(alpha - 0.5) < 1e-3) break;  // on the cutoff: float and double may disagree
        ++masked;
        EXPECT_EQ(material(out.key[v]) == 2, alpha >= 0.5) << "voxel (" << px << "," << py << "," << view << ")";
        moved_without += (ref::base_color(ignored, mask.tri, bm).w >= 0.5) != (alpha >= 0.5);
        moved_twice += (ref::base_color(twice, mask.tri, bm).w >= 0.5) != (alpha >= 0.5);
        break;
      }
    }
    EXPECT_EQ(check.bad, 0u);
    EXPECT_GT(textured, size_t(1000));
    EXPECT_GT(masked, size_t(800));
    EXPECT_GT(distinct, textured * 3 / 4) << "the transform should change most base colours";
    EXPECT_GT(moved_without, masked / 4) << "the transform should move the mask's holes";
    EXPECT_GT(moved_twice, masked / 4) << "applied twice, it should move them again";
    std::printf(
        "[ base map ] %zu textured voxels (%zu changed without the transform or with it twice), %zu masked "
        "(the holes move on %zu without it, %zu with it twice), largest error %.3f of the bound\n",
        textured, distinct, masked, moved_without, moved_twice, check.worst);
  }
}

// Real models with maps (../shared/gltf): Avocado (metallic-roughness and normal maps, TANGENT), the same
// file with TANGENT removed (generated tangents), MultiUVTest (an emissive map on TEXCOORD_1). Every
// shaded voxel whose roughness is at least 0.2 matches the reference.
TEST(Pbr, RealModelsWithMapsMatchTheReference) {
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: real-model pbr test skipped";
  namespace fs = std::filesystem;
  // Avocado without TANGENT: its .gltf with the attribute removed, beside copies of its other files.
  const fs::path tmp = fs::temp_directory_path() / ("pmr_pbr_models_" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  const fs::path avocado = fs::path(dir) / "Avocado" / "glTF";
  for (const auto& e : fs::directory_iterator(avocado)) fs::copy_file(e.path(), tmp / e.path().filename());
  {
    std::ifstream in(avocado / "Avocado.gltf");
    nlohmann::json doc = nlohmann::json::parse(in);
    for (auto& mesh : doc["meshes"])
      for (auto& prim : mesh["primitives"]) prim["attributes"].erase("TANGENT");
    std::ofstream(tmp / "Avocado.gltf") << doc.dump();
  }
  const std::vector<std::string> files = {(avocado / "Avocado.gltf").string(), (tmp / "Avocado.gltf").string(),
                                          dir + "/MultiUVTest/glTF/MultiUVTest.gltf"};
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    const Scene s = load_scene(f);
    if (f == files[1]) {
      EXPECT_GT(s.structure.generated_tangent_primitives, 0u) << "the copy should have no TANGENT";
    }
    glm::dvec3 lo, hi;
    ASSERT_TRUE(scene_bounds(s, lo, hi));
    RigConfig rc;
    rc.views = 5, rc.view_w = 96, rc.view_h = 64;
    const Rig rig = make_rig(rc, Display{}, lo, hi);
    const test::Rendered out = render_pbr(s, rig);
    const VoxelReference reference(s, rig, out);
    size_t compared = 0;
    BoundCheck check;
    for (size_t v = 0; v < out.key.size(); ++v) {
      if (out.key[v] == PMR_NO_KEY) continue;
      const PmrMta* m = reference.mta(v);
      ASSERT_NE(m, nullptr);
      const int W = rig.view_w, H = rig.view_h;
      const int view = int(v / size_t(W * H));
      const glm::dvec3 b = ref::source_barycentrics(*m, int(v % size_t(W)), int((v / size_t(W)) % size_t(H)), view);
      if (surface_at(s, rig, m->tri, b, false, view).roughness < 0.2) continue;
      const glm::dvec3 want = reference.colour(v, *m);
      check.voxel(out, v, want);
      ++compared;
    }
    EXPECT_EQ(check.bad, 0u);
    EXPECT_GT(compared, size_t(2000));
    std::printf("[ pbr      ] %s: %zu voxels, largest error %.3f of the bound\n", fs::path(f).filename().c_str(),
                compared, check.worst);
  }
  fs::remove_all(tmp);
}

// A smooth sphere (lat-long grid, smooth normals) of one material.
Scene sphere(float radius, const glm::vec3& c, float metallic, float roughness) {
  Scene s = test::empty_scene(false);
  s.materials[0].metallic = metallic, s.materials[0].roughness = roughness;
  const int stacks = 48, slices = 96;
  auto at = [&](int i, int j) {
    const double th = glm::pi<double>() * i / stacks, ph = 2.0 * glm::pi<double>() * j / slices;
    return glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
  };
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const glm::vec3 a = at(i, j), b = at(i + 1, j), d = at(i + 1, j + 1), e = at(i, j + 1);
      for (const auto& tri : {std::array<glm::vec3, 3>{a, b, d}, std::array<glm::vec3, 3>{a, d, e}}) {
        if (glm::length(glm::cross(tri[1] - tri[0], tri[2] - tri[0])) < 1e-9f) continue;
        test::add_triangle(s, c + radius * tri[0], c + radius * tri[1], c + radius * tri[2]);
        for (int k = 0; k < 3; ++k) {
          PmrVertexAttr& at3 = s.attributes[s.attributes.size() - 3 + size_t(k)];
          at3.normal[0] = tri[size_t(k)].x, at3.normal[1] = tri[size_t(k)].y, at3.normal[2] = tri[size_t(k)].z;
        }
      }
    }
  return s;
}

// The highlight of a glossy metal sphere under the default light moves across the views as the
// reference predicts (the view vector is each view's own): in views 0, N/2 and N-1 the brightest pixel
// is within 1 px of the reference's, and it moves between views 0 and N-1 by the predicted amount.
TEST(Pbr, SpecularHighlightMovesWithTheViews) {
  const int N = 9;
  const Rig rig = test::highlight_rig(N);
  const Scene s = sphere(0.8f, glm::vec3(0.0f), 1.0f, 0.2f);
  const test::Rendered out = render_pbr(s, rig);
  const VoxelReference reference(s, rig, out);
  double moved_got = 0.0, moved_want = 0.0;
  glm::dvec2 first_got(0.0), first_want(0.0);
  for (int view : {0, N / 2, N - 1}) {
    const glm::dvec2 at_got = test::brightest_pixel(out, nullptr, rig, view),
                     at_want = test::brightest_pixel(out, &reference, rig, view);
    EXPECT_LE(glm::length(at_got - at_want), 1.0 + 1e-9)
        << "view " << view << ": highlight at (" << at_got.x << "," << at_got.y << "), reference (" << at_want.x << ","
        << at_want.y << ")";
    if (view == 0) first_got = at_got, first_want = at_want;
    if (view == N - 1) moved_got = at_got.x - first_got.x, moved_want = at_want.x - first_want.x;
  }
  EXPECT_GT(std::abs(moved_want), 3.0) << "the rig should move the highlight by several pixels";
  EXPECT_NEAR(moved_got, moved_want, 1.0);
}

// Exposure scales either model by 2^EV (half-float outputs: 2^-10 relative).
// KHR_materials_ior: a dielectric's F0 is ((ior - 1) / (ior + 1))^2 (0 at ior 1, 0.17 at 2.4, 1 at the
// extension's ior 0), in the lights' and the environment's terms. Four grey dielectric quads, every
// voxel within the bound of the reference (which computes F0 from the material's ior itself); the
// reference at glTF's default 1.5 is outside it on 20% to all of each quad's voxels, so a kernel ignoring ior fails.
TEST(Pbr, IorSetsTheDielectricReflectance) {
  const Rig rig = test::small_rig(5, 64, 36);
  Scene s = test::empty_scene(true);
  const float iors[4] = {1.0f, 1.33f, 2.4f, 0.0f};
  for (int q = 0; q < 4; ++q) {
    PmrMaterial m = s.materials[0];
    m.metallic = 0.0f, m.roughness = 0.35f;
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.5f;
    m.f0_dielectric = dielectric_f0(iors[q]);  // as the loader sets it (SceneMaterials tests read ior)
    s.materials.push_back(m);
    const float x0 = -1.2f + 0.62f * float(q), x1 = x0 + 0.56f;
    test::add_triangle(s, {x0, -0.9f, 0.2f}, {x1, -0.9f, -0.2f}, {x1, 0.9f, 0.0f}, uint32_t(q + 1));
    test::add_triangle(s, {x0, -0.9f, 0.2f}, {x1, 0.9f, 0.0f}, {x0, 0.9f, 0.2f}, uint32_t(q + 1));
  }
  for (size_t k = 0; k < s.attributes.size(); ++k) {  // curved normals
    const glm::vec3 n = glm::normalize(glm::vec3(0.4f * float(k % 3) - 0.4f, 0.3f * float(k % 2) - 0.15f, 1.0f));
    std::copy(&n.x, &n.x + 3, s.attributes[k].normal);
  }
  test::base_colour_texture(s, 1, -1, 0);  // material inputs for every material (no texture)
  for (int q = 0; q < 4; ++q) s.material_inputs[size_t(q + 1)].ior = iors[q];
  const test::Rendered out = render_pbr(s, rig);
  VoxelReference reference(s, rig, out), plain(s, rig, out);
  Scene default_ior = s;
  for (SceneMaterialInputs& in : default_ior.material_inputs) in.ior = 1.5f;
  const VoxelReference at_15(default_ior, rig, out);
  BoundCheck check;
  std::map<uint32_t, size_t> per_material, off_at_15;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    ASSERT_NE(m, nullptr);
    const uint32_t material = s.triangles[m->tri].material;
    check.voxel(out, v, reference.colour(v, *m), "ior " + std::to_string(iors[material - 1]));
    ++per_material[material];
    half g;
    g.setBits(out.volume[v * 4 + 1]);
    const double want15 = at_15.colour(v, *m).y;
    off_at_15[material] += std::abs(double(float(g)) - want15) > 0.01 * want15 + 1e-3;
  }
  EXPECT_EQ(check.bad, 0u);
  for (uint32_t material = 1; material <= 4; ++material) {
    EXPECT_GT(per_material[material], size_t(150)) << "material " << material;
    EXPECT_GT(off_at_15[material], per_material[material] / 8) << "ior " << iors[material - 1] << " looks like 1.5";
  }
  std::printf("[ pbr ior  ] largest error %.3f of the bound\n", check.worst);
}

TEST(Pbr, ExposureScalesBothModels) {
  const Rig rig = test::small_rig(3, 40, 24);
  const Scene s = material_quads();
  for (Shading shading : {Shading::Lambert, Shading::Pbr}) {
    const test::Rendered a = render_pbr(s, rig, 0.0, Method::Pmr, shading),
                         b = render_pbr(s, rig, 1.5, Method::Pmr, shading);
    size_t lit = 0;
    for (size_t i = 0; i < a.volume.size(); ++i) {
      if (i % 4 == 3) continue;
      half x, y;
      x.setBits(a.volume[i]), y.setBits(b.volume[i]);
      const double want = double(float(x)) * std::exp2(1.5);
      ASSERT_NEAR(float(y), want, std::ldexp(std::abs(want), -9) + 1e-6) << to_string(shading) << " value " << i;
      lit += float(x) > 0.0f;
    }
    EXPECT_GT(lit, size_t(1000)) << to_string(shading);
  }
}

// The baselines shade with the same module: multipass fed PMR's positions is bit-identical; duplicate
// matches wherever both drew the same triangle (the fill rule aside).
TEST(Pbr, MethodsShadeAlike) {
  const Rig rig = test::small_rig(5, 48, 32);
  const Scene s = material_quads();
  const test::Rendered pmr = render_pbr(s, rig), dup = render_pbr(s, rig, 0.0, Method::Duplicate);
  size_t same = 0, covered = 0;
  for (size_t v = 0; v < pmr.key.size(); ++v) {
    covered += pmr.key[v] != PMR_NO_KEY;
    if (pmr.key[v] == PMR_NO_KEY || pmr.key[v] != dup.key[v]) continue;
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(pmr.volume[v * 4 + size_t(c)], dup.volume[v * 4 + size_t(c)]) << "voxel " << v;
    ++same;
  }
  EXPECT_GT(same, covered * 9 / 10);
  EXPECT_GT(covered, size_t(1000));
}

// ---- environment images (--environment) ------------------------------------------------------------

using test::image_environment;
using test::sky_environment;

test::Rendered render_environment(const Scene& scene, const Rig& rig, const std::shared_ptr<const Environment>& e,
                                  Method method = Method::Pmr) {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.method = method;
  pc.shading = Shading::Pbr;
  pc.environment = e;
  pc.environment_intensity = e->tables().header.intensity;
  return test::render_with(scene, rig, pc);
}

// Every covered voxel against the reference lit by the environment alone (an image turns the default
// light off): the number compared, and the largest error as a fraction of the bound (1% relative plus
// 1e-3 absolute per channel); the first failures are reported.
struct Agreement {
  size_t compared = 0;
  double worst = 0.0;
};
Agreement compare_with_environment(const Scene& s, const Rig& rig, const test::Rendered& out, const Environment& e,
                                   const std::string& what) {
  VoxelReference reference(s, rig, out);
  reference.lights.clear();
  reference.env = image_environment(e);
  Agreement a;
  BoundCheck check;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    if (!m) {
      ADD_FAILURE() << what << ": no MTA for key " << out.key[v];
      return a;
    }
    const glm::dvec3 want = reference.colour(v, *m);
    check.voxel(out, v, want, what);
    ++a.compared;
  }
  EXPECT_EQ(check.bad, 0u) << what;
  a.worst = check.worst;
  return a;
}

// The kernels' lookups (cl/environment.h: polynomial atan2, log2 and exp2 in float) against the host's
// in double precision, directly: random directions, the axes, the poles and the u seam, every
// roughness from 0 to 1 (for the GGX and the sheen levels), a turned map with a sun. Within 1e-4
// relative plus 1e-6 absolute (float texel coordinates, next to a sun texel 1000 times brighter than
// its neighbours).
TEST(PbrEnvironment, KernelLookupsMatchTheHost) {
  const Environment e = *sky_environment(37.0, 1.7);
  std::mt19937 g(11);
  std::normal_distribution<double> N;
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<glm::dvec3> dirs = {{1, 0, 0},  {-1, 0, 0},   {0, 1, 0},     {0, -1, 0},        {0, 0, 1},
                                  {0, 0, -1}, {1e-3, 0, 1}, {-1e-3, 0, 1}, {0.2, 0.98, 0.01}, test::sun_direction()};
  while (dirs.size() < 4000) dirs.push_back(glm::normalize(glm::dvec3(N(g), N(g), N(g))));
  std::vector<float> in;
  std::vector<double> rs;
  for (size_t i = 0; i < dirs.size(); ++i) {
    const glm::vec3 d(dirs[i]);
    rs.push_back(i % 10 == 0 ? double(i % 11) / 10.0 : U(g));
    in.insert(in.end(), {d.x, d.y, d.z, float(rs.back())});
  }
  const ClRuntime& rt = test::runtime();
  const ClProgram program = rt.build_program({"environment_probe.cl"}, "-cl-std=CL1.2", &test_kernel_sources());
  std::vector<float> out(9 * dirs.size());
  {
    ClKernel k(program, "environment_probe");
    const EnvironmentTables& t = e.tables();
    ClBuffer h = rt.buffer(sizeof t.header, "probe header"), data = rt.upload(t.data, "probe data"),
             a = rt.upload(in, "probe in"), b = rt.buffer(out.size() * 4, "probe out");
    rt.write(h, &t.header, sizeof t.header);
    k.args(h, data, a, b, cl_uint(dirs.size()));
    ASSERT_EQ(dirs.size() % 8, 0u) << "the probe takes 8 directions per work-item (SW lanes)";
    clReleaseEvent(rt.launch(k, dirs.size() / 8, 64));
    rt.read(b, out.data(), out.size() * 4);
  }
  double worst = 0.0;
  for (size_t i = 0; i < dirs.size(); ++i) {
    const glm::dvec3 d = glm::dvec3(glm::vec3(dirs[i]));  // the float direction the kernel saw
    const double r = double(float(rs[i]));
    const glm::dvec3 want[3] = {e.irradiance(d), e.prefiltered(d, r), e.sheen(d, r)};
    for (int k = 0; k < 9; ++k) {
      const double w = want[k / 3][k % 3], err = std::abs(double(out[9 * i + size_t(k)]) - w), tol = 1e-4 * w + 1e-6;
      worst = std::max(worst, err / tol);
      ASSERT_LE(err, tol) << "direction " << i << " (" << d.x << ", " << d.y << ", " << d.z << "), r " << rs[i]
                          << (k < 3   ? ": I"
                              : k < 6 ? ": P"
                                      : ": S")
                          << " channel " << k % 3;
    }
  }
  std::printf("[ env look ] %zu directions, largest error %.3f of the bound\n", dirs.size(), worst);
}

// Metal and dielectric spheres over roughness, and the material quads (vertex colours, curved normals,
// emissive, unlit, a back face), under the sky at two rotations: every shaded voxel within the bound of
// the reference evaluated with the same Environment's lookups.
TEST(PbrEnvironment, SpheresAndQuadsMatchTheReference) {
  const Rig rig = test::small_rig(5, 48, 32);
  double worst = 0.0;
  size_t compared = 0;
  for (double rotation : {0.0, 130.0}) {
    const std::shared_ptr<const Environment> e = sky_environment(rotation, 1.0);
    for (float metallic : {1.0f, 0.0f})
      for (float roughness : {0.2f, 0.3f, 0.47f, 0.75f, 1.0f}) {
        const Scene s = sphere(0.9f, glm::vec3(0.0f), metallic, roughness);
        const std::string what = "metallic " + std::to_string(metallic) + ", roughness " + std::to_string(roughness) +
                                 ", rotation " + std::to_string(rotation);
        const Agreement a = compare_with_environment(s, rig, render_environment(s, rig, e), *e, what);
        EXPECT_GT(a.compared, size_t(800)) << what;
        worst = std::max(worst, a.worst), compared += a.compared;
      }
    const Scene q = material_quads();
    const Agreement a = compare_with_environment(q, rig, render_environment(q, rig, e), *e, "quads");
    EXPECT_GT(a.compared, size_t(1000));
    worst = std::max(worst, a.worst), compared += a.compared;
  }
  std::printf("[ pbr env  ] %zu voxels, largest error %.3f of the bound\n", compared, worst);
}

// Rotation turns the map counter-clockwise seen from above: a sun at +X turned by 90 degrees lights the
// scene as a sun at -Z does (the same image shifted by a quarter of its width), and not as before.
TEST(PbrEnvironment, RotationMovesTheSunAsDocumented) {
  const Rig rig = test::small_rig(3, 48, 32);
  auto sun_at = [](glm::dvec3 sun) {
    return test::make_map(64, 32, [sun](glm::dvec3 d) {
      return glm::dot(d, sun) > std::cos(0.2) ? glm::dvec3(50.0, 40.0, 30.0) : glm::dvec3(0.1, 0.2, 0.3);
    });
  };
  auto turned = std::make_shared<Environment>(Environment::from_image(sun_at({1, 0, 0})));
  const Environment unturned = *turned;
  turned->set_rotation(90.0);
  const auto behind = std::make_shared<const Environment>(Environment::from_image(sun_at({0, 0, -1})));
  const Scene s = sphere(0.9f, glm::vec3(0.0f), 0.0f, 0.6f);
  const test::Rendered a = render_environment(s, rig, turned), b = render_environment(s, rig, behind),
                       c = render_environment(s, rig, std::make_shared<const Environment>(unturned));
  size_t lit = 0, changed = 0;
  for (size_t i = 0; i < a.volume.size(); ++i) {
    if (i % 4 == 3 || a.key[i / 4] == PMR_NO_KEY) continue;
    half x, y, z;
    x.setBits(a.volume[i]), y.setBits(b.volume[i]), z.setBits(c.volume[i]);
    ASSERT_NEAR(float(x), float(y), 2e-3 * std::abs(float(y)) + 1e-4) << "value " << i;
    lit += float(x) > 0.0f;
    changed += std::abs(float(x) - float(z)) > 0.1f * std::max(float(x), float(z));
  }
  EXPECT_GT(lit, size_t(1000));
  EXPECT_GT(changed, lit / 4) << "turning the map by 90 degrees should relight the sphere";
}

// The intensity scales the image and 0 turns it off (and with an image the default light is off, so a
// scene without emission renders black).
TEST(PbrEnvironment, IntensityScalesAndZeroTurnsOff) {
  const Rig rig = test::small_rig(3, 40, 24);
  const Scene s = sphere(0.9f, glm::vec3(0.0f), 0.5f, 0.4f);
  const test::Rendered one = render_environment(s, rig, sky_environment(0.0, 1.0)),
                       more = render_environment(s, rig, sky_environment(0.0, 2.5)),
                       off = render_environment(s, rig, sky_environment(0.0, 0.0));
  size_t lit = 0;
  for (size_t i = 0; i < one.volume.size(); ++i) {
    if (i % 4 == 3 || one.key[i / 4] == PMR_NO_KEY) continue;
    half x, y, z;
    x.setBits(one.volume[i]), y.setBits(more.volume[i]), z.setBits(off.volume[i]);
    ASSERT_NEAR(float(y), 2.5 * float(x), std::ldexp(2.5 * std::abs(float(x)), -9) + 1e-6) << "value " << i;
    ASSERT_EQ(float(z), 0.0f) << "value " << i;
    lit += float(x) > 0.0f;
  }
  EXPECT_GT(lit, size_t(1000));
}

// ---- the built-in studio (the command line's default environment) ----------------------------------

// A white rough dielectric facing the camera reads 0.8 to 1.0 under the studio (DESIGN 4b), lit by the
// studio alone: no default light comes with it.
TEST(PbrEnvironment, TheStudioLightsAWhiteRoughDielectricFacingTheCameraAt08To1) {
  const Rig rig = test::small_rig(5, 40, 24);
  const Scene s = test::white_rough_square();
  const auto studio = std::make_shared<const Environment>(Environment::studio());
  const test::Rendered out = render_environment(s, rig, studio);
  size_t covered = 0;
  double lo = 1e9, hi = -1e9;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    ++covered;
    for (int c = 0; c < 3; ++c) {
      half x;
      x.setBits(out.volume[v * 4 + size_t(c)]);
      lo = std::min(lo, double(float(x))), hi = std::max(hi, double(float(x)));
    }
  }
  std::printf("[ studio   ] white rough dielectric facing the camera: %.3f to %.3f\n", lo, hi);
  EXPECT_GT(covered, size_t(500));
  EXPECT_GE(lo, 0.8);
  EXPECT_LE(hi, 1.0);
}

// Pixels of view `view` brighter than `threshold` in red: 1 where pmr's (or the reference's) colour is.
std::vector<uint8_t> bright_mask(const test::Rendered& out, const Rig& rig, int view, const VoxelReference* ref,
                                 double threshold) {
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h), base = size_t(view) * W * H;
  std::vector<uint8_t> mask(W * H, 0);
  for (size_t p = 0; p < W * H; ++p) {
    const size_t v = base + p;
    if (out.key[v] == PMR_NO_KEY) continue;
    double red = 0.0;
    if (ref) {
      const PmrMta* m = ref->mta(v);
      red = m ? ref->colour(v, *m).x : 0.0;
    } else {
      half x;
      x.setBits(out.volume[v * 4]);
      red = float(x);
    }
    mask[p] = red > threshold;
  }
  return mask;
}

// Pixels of `a` with no pixel of `b` within one pixel (3x3).
size_t farther_than_one_pixel(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int W, int H) {
  size_t far = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (!a[size_t(y * W + x)]) continue;
      bool near = false;
      for (int dy = -1; dy <= 1 && !near; ++dy)
        for (int dx = -1; dx <= 1 && !near; ++dx) {
          const int xx = x + dx, yy = y + dy;
          near = xx >= 0 && yy >= 0 && xx < W && yy < H && b[size_t(yy * W + xx)];
        }
      far += !near;
    }
  return far;
}

// 8-connected regions of a mask.
int regions(std::vector<uint8_t> mask, int W, int H) {
  int count = 0;
  for (int start = 0; start < W * H; ++start) {
    if (!mask[size_t(start)]) continue;
    ++count;
    std::vector<int> stack{start};
    mask[size_t(start)] = 0;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = p % W + dx, y = p / W + dy;
          if (x < 0 || y < 0 || x >= W || y >= H || !mask[size_t(y * W + x)]) continue;
          mask[size_t(y * W + x)] = 0;
          stack.push_back(y * W + x);
        }
    }
  }
  return count;
}

// A polished metal sphere under the studio mirrors its soft boxes (radiance 8 to 20; the walls at most
// 0.3): in views 0 and N-1 every pixel pmr shows a box in lies within 1 px of one where the double-
// precision reference (its own reflection vectors from each view's eye, the same studio lookups) does,
// and the other way round. The boxes are at least four separate reflections, and they move between the
// views.
TEST(PbrEnvironment, APolishedSphereShowsTheStudioBoxesWhereTheReferenceDoes) {
  const int N = 7, W = 96, H = 96;
  const Rig rig = test::small_rig(N, W, H);
  const Scene s = sphere(0.9f, glm::vec3(0.0f), 1.0f, 0.0f);  // roughness clamped to 0.03
  const auto studio = std::make_shared<const Environment>(Environment::studio());
  const test::Rendered out = render_environment(s, rig, studio);
  VoxelReference reference(s, rig, out);
  reference.lights.clear();
  reference.env = image_environment(*studio);
  std::vector<uint8_t> first;
  for (int view : {0, N - 1}) {
    const std::vector<uint8_t> got = bright_mask(out, rig, view, nullptr, 2.0),
                               want = bright_mask(out, rig, view, &reference, 2.0);
    const size_t lit = size_t(std::count(got.begin(), got.end(), 1));
    const int boxes = regions(got, W, H);
    std::printf("[ studio   ] polished sphere, view %d: %zu pixels show a box, %d regions\n", view, lit, boxes);
    EXPECT_GT(lit, size_t(40)) << "view " << view;
    EXPECT_GE(boxes, 4) << "view " << view;
    EXPECT_EQ(farther_than_one_pixel(got, want, W, H), 0u) << "view " << view << ": pmr shows a box elsewhere";
    EXPECT_EQ(farther_than_one_pixel(want, got, W, H), 0u) << "view " << view << ": the reference shows one elsewhere";
    if (view == 0) first = got;
    else EXPECT_NE(first, got) << "the reflections do not move between views 0 and N-1";
  }
}

// Every rendering path shades with the environment alike: multipass fed PMR's positions and the fused
// raster + encode give PMR's values bit for bit; --sampling subpixel (which samples elsewhere) lights
// the same scene to the same overall brightness.
TEST(PbrEnvironment, PathsShadeAlike) {
  const Rig rig = test::small_rig(5, 48, 32);
  const Scene s = material_quads();
  const std::shared_ptr<const Environment> e = sky_environment(30.0, 1.0);
  test::expect_paths_agree(s, rig, test::pbr_config(Method::Pmr, TextureFilter::Bilinear, e));
}

// ---- KHR_lights_punctual -----------------------------------------------------------------------------

using test::make_light;
using test::reference_light;

// Every covered voxel of `out` against the reference (1% + 1e-3 per channel); returns how many were
// compared. `lit`, when given, counts the voxels the reference's lights brighten by more than 0.02
// against the environment alone, and `dark` those they do not brighten at all.
size_t expect_voxels_match(const VoxelReference& reference, size_t* lit = nullptr, size_t* dark = nullptr) {
  const test::Rendered& out = reference.out;
  VoxelReference unlit = reference;  // the same environment, no lights
  unlit.lights.clear();
  size_t compared = 0;
  BoundCheck check;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    if (!m) {
      ADD_FAILURE() << "no MTA for key " << out.key[v];
      return compared;
    }
    const glm::dvec3 want = reference.colour(v, *m), ambient = unlit.colour(v, *m);
    check.voxel(out, v, want);
    const double gain = glm::length(want - ambient);
    if (lit) *lit += gain > 0.02;
    if (dark) *dark += gain == 0.0;
    ++compared;
  }
  EXPECT_EQ(check.bad, 0u);
  std::printf("[ lights   ] %zu voxels, largest error %.3f of the bound\n", compared, check.worst);
  return compared;
}

// A directional, a point and a spot light (both with a range that ends inside the scene, the spot's cone
// edge crossing the quads), alone and together: every shaded voxel against the reference with the same
// lights, and each light lights some voxels and (point, spot) leaves others dark.
// For material_quads(): a coloured directional light, a point light whose range ends inside the scene,
// and a spot light whose cone edge crosses the quads.
std::vector<SceneLight> three_lights() {
  SceneLight sun = make_light(SceneLightType::Directional, glm::dvec3(5.0), glm::dvec3(0.4, -0.3, -1.0), 2.0f);
  sun.name = "sun";
  sun.color[0] = 1.0f, sun.color[1] = 0.6f, sun.color[2] = 0.3f;
  SceneLight bulb = make_light(SceneLightType::Point, glm::dvec3(0.2, 0.3, 1.5), glm::dvec3(0, 0, -1), 3.0f, 2.2f);
  bulb.color[0] = 0.8f, bulb.color[1] = 0.9f;
  SceneLight spot =
      make_light(SceneLightType::Spot, glm::dvec3(0.3, 0.2, 2.0), glm::dvec3(-0.1, 0.0, -1.0), 6.0f, 4.0f);
  spot.inner_cone = 0.2f, spot.outer_cone = 0.35f;
  return {sun, bulb, spot};
}

TEST(PbrLights, EveryShadedVoxelMatchesTheReferenceUnderEachLight) {
  const Rig rig = test::small_rig(7, 72, 40);
  const std::vector<SceneLight> lights = three_lights();
  const SceneLight &sun = lights[0], &bulb = lights[1], &spot = lights[2];
  const struct {
    const char* name;
    std::vector<SceneLight> lights;
    bool leaves_dark;
  } cases[] = {{"directional", {sun}, false},
               {"point", {bulb}, true},
               {"spot", {spot}, true},
               {"all three", {sun, bulb, spot}, false}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    Scene s = material_quads();
    s.lights = c.lights;
    const test::Rendered out = render_pbr(s, rig);
    VoxelReference reference(s, rig, out);
    reference.lights.clear();
    for (const SceneLight& l : c.lights) reference.lights.push_back(reference_light(l));
    size_t lit = 0, dark = 0;
    EXPECT_GT(expect_voxels_match(reference, &lit, &dark), size_t(3000));
    EXPECT_GT(lit, size_t(500)) << "the light should light much of the scene";
    if (c.leaves_dark) {
      EXPECT_GT(dark, size_t(300)) << "outside the range or the cone nothing should be lit";
    }
  }
}

// The fused raster + encode path and --sampling subpixel get the same lights as the fine raster: the
// fused image equals the encoded view volume bit for bit, and with a view raster of 3 W_d x H_d (every
// subpixel's sample a pixel center) subpixel sampling gives view sampling's image (but for depth ties:
// a few pixels in a thousand). The lights change most pixels, so a path without them would differ.
TEST(PbrLights, EveryPathShadesWithTheLights) {
  Scene s = material_quads();
  s.lights = three_lights();
  Display d;
  const Rig rig = test::subpixel_display_rig(d);
  auto render = [&](Sampling sampling, bool fuse) {
    PipelineConfig pc;
    pc.shading = Shading::Pbr;
    pc.sampling = sampling;
    pc.fuse_encode = fuse;
    return test::render_encoded(s, rig, d, pc);
  };
  const test::EncodedRender unfused = render(Sampling::View, false), fused = render(Sampling::View, true),
                            subpixel = render(Sampling::Subpixel, true);
  ASSERT_TRUE(fused.fused);
  ASSERT_FALSE(unfused.fused);
  EXPECT_EQ(fused.image, unfused.image);
  ASSERT_EQ(subpixel.image.size(), unfused.image.size());
  size_t differ = 0, drawn = 0;
  for (size_t i = 0; i < unfused.image.size(); i += 4) {
    differ += !std::equal(&subpixel.image[i], &subpixel.image[i] + 4, &unfused.image[i]);
    drawn += unfused.image[i + 3] != 0;
  }
  EXPECT_LE(differ, unfused.image.size() / 4 / 1000);
  EXPECT_GT(drawn, unfused.image.size() / 4 / 8);
  s.lights.clear();  // the default light instead
  const std::vector<uint16_t> unlit = render(Sampling::View, true).image;
  size_t changed = 0;
  for (size_t i = 0; i < unlit.size(); i += 4) changed += unlit[i] != fused.image[i];
  EXPECT_GT(changed, drawn / 2);
}

// The default light is used only for a scene without lights, and not at all with an environment image.
// Lambert keeps its one light whatever the scene's lights.
TEST(PbrLights, TheDefaultLightOnlyWithoutSceneLights) {
  const Rig rig = test::small_rig(5, 48, 32);
  const SceneLight bulb = make_light(SceneLightType::Point, glm::dvec3(0.0, 0.0, 2.0), glm::dvec3(0, 0, -1), 4.0f);
  auto used = [&](const Scene& s, PipelineConfig pc) {
    pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
    return describe_frame(rig, s.lights, pc).lights;
  };
  PipelineConfig pbr;
  pbr.shading = Shading::Pbr;
  Scene s = material_quads();
  std::vector<SceneLight> l = used(s, pbr);
  ASSERT_EQ(l.size(), 1u);
  EXPECT_TRUE(is_default_light(l[0]));
  EXPECT_EQ(l[0].type, SceneLightType::Directional);
  EXPECT_EQ(l[0].direction, -rig.light_world());
  EXPECT_FLOAT_EQ(l[0].intensity, float(0.8 * glm::pi<double>()));
  s.lights = {bulb};
  l = used(s, pbr);
  ASSERT_EQ(l.size(), 1u);
  EXPECT_FALSE(is_default_light(l[0]));
  EXPECT_EQ(l[0].position, bulb.position);

  // An environment image replaces the default light, never the scene's lights: without scene lights
  // the image alone lights the voxels; with a scene light, that light and the image.
  const std::shared_ptr<const Environment> sky = sky_environment(0.0, 1.0);
  PipelineConfig imaged = pbr;
  imaged.environment = sky;
  s.lights.clear();
  EXPECT_TRUE(used(s, imaged).empty());
  const test::Rendered alone = render_environment(s, rig, sky);
  EXPECT_GT(compare_with_environment(s, rig, alone, *sky, "the image alone").compared, size_t(1000));
  s.lights = {bulb};
  EXPECT_EQ(used(s, imaged).size(), 1u);
  const test::Rendered both = render_environment(s, rig, sky);
  VoxelReference reference(s, rig, both);
  reference.lights = {reference_light(bulb)};
  reference.env = image_environment(*sky);
  size_t lit = 0;
  EXPECT_GT(expect_voxels_match(reference, &lit), size_t(1000));
  EXPECT_GT(lit, size_t(300)) << "the scene's light should light the voxels beside the image";

  // Lambert: no light table, and the same pixels with or without the scene's lights.
  PipelineConfig lambert;
  lambert.shading = Shading::Lambert;
  EXPECT_TRUE(used(s, lambert).empty());
  const test::Rendered with = render_pbr(s, rig, 0.0, Method::Pmr, Shading::Lambert);
  s.lights.clear();
  const test::Rendered without = render_pbr(s, rig, 0.0, Method::Pmr, Shading::Lambert);
  EXPECT_EQ(with.volume, without.volume);
}

// A grey dielectric quad 3 x 2 in the z = 0 plane facing +Z, and a point light on its own node at
// (-1, 0, 1) (range 3); with `animated`, the light's node alone moves to (1, 0, 1) at t = 1 s (LINEAR).
std::string lit_quad_file(const std::string& dir, bool animated) {
  using namespace test;
  GltfFile g;
  const int pos = g.data<float>({-1.5f, -1, 0, 1.5f, -1, 0, 1.5f, 1, 0, -1.5f, 1, 0}, kFloat, "VEC3");
  const int nrm = g.data<float>({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, kFloat, "VEC3");
  const int idx = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, kUShort, "SCALAR");
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"name", "Bulb"}, {"type", "point"}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 2.0}, {"range", 3.0}}};
  g.add("materials", {{"pbrMetallicRoughness",
                       {{"baseColorFactor", {0.8, 0.8, 0.8, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.5}}}});
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}, {"indices", idx}, {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}});
  g.add("nodes",
        {{"name", "BulbNode"}, {"translation", {-1, 0, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  if (animated) {
    const int times = g.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
    const int moves = g.data<float>({-1, 0, 1, 1, 0, 1}, kFloat, "VEC3");
    g.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", moves}}}},
                            {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}}}}}};
  }
  g.scene({0, 1});
  return g.write(dir, animated ? "animated_bulb" : "bulb");
}

// One frame through the frame loop (FrameRenderer: posing, the lights' upload), read back like
// test::render_with.
test::Rendered render_frame(FrameRenderer& renderer, Pipeline& p, long frame, FrameRenderer::Frame* info) {
  test::Rendered r;
  *info = renderer.render(frame);
  p.read_debug(r.key, r.depth, r.count);
  p.read_volume(r.volume);
  r.mtas = p.read_mtas();
  return r;
}

PipelineConfig frame_loop_config() {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.shading = Shading::Pbr;
  pc.debug_outputs = true;
  return pc;
}

// The light's node is the only animated node (no geometry moves): the frame loop still moves the light.
// Frames 0 and 1 (t = 0 and 1 s) each match the reference with the light where the animation puts it,
// and the two frames differ.
TEST(PbrLights, AnAnimatedLightMovesBetweenFrames) {
  const std::string dir = test::temp_dir("pbr_lights_animated");
  std::filesystem::create_directories(dir);
  const Scene s = load_scene(lit_quad_file(dir, true));
  ASSERT_EQ(s.lights.size(), 1u);
  SequenceSpec spec;
  select_animation(s, "", spec);
  spec.fps = 1.0;
  RigConfig rc;
  rc.views = 5, rc.view_w = 64, rc.view_h = 40;
  FrameRenderer renderer(s, spec, rc, Display{}, nullptr);
  const PipelineConfig pc = frame_loop_config();
  Pipeline p(test::runtime(), pc);
  renderer.attach(p, nullptr);
  std::vector<uint16_t> volumes[2];
  for (long f : {0L, 1L}) {
    SCOPED_TRACE("frame " + std::to_string(f));
    FrameRenderer::Frame fr;
    const test::Rendered out = render_frame(renderer, p, f, &fr);
    SceneLight want = s.lights[0];
    want.position = glm::dvec3(f == 0 ? -1.0 : 1.0, 0.0, 1.0);
    ASSERT_EQ(fr.lights.size(), 1u);
    EXPECT_EQ(fr.lights[0].position, want.position);
    const std::vector<SceneLight> expected = renderer.describe(f, pc).lights;
    ASSERT_EQ(expected.size(), 1u);
    EXPECT_EQ(expected[0].position, fr.lights[0].position) << "the lights a resumed run expects";
    VoxelReference reference(s, renderer.rig(), out);
    reference.lights = {reference_light(want)};
    size_t lit = 0;
    EXPECT_GT(expect_voxels_match(reference, &lit), size_t(2000));
    EXPECT_GT(lit, size_t(1000));
    volumes[f] = out.volume;
  }
  size_t changed = 0, covered = 0;
  for (size_t i = 0; i < volumes[0].size(); i += 4) {
    half a, b;
    a.setBits(volumes[0][i]), b.setBits(volumes[1][i]);
    covered += float(a) > 0.0f;
    changed += std::abs(float(a) - float(b)) > 0.05f * std::max(float(a), float(b));
  }
  EXPECT_GT(changed, covered / 3) << "the light moved from one side of the quad to the other";
}

// A turntable turns the file's lights with the geometry (about +Y through the pivot), and leaves the
// default light where it is in the center camera's view.
TEST(PbrLights, TheTurntableTurnsLightsWithTheGeometry) {
  const std::string dir = test::temp_dir("pbr_lights_turntable");
  std::filesystem::create_directories(dir);
  Scene s = load_scene(lit_quad_file(dir, false));
  SequenceSpec spec;
  spec.turntable = true, spec.turntable_deg = 360.0, spec.turntable_frames = 8;  // frame 1: 45 degrees
  RigConfig rc;
  rc.views = 5, rc.view_w = 64, rc.view_h = 40;
  const PipelineConfig pc = frame_loop_config();
  {
    FrameRenderer renderer(s, spec, rc, Display{}, nullptr);
    Pipeline p(test::runtime(), pc);
    renderer.attach(p, nullptr);
    FrameRenderer::Frame fr;
    const test::Rendered out = render_frame(renderer, p, 1, &fr);
    EXPECT_DOUBLE_EQ(fr.angle, 45.0);
    // the light turned here with glm's rotation, not pose_scene's
    const glm::dvec3 c = renderer.pivot();
    const glm::dmat4 turn = glm::rotate(glm::dmat4(1.0), glm::radians(45.0), glm::dvec3(0, 1, 0));
    SceneLight want = s.lights[0];
    want.position = c + glm::dvec3(turn * glm::dvec4(s.lights[0].position - c, 1.0));
    ASSERT_EQ(fr.lights.size(), 1u);
    EXPECT_NEAR(glm::length(fr.lights[0].position - want.position), 0.0, 1e-12);
    // the reference surface: the geometry turned as pose_scene turns it (tested in test_pose.cpp)
    Scene posed = s;  // materials, textures and texture coordinates are the rest scene's
    PoseRequest r;
    r.turntable = true, r.turntable_deg = 45.0, r.pivot = c;
    pose_scene(s, r, posed);
    VoxelReference reference(posed, renderer.rig(), out);
    reference.lights = {reference_light(want)};
    EXPECT_GT(expect_voxels_match(reference), size_t(1000));
    // the test can tell: with the light left unturned, many voxels would differ
    VoxelReference unturned(posed, renderer.rig(), out);
    unturned.lights = {reference_light(s.lights[0])};
    size_t differ = 0;
    for (size_t v = 0; v < out.key.size(); ++v) {
      if (out.key[v] == PMR_NO_KEY) continue;
      const PmrMta* m = reference.mta(v);
      if (m && glm::length(reference.colour(v, *m) - unturned.colour(v, *m)) > 0.05) ++differ;
    }
    EXPECT_GT(differ, size_t(500));
  }
  s.lights.clear();  // the default light does not turn
  FrameRenderer renderer(s, spec, rc, Display{}, nullptr);
  Pipeline p(test::runtime(), pc);
  renderer.attach(p, nullptr);
  for (long f : {1L, 3L}) {
    const FrameRenderer::Frame fr = renderer.render(f);
    ASSERT_EQ(fr.lights.size(), 1u);
    EXPECT_TRUE(is_default_light(fr.lights[0]));
    EXPECT_EQ(fr.lights[0].direction, -renderer.rig().light_world()) << "frame " << f;
  }
}

}  // namespace
}  // namespace pmr
