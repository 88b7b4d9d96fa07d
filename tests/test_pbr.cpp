// --shading pbr against the double-precision reference of the model (tests/reference/pbr_reference.cpp):
// every shaded voxel of small renders, the highlight's motion across the views (specular parallax), the
// exposure, and the rendering paths agreeing with each other.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <glm/gtc/constants.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "reference/material_reference.h"
#include "reference/pbr_reference.h"
#include "reference/shade_reference.h"
#include "shading/environment.h"
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

// The model's inputs at source barycentrics b of triangle `tri` seen from view `view`, computed here
// from the scene's material inputs (tests/reference/material_reference.h), for the reference.
ref::SurfacePoint surface_at(const Scene& s, const Rig& rig, uint32_t tri, const glm::dvec3& b, bool back, int view) {
  const PmrTriangle& t = s.triangles[tri];
  ref::SurfacePoint sp;
  ref::material_at(s, tri, b, back, sp);
  sp.p = glm::dvec3(0.0);
  for (int k = 0; k < 3; ++k) sp.p += b[k] * glm::dvec3(s.positions[t.v[k]]);
  sp.eye = glm::dvec3(glm::inverse(rig.view_matrix(view))[3]);
  return sp;
}

// The defaults: one directional light toward the rig's light direction with E = 0.8 pi, a uniform
// environment of radiance 0.2 (I = P = 0.2) and the split-sum table the kernels are given.
std::vector<ref::PunctualLight> default_light(const Rig& rig) {
  ref::PunctualLight l;
  l.type = ref::LightType::Directional;
  l.direction = -rig.light_world();
  l.color_intensity = glm::dvec3(0.8 * glm::pi<double>());
  return {l};
}

ref::EnvironmentTerms uniform_environment(double radiance) {
  ref::EnvironmentTerms env;
  env.irradiance = [=](const glm::dvec3&) { return glm::dvec3(radiance); };
  env.prefiltered = [=](const glm::dvec3&, double) { return glm::dvec3(radiance); };
  env.split_sum = [](double nv, double r) { return split_sum(nv, r); };
  return env;
}

// The reference colour of every covered voxel of a render (volume index v), under the default light
// and environment: the winning MTA found by its key and view, then the model at its barycentrics.
struct VoxelReference {
  const Scene& scene;
  const Rig& rig;
  const test::Rendered& out;
  std::multimap<uint32_t, PmrMta> by_key;
  std::vector<ref::PunctualLight> lights = default_light(rig);
  ref::EnvironmentTerms env = uniform_environment(0.2);

  VoxelReference(const Scene& s, const Rig& r, const test::Rendered& o) : scene(s), rig(r), out(o) {
    for (const PmrMta& m : out.mtas) by_key.emplace(m.key, m);
  }
  // The winner of voxel v (null if none matches its key and view).
  const PmrMta* mta(size_t v) const {
    const int view = int(v / (size_t(rig.view_w) * size_t(rig.view_h)));
    auto range = by_key.equal_range(out.key[v]);
    for (auto it = range.first; it != range.second; ++it)
      if (view >= it->second.view_lo && view <= it->second.view_hi) return &it->second;
    return nullptr;
  }
  glm::dvec3 colour(size_t v, const PmrMta& m) const {
    const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
    const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
    const glm::dvec3 b = ref::source_barycentrics(m, px, py, view);
    return ref::pbr_color(surface_at(scene, rig, m.tri, b, (m.flags & PMR_MTA_BACK) != 0, view), lights, env, 1.0);
  }
};

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
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  size_t compared = 0, bad = 0, back = 0;
  std::map<uint32_t, size_t> per_material;
  double worst = 0.0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
    const PmrMta* m = reference.mta(v);
    ASSERT_NE(m, nullptr) << "no MTA for key " << out.key[v];
    back += (m->flags & PMR_MTA_BACK) != 0;
    const glm::dvec3 want = reference.colour(v, *m);
    for (int c = 0; c < 3; ++c) {
      half got;
      got.setBits(out.volume[v * 4 + size_t(c)]);
      const double err = std::abs(double(float(got)) - want[c]), tol = 0.01 * std::abs(want[c]) + 1e-3;
      worst = std::max(worst, err / tol);
      if (err > tol && ++bad <= 5)
        ADD_FAILURE() << "voxel (" << px << "," << py << "," << view << ") channel " << c << ": " << float(got)
                      << " vs " << want[c];
    }
    ++compared;
    ++per_material[s.triangles[m->tri].material];
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(compared, size_t(3000));
  for (uint32_t material = 1; material <= 6; ++material)  // every quad, the emissive and unlit ones too
    EXPECT_GT(per_material[material], size_t(100)) << "material " << material;
  EXPECT_GT(back, 0u) << "the scene should contain a back face";
  std::printf("[ pbr      ] %zu voxels, largest error %.3f of the bound\n", compared, worst);
}

