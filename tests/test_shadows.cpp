// Shadows (DESIGN section 4d): the frame's shadow maps against a plain C++ rasterization, and the
// visibility the kernels shade with against exact visibility, ray-cast in double precision
// (tests/reference/visibility_reference.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "gltf_builder.h"
#include "pbr_support.h"
#include "pipeline/shadow_stage.h"
#include "reference/shade_reference.h"
#include "reference/visibility_reference.h"
#include "shadow_support.h"
#include "shading/lights.h"
#include "shading/studio_environment.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::add_box;
using test::add_quad;
using test::add_sphere;
using test::probe;
using test::Receiver;
using test::render_maps;
using test::ShadowMaps;

// A ground plane at y = -0.5 and a box standing on it.
Scene box_on_plane() {
  Scene s = test::empty_scene(false);
  add_quad(s, {-1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, -1.5f}, {-1.5f, -0.5f, -1.5f});
  add_box(s, {-0.25f, -0.5f, -0.25f}, {0.25f, 0.1f, 0.25f});
  return s;
}

// The same turned 60 degrees about +X (+Y toward +Z), so that the rigs of test::small_rig, which look
// down -Z, see the plane nearly face on; vertex and face normals turned with it.
Scene box_on_plane_facing_the_camera() {
  Scene s = box_on_plane();
  const double c = 0.5, sn = std::sqrt(0.75);
  auto turn = [&](float* v) {
    const double y = v[1], z = v[2];
    v[1] = float(c * y - sn * z), v[2] = float(sn * y + c * z);
  };
  for (glm::vec3& p : s.positions) turn(&p.x);
  for (PmrVertexAttr& a : s.attributes) turn(a.normal);
  for (PmrTriangle& t : s.triangles) turn(t.face_normal);
  return s;
}

SceneLight sun(glm::dvec3 travel) {
  SceneLight l;
  l.type = SceneLightType::Directional;
  l.intensity = 3.0f;
  l.direction = glm::normalize(travel);
  return l;
}

// The world size of a texel of the light's map at p (the face of p's major axis for a cube).
double texel_at(const ShadowMaps& m, const SceneLight& light, const glm::dvec3& p) {
  size_t k = 0;
  if (m.maps.size() == 6) {
    const glm::dvec3 d = p - light.position, a = glm::abs(d);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    k = size_t(2 * axis + (d[axis] < 0.0 ? 1 : 0));
  }
  const PmrShadowMap& s = m.maps[k];
  if (!s.perspective) return s.texel;
  return s.texel *
         glm::dot(p - glm::dvec3(s.origin[0], s.origin[1], s.origin[2]), glm::dvec3(s.axis[0], s.axis[1], s.axis[2]));
}

