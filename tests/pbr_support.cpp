#include "pbr_support.h"

#include <gtest/gtest.h>

#include <Imath/half.h>

#include <glm/gtc/constants.hpp>

#include "environment_maps.h"
#include "reference/material_reference.h"
#include "reference/shade_reference.h"
#include "shading/environment.h"
#include "shading/sheen.h"

namespace pmr::test {

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

// The model's bound on one voxel of a render: 1% relative plus 1e-3 absolute per colour channel.
// Counts the channels outside it (reporting the first five) and the largest error as a fraction of it.
void BoundCheck::voxel(const Rendered& out, size_t v, const glm::dvec3& want, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    half got;
    got.setBits(out.volume[v * 4 + size_t(c)]);
    const double err = std::abs(double(float(got)) - want[c]), tol = 0.01 * std::abs(want[c]) + 1e-3;
    worst = std::max(worst, err / tol);
    if (err > tol && ++bad <= 5)
      ADD_FAILURE() << what << " " << v << " channel " << c << ": " << float(got) << " vs " << want[c];
  }
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
  env.sheen = [=](const glm::dvec3&, double) { return glm::dvec3(radiance); };
  env.sheen_albedo = [](double nv, double s) { return sheen_albedo(nv, s); };
  return env;
}

VoxelReference::VoxelReference(const Scene& s, const Rig& r, const Rendered& o) : scene(s), rig(r), out(o) {
  for (const PmrMta& m : out.mtas) by_key.emplace(m.key, m);
}

const PmrMta* VoxelReference::mta(size_t v) const {
  const int view = int(v / (size_t(rig.view_w) * size_t(rig.view_h)));
  auto range = by_key.equal_range(out.key[v]);
  for (auto it = range.first; it != range.second; ++it)
    if (view >= it->second.view_lo && view <= it->second.view_hi) return &it->second;
  return nullptr;
}

glm::dvec3 VoxelReference::colour(size_t v, const PmrMta& m) const {
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
  const glm::dvec3 b = ref::source_barycentrics(m, px, py, view);
  return ref::pbr_color(surface_at(scene, rig, m.tri, b, (m.flags & PMR_MTA_BACK) != 0, view), lights, env, 1.0);
}

PipelineConfig pbr_config(Method method, TextureFilter filter, const std::shared_ptr<const Environment>& env) {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.shading = Shading::Pbr;
  pc.method = method;
  pc.multipass_snapped = method == Method::Multipass;
  pc.texture_filter = filter;
  pc.environment = env;
  return pc;
}

Rendered render_pbr(const Scene& s, const Rig& rig, Method method, TextureFilter filter,
                    const std::shared_ptr<const Environment>& env) {
  return render_with(s, rig, pbr_config(method, filter, env));
}

std::shared_ptr<const Environment> white_environment() {
  return std::make_shared<const Environment>(
      Environment::from_image(make_map(32, 16, [](glm::dvec3) { return glm::dvec3(1.0); }), "white"));
}

ref::EnvironmentTerms image_environment(const Environment& e) {
  ref::EnvironmentTerms env;
  env.irradiance = [&e](const glm::dvec3& n) { return e.irradiance(n); };
  env.prefiltered = [&e](const glm::dvec3& d, double r) { return e.prefiltered(d, r); };
  env.split_sum = [](double nv, double r) { return split_sum(nv, r); };
  env.sheen = [&e](const glm::dvec3& d, double s) { return e.sheen(d, s); };
  env.sheen_albedo = [](double nv, double s) { return sheen_albedo(nv, s); };
  return env;
}

std::shared_ptr<Environment> sky_environment(double rotation_deg, double intensity) {
  auto e = std::make_shared<Environment>(Environment::from_image(make_map(64, 32, sun_sky), "sky"));
  e->set_rotation(rotation_deg);
  e->set_intensity(intensity);
  return e;
}

Scene white_rough_square() {
  Scene s = empty_scene(true);
  s.materials[0].metallic = 0.0f, s.materials[0].roughness = 1.0f;
  for (float& c : s.materials[0].base_color) c = 1.0f;
  add_triangle(s, {-1.0f, -1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 0.0f});
  add_triangle(s, {-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {-1.0f, 1.0f, 0.0f});
  return s;
}

int add_texture16(Scene& s, const std::function<glm::dvec4(int, int)>& f) {
  SceneTexture t;
  t.width = t.height = 16;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const glm::dvec4 c = f(x, y);
      for (int k = 0; k < 4; ++k) t.rgba.push_back(uint8_t(std::lround(255.0 * glm::clamp(c[k], 0.0, 1.0))));
    }
  s.textures.push_back(t);
  return int(s.textures.size() - 1);
}