// Two quads whose materials use every map: metallic-roughness, normal (scale 0.8) and occlusion
// (strength 0.7) on the left, sampled on TEXCOORD_1 through a texture transform and TEXCOORD_0; an
// emissive map and a mirrored normal map (tangent w = -1, tangents not orthogonal to the normals) on the
// right. Procedural 16x16 textures, curved normals.
Scene mapped_quads() {
  Scene s = test::empty_scene(false);
  s.material_inputs.resize(1);
  auto texture = [&](auto texel_of) {
    SceneTexture t;
    t.width = 16, t.height = 16;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const glm::dvec4 c = texel_of(x, y);
        for (int k = 0; k < 4; ++k) t.rgba.push_back(uint8_t(std::lround(255.0 * glm::clamp(c[k], 0.0, 1.0))));
      }
    s.textures.push_back(t);
    return int(s.textures.size() - 1);
  };
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
  size_t compared = 0, bad = 0, changed = 0;
  std::map<uint32_t, size_t> per_material;
  double worst = 0.0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    ASSERT_NE(m, nullptr);
    const glm::dvec3 want = reference.colour(v, *m), plain_colour = without_maps.colour(v, *m);
    changed += glm::length(want - plain_colour) > 0.05 * glm::length(plain_colour);
    for (int c = 0; c < 3; ++c) {
      half got;
      got.setBits(out.volume[v * 4 + size_t(c)]);
      const double err = std::abs(double(float(got)) - want[c]), tol = 0.01 * std::abs(want[c]) + 1e-3;
      worst = std::max(worst, err / tol);
      if (err > tol && ++bad <= 5) ADD_FAILURE() << "voxel " << v << " channel " << c << ": " << float(got) << " vs " << want[c];
    }
    ++compared;
    ++per_material[s.triangles[m->tri].material];
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(per_material[1], size_t(1000));
  EXPECT_GT(per_material[2], size_t(1000));
  EXPECT_GT(changed, compared * 3 / 4) << "the maps should change most voxels";
  std::printf("[ pbr maps ] %zu voxels, %zu changed by the maps, largest error %.3f of the bound\n", compared, changed,
              worst);
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
    if (f == files[1]) EXPECT_GT(s.structure.generated_tangent_primitives, 0u) << "the copy should have no TANGENT";
    glm::dvec3 lo, hi;
    ASSERT_TRUE(scene_bounds(s, lo, hi));
    RigConfig rc;
    rc.views = 5, rc.view_w = 96, rc.view_h = 64;
    const Rig rig = make_rig(rc, Display{}, lo, hi);
    const test::Rendered out = render_pbr(s, rig);
    const VoxelReference reference(s, rig, out);
    size_t compared = 0, bad = 0;
    double worst = 0.0;
    for (size_t v = 0; v < out.key.size(); ++v) {
      if (out.key[v] == PMR_NO_KEY) continue;
      const PmrMta* m = reference.mta(v);
      ASSERT_NE(m, nullptr);
      const int W = rig.view_w, H = rig.view_h;
      const int view = int(v / size_t(W * H));
      const glm::dvec3 b = ref::source_barycentrics(*m, int(v % size_t(W)), int((v / size_t(W)) % size_t(H)), view);
      if (surface_at(s, rig, m->tri, b, false, view).roughness < 0.2) continue;
      const glm::dvec3 want = reference.colour(v, *m);
      for (int c = 0; c < 3; ++c) {
        half got;
        got.setBits(out.volume[v * 4 + size_t(c)]);
        const double err = std::abs(double(float(got)) - want[c]), tol = 0.01 * std::abs(want[c]) + 1e-3;
        worst = std::max(worst, err / tol);
        if (err > tol && ++bad <= 5) ADD_FAILURE() << "voxel " << v << " channel " << c << ": " << float(got) << " vs " << want[c];
      }
      ++compared;
    }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(compared, size_t(2000));
    std::printf("[ pbr      ] %s: %zu voxels, largest error %.3f of the bound\n", fs::path(f).filename().c_str(), compared,
                worst);
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
  RigConfig rc;
  rc.views = N, rc.view_w = 160, rc.view_h = 100, rc.cone_deg = 60.0;
  const Rig rig = make_rig(rc, Display{}, glm::dvec3(-1.0), glm::dvec3(1.0));
  const Scene s = sphere(0.8f, glm::vec3(0.0f), 1.0f, 0.2f);
  const test::Rendered out = render_pbr(s, rig);
  const VoxelReference reference(s, rig, out);
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  double moved_got = 0.0, moved_want = 0.0;
  glm::dvec2 first_got(0.0), first_want(0.0);
  for (int view : {0, N / 2, N - 1}) {
    double best_got = -1.0, best_want = -1.0;
    glm::dvec2 at_got(0.0), at_want(0.0);
    for (size_t py = 0; py < H; ++py)
      for (size_t px = 0; px < W; ++px) {
        const size_t v = (size_t(view) * H + py) * W + px;
        if (out.key[v] == PMR_NO_KEY) continue;
        half g;
        g.setBits(out.volume[v * 4 + 1]);
        if (float(g) > best_got) best_got = float(g), at_got = glm::dvec2(px, py);
        const PmrMta* m = reference.mta(v);
        ASSERT_NE(m, nullptr);
        const double want = reference.colour(v, *m).y;
        if (want > best_want) best_want = want, at_want = glm::dvec2(px, py);
      }
    EXPECT_LE(glm::length(at_got - at_want), 1.0 + 1e-9) << "view " << view << ": highlight at (" << at_got.x << ","
                                                       << at_got.y << "), reference (" << at_want.x << "," << at_want.y << ")";
    if (view == 0) first_got = at_got, first_want = at_want;
    if (view == N - 1) moved_got = at_got.x - first_got.x, moved_want = at_want.x - first_want.x;
  }
  EXPECT_GT(std::abs(moved_want), 3.0) << "the rig should move the highlight by several pixels";
  EXPECT_NEAR(moved_got, moved_want, 1.0);
}

// Exposure scales either model by 2^EV (half-float outputs: 2^-10 relative).
TEST(Pbr, ExposureScalesBothModels) {
  const Rig rig = test::small_rig(3, 40, 24);
  const Scene s = material_quads();
  for (Shading shading : {Shading::Lambert, Shading::Pbr}) {
    const test::Rendered a = render_pbr(s, rig, 0.0, Method::Pmr, shading), b = render_pbr(s, rig, 1.5, Method::Pmr, shading);
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
    for (int c = 0; c < 4; ++c) ASSERT_EQ(pmr.volume[v * 4 + size_t(c)], dup.volume[v * 4 + size_t(c)]) << "voxel " << v;
    ++same;
  }
  EXPECT_GT(same, covered * 9 / 10);
  EXPECT_GT(covered, size_t(1000));
}

}  // namespace
}  // namespace pmr