// Whether the exact visibility of `exact` changes within distance h across the light (unit l toward
// it) around receiver r: at 8 points h from r.p across l, each slid along l back onto r's plane (for h
// a texel, the texel's footprint on the receiver).
bool near_shadow_edge(const Scene& s, const ref::PunctualLight& exact, const Receiver& r, const glm::dvec3& l,
                      double h) {
  const double e = ref::ray_visibility(s, r.p, exact);
  const glm::dvec3 t = glm::normalize(glm::cross(l, std::abs(l.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
  const glm::dvec3 b = glm::cross(l, t);
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4.0;
    const glm::dvec3 step = h * (std::cos(a) * t + std::sin(a) * b);
    if (ref::ray_visibility(s, r.p + step - l * (glm::dot(step, r.n) / glm::dot(l, r.n)), exact) != e) return true;
  }
  return false;
}

// DESIGN 4d's bound on the receivers that a point-like light reaches (facing it, inside a spot's cone):
// the mean |V - V_exact| at most 0.02, and where V is on the wrong side of 1/2 the exact edge lies
// within one texel of the map (V_exact differs at a point of the receiver's plane one texel away as
// the map sees it). Returns the count of receivers compared with V_exact = 0.
size_t expect_hard_shadow(const Scene& s, const SceneLight& light, const std::vector<Receiver>& at) {
  const ShadowMaps m = render_maps(s);
  const std::vector<float> v = probe(m, light, at);
  const ref::PunctualLight exact = test::reference_light(light);
  double sum = 0.0;
  size_t shadowed = 0, displaced = 0;
  size_t compared = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    glm::dvec3 l;
    if (!(ref::light_irradiance(exact, at[i].p, l).x > 0.0) || glm::dot(l, at[i].n) <= 0.0) continue;
    ++compared;
    const double e = ref::ray_visibility(s, at[i].p, exact);
    sum += std::abs(v[i] - e);
    shadowed += e == 0.0;
    if (std::abs(v[i] - e) <= 0.5) continue;
    const double h = texel_at(m, light, at[i].p);
    if (!near_shadow_edge(s, exact, at[i], l, h) && ++displaced <= 5)
      ADD_FAILURE() << "V " << v[i] << " at (" << at[i].p.x << ", " << at[i].p.y << ", " << at[i].p.z << "), exactly "
                    << e << " within a texel (" << h << ") around";
  }
  const double mean = sum / double(compared);
  EXPECT_LE(mean, 0.02);
  EXPECT_EQ(displaced, 0u);
  std::printf("[ shadows  ] %zu receivers lit (%zu shadowed), mean |V error| %.4f\n", compared, shadowed, mean);
  return shadowed;
}

// Receivers on the ground plane y = -0.5 (step apart) and on the box's faces.
std::vector<Receiver> box_receivers(double step) {
  std::vector<Receiver> at;
  for (double x = -1.45; x <= 1.45; x += step)
    for (double z = -1.45; z <= 1.45; z += step)
      if (std::abs(x) > 0.25 || std::abs(z) > 0.25) at.push_back({{x, -0.5, z}, {0, 1, 0}});
  for (double u = -0.24; u <= 0.24; u += step)
    for (double w = -0.49; w <= 0.09; w += step) {
      at.push_back({{0.25, w, u}, {1, 0, 0}}), at.push_back({{-0.25, w, u}, {-1, 0, 0}});
      at.push_back({{u, w, 0.25}, {0, 0, 1}}), at.push_back({{u, w, -0.25}, {0, 0, -1}});
    }
  return at;
}

TEST(Shadows, DirectionalLightMatchesRayCasting) {
  for (const glm::dvec3 travel : {glm::dvec3(0.3, -1.0, -0.2), glm::dvec3(1.0, -0.27, 0.4)}) {  // steep, grazing
    Scene s = box_on_plane();
    s.lights = {sun(travel)};
    EXPECT_GT(expect_hard_shadow(s, s.lights[0], box_receivers(0.013)), 500u);
  }
}

TEST(Shadows, SpotLightMatchesRayCasting) {
  Scene s = box_on_plane();
  s.lights = {test::make_light(SceneLightType::Spot, {1.1, 0.6, 0.7}, {-1.1, -1.0, -0.7}, 20.0f, 0.0f)};
  s.lights[0].outer_cone = 0.7f;
  EXPECT_GT(expect_hard_shadow(s, s.lights[0], box_receivers(0.013)), 500u);
}

// A point light inside a room of six walls, a small box between it and each wall: every cube face
// holds a shadow.
TEST(Shadows, PointLightMatchesRayCastingOnEveryCubeFace) {
  Scene s = test::empty_scene(false);
  const float w = 1.2f;
  add_box(s, {-w, -w, -w}, {w, w, w});  // outward faces; both sides receive (the kernel flips toward the light)
  const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::vec3& a : axes) add_box(s, a * 0.5f - glm::vec3(0.1f), a * 0.5f + glm::vec3(0.1f));
  s.lights = {test::make_light(SceneLightType::Point, {0.05, 0.03, -0.02}, {0, 0, -1}, 20.0f, 0.0f)};
  std::vector<Receiver> at;
  for (const glm::vec3& a : axes)
    for (double u = -1.15; u <= 1.15; u += 0.02)
      for (double v = -1.15; v <= 1.15; v += 0.02) {
        glm::dvec3 p = glm::dvec3(a) * double(w);
        const int i = a.x != 0 ? 0 : a.y != 0 ? 1 : 2;
        p[(i + 1) % 3] = u, p[(i + 2) % 3] = v;
        at.push_back({p, -glm::dvec3(a)});
      }
  EXPECT_GT(expect_hard_shadow(s, s.lights[0], at), 6u * 200u);
}