void add_feature_quads(Scene& s, const std::array<glm::vec3, 4>& bases,
                       const std::function<void(int, SceneMaterialInputs&)>& inputs) {
  if (s.material_inputs.empty()) s.material_inputs.resize(s.materials.size());
  const size_t first = s.positions.size();
  for (int q = 0; q < 4; ++q) {
    PmrMaterial m = s.materials[0];
    for (int c = 0; c < 3; ++c) m.base_color[c] = bases[size_t(q)][c];
    s.materials.push_back(m);
    SceneMaterialInputs in;
    for (int slot = 0; slot < kTextureSlots; ++slot) in.slots[size_t(slot)].srgb = texture_slot_is_srgb(slot);
    inputs(q, in);
    s.material_inputs.push_back(in);
    const uint32_t material = uint32_t(s.materials.size() - 1);
    const float x0 = -1.3f + 0.66f * float(q), x1 = x0 + 0.6f, z = 0.2f * float(q % 2) - 0.1f;
    add_triangle(s, {x0, -0.9f, z + 0.2f}, {x1, -0.8f, z - 0.2f}, {x1, 0.9f, z}, material);
    add_triangle(s, {x0, -0.9f, z + 0.2f}, {x1, 0.9f, z}, {x0, 1.0f, z + 0.1f}, material);
  }
  s.texcoords.resize(1), s.texcoords[0].resize(s.positions.size());
  s.tangents.resize(s.positions.size());
  for (size_t k = first; k < s.positions.size(); ++k) {
    const glm::vec3 p = s.positions[k];
    s.texcoords[0][k] = glm::vec2(1.2f * p.x + 0.7f, 0.5f - 0.5f * p.y);
    s.tangents[k] = glm::vec4(1.0f, 0.2f * float(k % 3), 0.1f, k % 2 ? 1.0f : -1.0f);
    PmrVertexAttr& a = s.attributes[k];
    const glm::vec3 n = glm::normalize(glm::vec3(0.4f * float(k % 3) - 0.4f, 0.3f * float(k % 2) - 0.15f, 1.0f));
    a.normal[0] = n.x, a.normal[1] = n.y, a.normal[2] = n.z;
  }
  s.lights = {make_light(SceneLightType::Point, glm::dvec3(0.3, 0.6, 1.6), glm::dvec3(0, 0, -1), 4.0f)};
}

FeatureCheck check_feature(const VoxelReference& with, const VoxelReference& without) {
  FeatureCheck r;
  const Rendered& out = with.out;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = with.mta(v);
    if (!m) {
      ADD_FAILURE() << "no MTA for key " << out.key[v];
      return r;
    }
    const glm::dvec3 want = with.colour(v, *m), bare = without.colour(v, *m);
    r.check.voxel(out, v, want);
    const uint32_t material = with.scene.triangles[m->tri].material;
    ++r.voxels[material];
    for (int c = 0; c < 3; ++c)
      if (std::abs(want[c] - bare[c]) > 2.0 * (0.01 * std::abs(want[c]) + 1e-3)) {
        ++r.changed[material];
        break;
      }
  }
  return r;
}

FeatureCheck check_feature_under(const Scene& lit, const Scene& without_feature,
                                 const std::shared_ptr<const Environment>& env) {
  Scene s = lit, plain = without_feature;
  s.lights.clear(), plain.lights.clear();
  const Rig rig = small_rig(5, 80, 40);
  const Rendered out = render_pbr(s, rig, Method::Pmr, TextureFilter::Bilinear, env);
  VoxelReference reference(s, rig, out), bare(plain, rig, out);
  reference.lights.clear(), bare.lights.clear();
  reference.env = bare.env = image_environment(*env);
  return check_feature(reference, bare);
}

double expect_feature_matches_reference(const Scene& s, const Scene& without,
                                        const std::vector<ref::PunctualLight>& lights, uint32_t n, size_t divisor) {
  const Rig rig = small_rig(5, 80, 40);
  const Rendered out = render_pbr(s, rig);
  VoxelReference reference(s, rig, out), bare(without, rig, out);
  reference.lights = bare.lights = lights;
  FeatureCheck r = check_feature(reference, bare);
  EXPECT_EQ(r.check.bad, 0u);
  for (uint32_t material = 1; material <= n; ++material) {
    EXPECT_GT(r.voxels[material], size_t(300)) << "material " << material;
    if (material < n) {
      EXPECT_GT(r.changed[material], r.voxels[material] / divisor) << "material " << material;
    }
  }
  EXPECT_EQ(r.changed[n], 0u) << "material " << n << " has no such feature";
  return r.check.worst;
}