// Casters by material (DESIGN 4d): a MASK quad alpha-tested (a checker of alpha 0 and 1), a BLEND quad
// of alpha 0.5 and a glass quad of transmission 0.7 over a plane: the light through each is what
// ray casting with the casters' opacities gives (0 or 1, 0.5, 0.7).
TEST(Shadows, MaskBlendAndGlassCastWhatTheyBlock) {
  Scene s = test::empty_scene(false);
  add_quad(s, {-1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, -1.5f}, {-1.5f, -0.5f, -1.5f});
  PmrMaterial mask = s.materials[0], blend = s.materials[0], glass = s.materials[0];
  mask.alpha_mode = PMR_ALPHA_MASK, mask.alpha_cutoff = 0.5f;
  blend.alpha_mode = PMR_ALPHA_BLEND, blend.base_color[3] = 0.5f;
  glass.transmission = 0.7f;
  s.materials.insert(s.materials.end(), {mask, blend, glass});
  const int checker =
      test::add_texture16(s, [](int x, int y) { return glm::dvec4(1, 1, 1, ((x / 4 + y / 4) % 2) ? 1.0 : 0.0); });
  test::base_colour_texture(s, 1, checker);
  s.material_inputs[3].has_transmission = true, s.material_inputs[3].transmission = 0.7f;  // the factors drawn
  const float x0[3] = {-1.2f, -0.3f, 0.5f};
  for (uint32_t q = 0; q < 3; ++q) {
    const float a = x0[q], b = a + 0.7f;
    test::add_triangle(s, {a, 0.0f, 0.4f}, {b, 0.0f, 0.4f}, {b, 0.0f, -0.4f}, q + 1);
    test::add_triangle(s, {a, 0.0f, 0.4f}, {b, 0.0f, -0.4f}, {a, 0.0f, -0.4f}, q + 1);
  }
  for (size_t v = 0; v < s.positions.size(); ++v)
    test::texcoord(s, 0, v) = glm::vec2((s.positions[v].x + 1.2f) / 0.7f, (s.positions[v].z + 0.4f) / 0.8f);
  s.lights = {sun({0.1, -1.0, 0.05})};
  std::vector<Receiver> at;
  for (double x = -1.45; x <= 1.45; x += 0.01)
    for (double z = -0.6; z <= 0.6; z += 0.01) at.push_back({{x, -0.5, z}, {0, 1, 0}});
  expect_hard_shadow(s, s.lights[0], at);
  const ShadowMaps m = render_maps(s);
  const std::vector<float> v = probe(m, s.lights[0], at);
  const ref::PunctualLight exact = test::reference_light(s.lights[0]);
  size_t half = 0, glassy = 0, holes = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    const double e = ref::ray_visibility(s, at[i].p, exact);
    if (std::abs(e - 0.5) < 1e-9 && std::abs(v[i] - 0.5) < 0.02) ++half;
    if (std::abs(e - 0.7) < 1e-6 && std::abs(v[i] - 0.7) < 0.02) ++glassy;
    if (e == 1.0 && at[i].p.x < -0.5 && at[i].p.x > -1.15 && std::abs(at[i].p.z) < 0.35 && v[i] > 0.98f) ++holes;
  }
  EXPECT_GT(half, 2000u) << "under the BLEND quad";
  EXPECT_GT(glassy, 2000u) << "under the glass";
  EXPECT_GT(holes, 1000u) << "through the MASK quad's holes";
}

// The exact visibility of a light with a size at p: the unoccluded fraction of n x n stratified points
// on the disk it shows to p (a sphere light: its great disk facing p; a sun of apparent diameter
// `angle`: directions within the cone), ray-cast.
double exact_soft_visibility(const Scene& s, const SceneLight& light, const glm::dvec3& p, int n);

// The same for an area light and a receiver of normal up: the fraction of its irradiance (the points of
// an n x n grid on its shape weighted by cos_light cos_receiver / d^2) that arrives unoccluded.
double exact_area_visibility(const Scene& s, const SceneLight& light, const glm::dvec3& p, int n) {
  double on = 0.0, all = 0.0;
  auto add = [&](double u, double v) {
    const glm::dvec3 q = light.position + 0.5 * u * light.width * light.right + 0.5 * v * light.height * light.up;
    // a distant light's shape lies at distance 1 in every direction from p: a ray to infinity
    const glm::dvec3 d = light.distant ? q : q - p;
    const double len = glm::length(d), far = light.distant ? 1e300 : len;
    const double w = std::max(0.0, -glm::dot(d, light.direction) / len) * std::max(0.0, d.y / len) / (len * len);
    all += w;
    if (w > 0.0 && ref::transmittance(s, p, d / len, 1e-7, far) > 0.5) on += w;
  };
  // the center and the rim agreeing: fully lit or fully shadowed (the occluders here are large)
  for (int k = 0; k < 8; ++k) add(std::cos(k * M_PI / 4), std::sin(k * M_PI / 4));
  add(0.0, 0.0);
  if (on == 0.0 || on == all) return on == 0.0 ? 0.0 : 1.0;
  on = all = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2.0 * (i + 0.5) / n - 1.0, v = 2.0 * (j + 0.5) / n - 1.0;
      if (light.type == SceneLightType::Disk && u * u + v * v > 1.0) continue;
      add(u, v);
    }
  return on / all;
}