void expect_paths_agree(const Scene& s, const Rig& rig, const PipelineConfig& pc, const Scene* other) {
  PipelineConfig snapped = pc;
  snapped.method = Method::Multipass, snapped.multipass_snapped = true;
  EXPECT_EQ(render_with(s, rig, pc).volume, render_with(s, rig, snapped).volume);
  Display d;
  d.width = 240, d.height = 135;
  d.offset = default_offset(d.lens_pitch, rig.views);
  PipelineConfig fused = pc, subpixel = pc;
  fused.fuse_encode = subpixel.fuse_encode = true;
  subpixel.sampling = Sampling::Subpixel;
  const EncodedRender f = render_encoded(s, rig, d, fused), u = render_encoded(s, rig, d, pc),
                      sp = render_encoded(s, rig, d, subpixel);
  ASSERT_TRUE(f.fused);
  EXPECT_EQ(f.image, u.image);
  const std::vector<uint16_t> bare = other ? render_encoded(*other, rig, d, fused).image : f.image;
  double sum_view = 0.0, sum_subpixel = 0.0;
  size_t lit = 0, changed = 0;
  for (size_t i = 0; i < f.image.size(); ++i) {
    if (i % 4 == 3) continue;
    half x, y;
    x.setBits(f.image[i]), y.setBits(sp.image[i]);
    sum_view += float(x), sum_subpixel += float(y);
    lit += float(x) > 0.0f;
    changed += f.image[i] != bare[i];
  }
  EXPECT_GT(lit, size_t(1000));
  if (other) {
    EXPECT_GT(changed, lit / 4) << "the feature should change the image";
  }
  EXPECT_NEAR(sum_subpixel, sum_view, 0.05 * sum_view);
}

ModelCheck check_model(const VoxelReference& reference, const SurfaceTest& include, const SurfaceTest& count) {
  ModelCheck r;
  const Rendered& out = reference.out;
  const size_t W = size_t(reference.rig.view_w), H = size_t(reference.rig.view_h);
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = reference.mta(v);
    if (!m) {
      ADD_FAILURE() << "no MTA for key " << out.key[v];
      return r;
    }
    const int view = int(v / (W * H));
    const glm::dvec3 b = ref::source_barycentrics(*m, int(v % W), int((v / W) % H), view);
    const ref::SurfacePoint sp =
        surface_at(reference.scene, reference.rig, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, view);
    if (!include(sp)) continue;
    r.check.voxel(out, v, reference.colour(v, *m));
    ++r.compared;
    r.counted += count(sp);
  }
  return r;
}

Rig highlight_rig(int views) {
  RigConfig rc;
  rc.views = views, rc.view_w = 160, rc.view_h = 100, rc.cone_deg = 60.0;
  return make_rig(rc, Display{}, glm::dvec3(-1.0), glm::dvec3(1.0));
}

glm::dvec2 brightest_pixel(const Rendered& out, const VoxelReference* reference, const Rig& rig, int view,
                           glm::dvec2 avoid, double away) {
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  double best = -1.0;
  glm::dvec2 at(-1.0);
  for (size_t py = 0; py < H; ++py)
    for (size_t px = 0; px < W; ++px) {
      const size_t v = (size_t(view) * H + py) * W + px;
      if (out.key[v] == PMR_NO_KEY || glm::length(glm::dvec2(px, py) - avoid) <= away) continue;
      double value;
      if (reference) {
        const PmrMta* m = reference->mta(v);
        if (!m) {
          ADD_FAILURE() << "no MTA for key " << out.key[v];
          return at;
        }
        value = reference->colour(v, *m).y;
      } else {
        half g;
        g.setBits(out.volume[v * 4 + 1]);
        value = double(float(g));
      }
      if (value > best) best = value, at = glm::dvec2(px, py);
    }
  return at;
}

ref::PunctualLight reference_light(const SceneLight& l) {
  ref::PunctualLight r;
  r.type = l.type == SceneLightType::Point  ? ref::LightType::Point
           : l.type == SceneLightType::Spot ? ref::LightType::Spot
                                            : ref::LightType::Directional;
  r.color_intensity = glm::dvec3(l.color[0], l.color[1], l.color[2]) * double(l.intensity);
  r.position = l.position;
  r.direction = l.direction;
  r.range = l.range;
  r.cos_inner = std::cos(double(l.inner_cone));
  r.cos_outer = std::cos(double(l.outer_cone));
  return r;
}

SceneLight make_light(SceneLightType type, const glm::dvec3& position, const glm::dvec3& direction, float intensity,
                      float range) {
  SceneLight l;
  l.type = type;
  l.position = position;
  l.direction = glm::normalize(direction);
  l.intensity = intensity;
  l.range = range;
  return l;
}

void quad(Scene& s, float x0, float y0, float x1, float y1, float z, uint32_t material) {
  add_triangle(s, {x0, y0, z}, {x1, y0, z}, {x1, y1, z}, material);
  add_triangle(s, {x0, y0, z}, {x1, y1, z}, {x0, y1, z}, material);
}

uint32_t add_material(Scene& s, const PmrMaterial& m) {
  s.materials.push_back(m);
  return uint32_t(s.materials.size() - 1);
}

PmrMaterial unlit(glm::vec3 c) {
  PmrMaterial m = default_material();
  m.unlit = 1;
  m.base_color[0] = c.x, m.base_color[1] = c.y, m.base_color[2] = c.z;
  return m;
}

}  // namespace pmr::test