double exact_soft_visibility(const Scene& s, const SceneLight& light, const glm::dvec3& p, int n) {
  if (is_area_light(light)) return exact_area_visibility(s, light, p, n);
  const bool sun = light.type == SceneLightType::Directional;
  const glm::dvec3 axis = sun ? -light.direction : glm::normalize(light.position - p);
  const glm::dvec3 x =
      glm::normalize(glm::cross(axis, std::abs(axis.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
  const glm::dvec3 y = glm::cross(axis, x);
  const double r = sun ? std::tan(0.5 * light.angle) : double(light.radius);
  auto lit = [&](double u, double v) {
    const glm::dvec3 d = r * (u * x + v * y);
    return sun ? ref::transmittance(s, p, glm::normalize(axis + d), 1e-7, 1e300) > 0.5
               : ref::transmittance(s, p, glm::normalize(light.position + d - p), 1e-7,
                                    glm::length(light.position + d - p)) > 0.5;
  };
  // the center and the rim agreeing: fully lit or fully shadowed (the occluders here are large)
  const bool center = lit(0.0, 0.0);
  bool same = true;
  for (int k = 0; k < 8 && same; ++k) same = lit(std::cos(k * M_PI / 4), std::sin(k * M_PI / 4)) == center;
  if (same) return center ? 1.0 : 0.0;
  size_t on = 0, all = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2.0 * (i + 0.5) / n - 1.0, v = 2.0 * (j + 0.5) / n - 1.0;
      if (u * u + v * v > 1.0) continue;
      ++all, on += lit(u, v);
    }
  return double(on) / double(all);
}

// A ball resting on a plane and two overlapping occluders at two heights above it (where estimating
// one blocker depth per receiver fails), lit by a sphere light and by a sun with an apparent size:
// over the receivers in a penumbra (0 < V_exact < 1) the mean |V - V_exact| is at most 0.03, and the
// penumbra widens away from the caster (a contact region stays dark).
TEST(Shadows, SoftShadowsMatchTheExactFraction) {
  Scene base = test::empty_scene(false);
  add_quad(base, {-1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, 1.5f}, {1.5f, -0.5f, -1.5f}, {-1.5f, -0.5f, -1.5f});
  add_sphere(base, {-0.5f, -0.2f, 0.3f}, 0.3f, 12);
  add_quad(base, {0.1f, 0.4f, 0.4f}, {0.9f, 0.4f, 0.4f}, {0.9f, 0.4f, -0.2f}, {0.1f, 0.4f, -0.2f});
  add_quad(base, {0.4f, -0.1f, 0.1f}, {1.1f, -0.1f, 0.1f}, {1.1f, -0.1f, -0.6f}, {0.4f, -0.1f, -0.6f});
  SceneLight sphere = test::make_light(SceneLightType::Point, {0.1, 1.6, 0.1}, {0, -1, 0}, 30.0f, 0.0f);
  sphere.radius = 0.25f;
  SceneLight wide_sun = sun({0.1, -1.0, 0.05});
  wide_sun.angle = 0.12f;
  // a disk of the sphere's silhouette, and a rect of the same area, facing down
  SceneLight disk = sphere;
  disk.type = SceneLightType::Disk, disk.right = {1, 0, 0}, disk.up = {0, 0, -1};
  disk.width = disk.height = 2.0 * sphere.radius;
  SceneLight rect = disk;
  rect.type = SceneLightType::Rect, rect.width = rect.height = std::sqrt(M_PI) * sphere.radius;
  // the studio's ceiling (a distant disk) and its key box (a distant rect, 15 degrees above the horizon)
  const std::vector<SceneLight> boxes = studio_box_lights();
  for (const SceneLight& light : {sphere, wide_sun, disk, rect, boxes[0], boxes[1]}) {
    SCOPED_TRACE(light.distant ? light.name : light_type_name(light.type));
    Scene s = base;
    s.lights = {light};
    const ShadowMaps m = render_maps(s);
    std::vector<Receiver> at;
    std::vector<double> exact;
    for (double x = -1.2; x <= 1.4; x += 0.025)
      for (double z = -1.0; z <= 1.0; z += 0.025) {
        const double e = exact_soft_visibility(s, light, {x, -0.5, z}, 20);
        if (e > 0.0 && e < 1.0) at.push_back({{x, -0.5, z}, {0, 1, 0}}), exact.push_back(e);
      }
    const std::vector<float> v = probe(m, light, at);
    double sum = 0.0;
    for (size_t i = 0; i < at.size(); ++i) sum += std::abs(v[i] - exact[i]);
    const double mean = sum / double(at.size());
    EXPECT_LE(mean, 0.03);
    EXPECT_GT(at.size(), 300u);
    std::printf("[ shadows  ] %s: %zu penumbra receivers, mean |V error| %.4f\n",
                light.distant ? light.name.c_str() : light_type_name(light.type), at.size(), mean);
  }
}

// A convex receiver facing the light shadows nothing of itself.
TEST(Shadows, NoAcneOnACurvedReceiverFacingTheLight) {
  Scene s = test::empty_scene(false);
  add_sphere(s, {0.0f, 0.0f, 0.0f}, 0.8f, 48);
  s.lights = {sun({0.4, -0.7, -0.6})};
  const ShadowMaps m = render_maps(s);
  std::vector<Receiver> at;
  const glm::dvec3 l = -glm::normalize(s.lights[0].direction);
  for (const PmrTriangle& t : s.triangles) {
    const glm::dvec3 a(s.positions[t.v[0]]), b(s.positions[t.v[1]]), c(s.positions[t.v[2]]);
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    for (const glm::dvec3 w : {glm::dvec3(1, 1, 1) / 3.0, glm::dvec3(0.7, 0.2, 0.1), glm::dvec3(0.1, 0.1, 0.8)})
      if (glm::dot(n, l) > 0.05) at.push_back({w.x * a + w.y * b + w.z * c, n});
  }
  const std::vector<float> v = probe(m, s.lights[0], at);
  size_t acne = 0;
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i] < 0.999f && ++acne <= 5)
      ADD_FAILURE() << "V " << v[i] << " at n.l " << glm::dot(at[i].n, l) << " (" << at[i].p.x << ", " << at[i].p.y
                    << ", " << at[i].p.z << ")";
  EXPECT_EQ(acne, 0u) << "of " << at.size() << " receivers facing the light";
  EXPECT_GT(at.size(), 5000u);
}

// Where a box stands on the plane the shadow starts at the box: receivers just beyond its base, in its
// shadow, are shadowed from one texel on (the light at 20 degrees above the horizon).
TEST(Shadows, NoGapAtContact) {
  Scene s = box_on_plane();
  s.lights = {sun({1.0, -0.36, 0.0})};
  const ShadowMaps m = render_maps(s);
  const double texel = m.maps[0].texel;
  std::vector<Receiver> at;
  for (double d = 1.0; d <= 6.0; d += 0.25)
    for (double z = -0.2; z <= 0.2; z += 0.05) at.push_back({{0.25 + d * texel, -0.5, z}, {0, 1, 0}});
  const std::vector<float> v = probe(m, s.lights[0], at);
  for (size_t i = 0; i < at.size(); ++i)
    EXPECT_LT(v[i], 0.5f) << "at x = 0.25 + " << (at[i].p.x - 0.25) / texel << " texels";
}

// The shaded result: every covered voxel of the box on the plane under a sun (and the uniform
// environment, its occlusion off) equals the reference's colour with the sun's term times the ray-cast visibility at the voxel's surface point (1% + 1e-3 per
// channel), except within a texel of a shadow's edge.
TEST(Shadows, ShadedVoxelsMatchTheReferenceWithRayCastVisibility) {
  Scene s = box_on_plane_facing_the_camera();
  s.lights = {sun({0.5, -1.0, -0.3})};
  const Rig rig = test::small_rig(5, 96, 64);
  PipelineConfig pc = test::pbr_config(Method::Pmr, TextureFilter::Bilinear, nullptr);
  pc.shadows = true;
  pc.environment_occlusion = false;  // tested on its own (tests/test_environment_occlusion.cpp)
  const test::Rendered out = test::render_with(s, rig, pc);
  test::VoxelReference lit(s, rig, out), ambient(s, rig, out);
  lit.lights = {test::reference_light(s.lights[0])};
  ambient.lights.clear();
  const ref::PunctualLight exact = lit.lights[0];
  const double texel = render_maps(s).maps[0].texel;
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  test::BoundCheck check;
  size_t compared = 0, shadowed = 0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = lit.mta(v);
    ASSERT_NE(m, nullptr);
    const int view = int(v / (W * H));
    const glm::dvec3 b = ref::source_barycentrics(*m, int(v % W), int((v / W) % H), view);
    const glm::dvec3 p = test::surface_at(s, rig, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, view).p;
    const double e = ref::ray_visibility(s, p, exact);
    const float* fn = s.triangles[m->tri].face_normal;
    if (near_shadow_edge(s, exact, {p, glm::dvec3(fn[0], fn[1], fn[2])}, -exact.direction, 1.5 * texel)) continue;
    const glm::dvec3 a = ambient.colour(v, *m);
    check.voxel(out, v, a + e * (lit.colour(v, *m) - a), "shadowed voxel");
    ++compared, shadowed += e == 0.0;
  }
  EXPECT_EQ(check.bad, 0u);
  EXPECT_GT(compared, 5000u);
  EXPECT_GT(shadowed, 500u);
  size_t covered = 0;
  for (uint32_t k : out.key) covered += k != PMR_NO_KEY;
  std::printf("[ shadows  ] %zu of %zu covered voxels compared, %zu of them shadowed\n", compared, covered, shadowed);
}

// Every path gives the same shadows: the fused display image equals the encoded view volume bit for
// bit, subpixel sampling on a raster of 3 W_d x H_d equals view sampling but for depth ties, and the
// duplicate and multipass baselines shade each voxel they share with PMR (same winner) alike: the same
// bits (duplicate), within 1e-3 (multipass, whose per-view passes round the surface point apart).
void every_path_gives_the_same_shadows(const SceneLight& light);

// A rect area light of 0.6 m x 0.4 m, 1.6 m over the plane of box_on_plane_facing_the_camera and off to
// the side of the box, facing the plane.
SceneLight rect_over_the_turned_plane() {
  auto turn = [](glm::dvec3 v) {
    return glm::dvec3(v.x, 0.5 * v.y - std::sqrt(0.75) * v.z, std::sqrt(0.75) * v.y + 0.5 * v.z);
  };
  SceneLight l;
  l.type = SceneLightType::Rect, l.intensity = 30.0f;
  l.position = turn({0.3, 1.1, 0.1}), l.direction = glm::normalize(turn({-0.2, -1.0, 0.0}));
  l.right = glm::normalize(glm::dvec3(1, 0, 0) - l.direction.x * l.direction), l.up = glm::cross(-l.direction, l.right);
  l.width = 0.6, l.height = 0.4;
  return l;
}

TEST(Shadows, EveryPathGivesTheSameShadows) {
  for (const SceneLight& light : {sun({0.5, -1.0, -0.3}), rect_over_the_turned_plane()}) {
    SCOPED_TRACE(light_type_name(light.type));
    every_path_gives_the_same_shadows(light);
  }
}

void every_path_gives_the_same_shadows(const SceneLight& light) {
  Scene s = box_on_plane_facing_the_camera();
  s.lights = {light};
  Display d;
  const Rig rig = test::subpixel_display_rig(d);
  auto encoded = [&](Sampling sampling, bool fuse, bool shadows) {
    PipelineConfig pc;
    pc.shading = Shading::Pbr, pc.sampling = sampling, pc.fuse_encode = fuse, pc.shadows = shadows;
    return test::render_encoded(s, rig, d, pc);
  };
  const test::EncodedRender unfused = encoded(Sampling::View, false, true), fused = encoded(Sampling::View, true, true),
                            subpixel = encoded(Sampling::Subpixel, true, true),
                            unshadowed = encoded(Sampling::View, true, false);
  ASSERT_TRUE(fused.fused);
  EXPECT_EQ(fused.image, unfused.image);
  size_t differ = 0, darker = 0;
  for (size_t i = 0; i < unfused.image.size(); i += 4) {
    differ += !std::equal(&subpixel.image[i], &subpixel.image[i] + 4, &unfused.image[i]);
    darker += test::half_value(fused.image[i + 1]) < 0.9f * test::half_value(unshadowed.image[i + 1]);
  }
  EXPECT_LE(differ, unfused.image.size() / 4 / 1000);
  EXPECT_GT(darker, 25u) << "the box's shadow should darken the plane (of " << unfused.image.size() / 4 << " pixels)";
  const Rig small = test::small_rig(5, 64, 48);
  std::vector<test::Rendered> methods;
  for (Method m : {Method::Pmr, Method::Duplicate, Method::Multipass}) {
    PipelineConfig pc = test::pbr_config(m, TextureFilter::Bilinear, nullptr);
    pc.shadows = true;
    methods.push_back(test::render_with(s, small, pc));
  }
  for (size_t k = 1; k < methods.size(); ++k) {
    size_t same = 0, covered = 0;
    for (size_t v = 0; v < methods[0].key.size(); ++v) {
      covered += methods[0].key[v] != PMR_NO_KEY;
      if (methods[0].key[v] == PMR_NO_KEY || methods[0].key[v] != methods[k].key[v]) continue;
      for (int c = 0; c < 3; ++c) {
        const float a = test::half_value(methods[0].volume[v * 4 + size_t(c)]);
        const float b = test::half_value(methods[k].volume[v * 4 + size_t(c)]);
        if (k == 1) ASSERT_EQ(a, b) << "duplicate, voxel " << v;
        else ASSERT_NEAR(a, b, 1e-3) << "multipass, voxel " << v;
      }
      ++same;
    }
    EXPECT_GT(same, covered * 9 / 10) << k;
  }
}

// A still frame renders its maps once: a second frame of the same lights and triangles renders none
// and draws the same image; a moved light, or moved triangles, render them again.
TEST(Shadows, MapsAreRenderedAgainOnlyWhenSomethingMoved) {
  Scene s = box_on_plane_facing_the_camera();
  s.lights = {sun({0.5, -1.0, -0.3})};
  const Rig rig = test::small_rig(3, 64, 48);
  PipelineConfig pc = test::pbr_config(Method::Pmr, TextureFilter::Bilinear, nullptr);
  pc.shadows = true;
  Pipeline p(test::runtime(), pc);
  p.set_scene(s);
  p.configure(rig, nullptr);
  std::vector<uint16_t> first, again, moved;
  auto frame = [&](const std::vector<SceneLight>& lights, std::vector<uint16_t>& image) {
    FrameDescription f = describe_frame(rig, lights, pc);
    const StageTimes t = p.render(f);
    p.read_volume(image);
    return t.shadow;
  };
  EXPECT_GT(frame(s.lights, first), 0.0);
  EXPECT_EQ(frame(s.lights, again), 0.0) << "nothing moved: no shadow pass";
  EXPECT_EQ(first, again);
  EXPECT_GT(frame({sun({-0.5, -1.0, -0.3})}, moved), 0.0) << "the light moved";
  EXPECT_NE(first, moved);
  Scene posed = s;
  for (glm::vec3& q : posed.positions) q.x += 0.1f;
  p.update_geometry(posed);
  EXPECT_GT(frame(s.lights, moved), 0.0) << "the triangles moved";
}

// A light's size comes from its extras (Blender's light radius and sun angle): pmr info names it, the
// sidecar records it, and a value out of range is one error line.
TEST(Shadows, LightSizesAreReadFromTheLightsExtras) {
  using namespace test::gltf_builder_detail;
  const std::string dir = test::temp_dir("light_sizes");
  std::filesystem::create_directories(dir);
  auto file = [&](const nlohmann::json& radius, const std::string& name) {
    GltfFile g;
    const int p = g.data<float>({-1, -1, 0, 1, -1, 0, 0, 1, 0}, kFloat, "VEC3");
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", p}}}}}));
    std::vector<int> roots = {g.add("nodes", {{"mesh", 0}})};
    for (int i = 0; i < 2; ++i)
      roots.push_back(
          g.add("nodes", {{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}}));
    g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "point"}, {"intensity", 5.0}, {"extras", {{"pmr_radius", radius}}}},
        {{"type", "directional"}, {"extras", {{"pmr_angle", 0.02}}}}};
    g.scene(roots);
    return g.write(dir, name);
  };
  const test::CliRun info = test::run("info " + file(0.1, "sized"));
  EXPECT_NE(info.output.find("radius 0.1 m (soft shadows)"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("angle 1.14592 deg (soft shadows)"), std::string::npos) << info.output;
  const std::string out = dir + "/out";
  ASSERT_EQ(
      test::run("render " + file(0.1, "sized") + " -q --views 2 --view-size 32x16 --display 64x36 --out " + out).status,
      0);
  const std::string sidecar = test::read_file(out + "/frame_0000.json");
  EXPECT_NE(sidecar.find("\"radius\": 0.1"), std::string::npos);
  EXPECT_NE(sidecar.find("\"angle\": 0.0199999"), std::string::npos) << sidecar;  // 0.02 in single precision
  test::expect_one_error_line(test::run("info " + file(-1.0, "negative")), "extras.pmr_radius must be a number");
  test::expect_one_error_line(test::run("info " + file("big", "text")), "extras.pmr_radius must be a number");
  std::filesystem::remove_all(dir);
}

// The sidecar records the shadows when they are on (their map sizes), and nothing when off, so that a
// sidecar of an older pmr reads as off; --resume compares them.
TEST(Shadows, TheSidecarRecordsThemAndResumeCompares) {
  const std::string out = test::temp_dir("shadows_resume");
  const std::string small = " --views 4 --view-size 48x24 --display 160x90 --environment uniform --out " + out;
  ASSERT_EQ(test::run("render --shadows off" + small).status, 0);
  EXPECT_EQ(test::read_file(out + "/frame_0000.json").find("\"shadows\""), std::string::npos);
  EXPECT_EQ(test::run("render --shadows off --resume" + small).status, 0);
  test::expect_one_error_line(test::run("render --resume" + small), "shading differs");
  ASSERT_EQ(test::run("render --overwrite" + small).status, 0);
  const std::string on = test::read_file(out + "/frame_0000.json");
  EXPECT_NE(on.find("\"map_size\": 2048"), std::string::npos) << on;
  EXPECT_NE(on.find("\"local_map_size\": 1024"), std::string::npos);
  EXPECT_NE(on.find("\"directions\": 64"), std::string::npos) << on;
  EXPECT_EQ(test::run("render --resume" + small).status, 0);
  // the environment's occlusion off is another shading: recorded, and resume tells them apart
  test::expect_one_error_line(test::run("render --resume --environment-occlusion off" + small), "shading differs");
  ASSERT_EQ(test::run("render --overwrite --environment-occlusion off" + small).status, 0);
  const std::string unoccluded = test::read_file(out + "/frame_0000.json");
  EXPECT_NE(unoccluded.find("\"directions\": 0"), std::string::npos) << unoccluded;
  test::expect_usage_error(test::run("render --shadows maybe" + small), "--shadows");
  test::expect_usage_error(test::run("render --environment-occlusion maybe" + small), "--environment-occlusion");
}

}  // namespace
}  // namespace pmr
