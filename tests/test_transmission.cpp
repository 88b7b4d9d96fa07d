// Transmission (DESIGN section 4c step 2: KHR_materials_transmission, KHR_materials_volume and
// KHR_materials_ior) against the double-precision reference (tests/reference/transmission_reference.h)
// and against geometry computed here: a thin pane shows the wall behind it weighted by 1 - F, a thick
// slab shifts the wall by the model's offset in each view, Beer-Lambert's closed form, blur growing with
// roughness, and every rendering path drawing the same glass.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "pbr_support.h"
#include "reference/reference.h"
#include "reference/shade_reference.h"
#include "reference/transmission_reference.h"
#include "shading/environment.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::add_material;
using test::quad;
using test::unlit;

PmrMaterial glass(float roughness, float ior, float thickness) {
  PmrMaterial m = default_material();
  m.metallic = 0.0f, m.roughness = roughness, m.transmission = 1.0f;
  m.ior = ior, m.f0_dielectric = dielectric_f0(ior), m.thickness = thickness;
  return m;
}

constexpr float kWallZ = -0.5f, kGlassZ = 0.3f;

PipelineConfig pbr_config(const std::shared_ptr<const Environment>& env = nullptr) {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.shading = Shading::Pbr;
  pc.environment = env;
  if (env) pc.environment_intensity = env->tables().header.intensity;
  return pc;
}

float channel(const std::vector<uint16_t>& image, size_t pixel, int c) {
  return test::half_value(image[pixel * 4 + size_t(c)]);
}

// Raster position of a world point in view `view` (the reference's snapped vertex, in pixels).
glm::dvec2 raster_of(const PmrParams& P, const glm::dvec3& world, int view) {
  const float w[3] = {float(world.x), float(world.y), float(world.z)};
  const PmrVertex v = ref::transform_vertex(P, w);
  const double x = (double(v.x0) + double(P.view_coord[view]) * double(v.dx)) / PMR_X_ONE;
  return {x, double(v.y) / PMR_Y_ONE};
}

// The world point at depth z that view `view` shows at raster position r (Newton on the projection).
glm::dvec3 on_plane(const PmrParams& P, const glm::dvec2& r, double z, int view) {
  glm::dvec2 q(0.0);
  for (int it = 0; it < 40; ++it) {
    const glm::dvec2 e = raster_of(P, {q.x, q.y, z}, view) - r;
    if (glm::length(e) < 1e-5) break;
    const double h = 1e-3;
    const glm::dvec2 jx = (raster_of(P, {q.x + h, q.y, z}, view) - raster_of(P, {q.x - h, q.y, z}, view)) / (2 * h);
    const glm::dvec2 jy = (raster_of(P, {q.x, q.y + h, z}, view) - raster_of(P, {q.x, q.y - h, z}, view)) / (2 * h);
    const double det = jx.x * jy.y - jy.x * jx.y;
    q -= glm::dvec2(jy.y * e.x - jy.x * e.y, -jx.y * e.x + jx.x * e.y) / det;
  }
  return {q.x, q.y, z};
}

// Smallest x in [lo, hi] with f(x) >= 0 for an increasing f (bisection).
template <class F>
double crossing(F f, double lo, double hi) {
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) >= 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

bool uniform_around(const std::vector<uint16_t>& volume, const Rig& rig, size_t v, int radius) {
  const int W = rig.view_w, H = rig.view_h, px = int(v % size_t(W)), py = int((v / size_t(W)) % size_t(H));
  const size_t base = v - size_t(py * W + px);
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int x = px + dx, y = py + dy;
      if (x < 0 || y < 0 || x >= W || y >= H) return false;
      for (int c = 0; c < 4; ++c)
        if (volume[(base + size_t(y * W + x)) * 4 + size_t(c)] != volume[v * 4 + size_t(c)]) return false;
    }
  return true;
}

// Every voxel whose winner is one of the glass's triangles (index >= first_glass) against the reference,
// where fill(v, view, triangle, sp) gives the light through it (sp.through, sp.attenuation); voxels it refuses
// (false) are left out. Returns the number compared; *worst the largest error as a fraction of the bound.
template <class Fill>
size_t compare_glass(const Scene& s, const Rig& rig, const test::Rendered& out, uint32_t first_glass, Fill fill,
                     const ref::EnvironmentTerms& env, const std::vector<ref::PunctualLight>& lights, double* worst) {
  std::multimap<uint32_t, PmrMta> by_key;
  for (const PmrMta& m : out.mtas) by_key.emplace(m.key, m);
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  test::BoundCheck check;
  size_t compared = 0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY || (out.key[v] >> PMR_KEY_SUB_BITS) < first_glass) continue;
    const int view = int(v / (W * H));
    const PmrMta* m = nullptr;
    auto range = by_key.equal_range(out.key[v]);
    for (auto it = range.first; it != range.second; ++it)
      if (view >= it->second.view_lo && view <= it->second.view_hi) m = &it->second;
    if (!m) {
      ADD_FAILURE() << "no MTA for voxel " << v;
      continue;
    }
    const glm::dvec3 b = ref::source_barycentrics(*m, int(v % W), int((v / W) % H), view);
    ref::SurfacePoint sp = test::surface_at(s, rig, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, view);
    if (!fill(v, view, m->tri, sp)) continue;
    check.voxel(out, v, ref::pbr_color(sp, lights, env, 1.0), "glass voxel");
    ++compared;
  }
  *worst = check.worst;
  EXPECT_EQ(check.bad, 0u);
  return compared;
}

// A fill for compare_glass: the light through is f(the wall's colour at the voxel in a render without
// the glass), where that wall is uniform nearby (the source's taps all see it).
template <class F>
auto wall_behind(const test::Rendered& wall, const Rig& rig, F f) {
  return [&wall, &rig, f](size_t v, int, uint32_t, ref::SurfacePoint& sp) {
    if (!uniform_around(wall.volume, rig, v, 2)) return false;
    sp.through = f(glm::dvec3(channel(wall.volume, v, 0), channel(wall.volume, v, 1), channel(wall.volume, v, 2)));
    return true;
  };
}

Scene two_tone_wall(float split_x) {
  Scene s = test::empty_scene(true);
  const uint32_t dark = add_material(s, unlit({0.8f, 0.3f, 0.1f})), light = add_material(s, unlit({0.1f, 0.4f, 0.9f}));
  quad(s, -4.0f, -4.0f, split_x, 4.0f, kWallZ, dark);
  quad(s, split_x, -4.0f, 4.0f, 4.0f, kWallZ, light);
  return s;
}

// A thin pane (ior 1.5, roughness 0, transmission 1) in front of a two-coloured wall: every pane voxel
// is (1 - (F0 A + B)) x the wall behind it plus the reflections, as the reference computes them, within
// 1% + 1e-3 (the source is the wall's own image: sampled at the voxel's own position, a thin pane does
// not bend the ray).
TEST(Transmission, AThinPaneShowsTheWallWeightedByOneMinusFresnel) {
  const Rig rig = test::small_rig(5, 48, 32);
  const Scene wall_only = two_tone_wall(0.1f);
  Scene s = wall_only;
  const uint32_t first_glass = uint32_t(s.triangles.size());
  quad(s, -0.6f, -0.5f, 0.6f, 0.5f, kGlassZ, add_material(s, glass(0.0f, 1.5f, 0.0f)));
  const test::Rendered out = test::render_with(s, rig, pbr_config()),
                       wall = test::render_with(wall_only, rig, pbr_config());
  double worst = 0.0;
  const size_t n =
      compare_glass(s, rig, out, first_glass, wall_behind(wall, rig, [](const glm::dvec3& c) { return c; }),
                    test::uniform_environment(0.2), test::default_light(rig), &worst);
  std::printf("[ glass    ] thin pane: %zu voxels, largest error %.3f of the bound\n", n, worst);
  EXPECT_GT(n, size_t(300));
}

// Clear glass over a transparent background (DESIGN 4c; --background none, the default): where a thin
// pane sees past the scene, the environment is not drawn and alpha falls to about 1 - transmission x
// (1 - F) (F ~ 0.04 at ior 1.5), so a panel's black or a plate shows through; where a wall is behind
// it, the pane is what it was, alpha 1, bit for bit.
TEST(Transmission, ClearGlassLetsTheBackgroundThroughWhereItSeesPastTheScene) {
  const Rig rig = test::small_rig(5, 48, 32);
  Scene wall_only = test::empty_scene(true);
  quad(wall_only, -4.0f, -4.0f, 0.0f, 4.0f, kWallZ, add_material(wall_only, unlit({0.8f, 0.3f, 0.1f})));
  Scene s = wall_only;
  PmrMaterial pane = glass(0.0f, 1.5f, 0.0f);
  pane.transmission = 0.8f;
  quad(s, -0.8f, -0.5f, 0.8f, 0.5f, kGlassZ, add_material(s, pane));
  PipelineConfig clear = pbr_config();
  clear.clear_glass = true;
  const test::Rendered drawn = test::render_with(s, rig, pbr_config()), see_through = test::render_with(s, rig, clear),
                       wall = test::render_with(wall_only, rig, pbr_config());
  size_t over_wall = 0, over_nothing = 0;
  double lo = 1.0, hi = 0.0;
  for (size_t p = 0; p < drawn.key.size(); ++p) {
    if (drawn.key[p] == PMR_NO_KEY || channel(drawn.volume, p, 3) != 1.0f) continue;
    const bool glass_here = drawn.key[p] != wall.key[p];
    if (!glass_here) continue;
    const size_t w = size_t(rig.view_w), x = p % w;
    const bool wall_around = x > 1 && x + 2 < w && channel(wall.volume, p - 2, 3) == 1.0f &&
                             channel(wall.volume, p + 2, 3) == 1.0f;  // the source's filter stays on the wall
    if (wall_around && channel(wall.volume, p, 3) == 1.0f) {          // the wall behind: nothing changes
      ++over_wall;
      for (int c = 0; c < 4; ++c) ASSERT_EQ(see_through.volume[p * 4 + size_t(c)], drawn.volume[p * 4 + size_t(c)]);
    } else if (wall.key[p] == PMR_NO_KEY) {  // nothing behind: the background shows through
      ++over_nothing;
      const double a = channel(see_through.volume, p, 3);
      lo = std::min(lo, a), hi = std::max(hi, a);
      ASSERT_LT(channel(see_through.volume, p, 1), channel(drawn.volume, p, 1)) << "the environment is not drawn";
    }
  }
  std::printf("[ glass    ] clear pane: %zu voxels over the wall, %zu over nothing (alpha %.3f to %.3f)\n", over_wall,
              over_nothing, lo, hi);
  EXPECT_GT(over_wall, size_t(200));
  EXPECT_GT(over_nothing, size_t(200));
  // 1 - T (1 - R): R = F0 A + B of the split sum, 0.04 head-on at ior 1.5 and more in the outer views
  EXPECT_GE(lo, 1.0 - 0.8 * 0.97);
  EXPECT_LE(hi, 1.0 - 0.8 * 0.85);
}

// Rough and thick glass over a striped wall, every glass voxel against the reference (roughness >= 0.2,
// DESIGN 4c): the reference draws the wall's views itself (its rasterizer, the unlit colours), builds
// their mip chains in double precision, follows each voxel's refracted ray and reads its source
// trilinearly (tests/reference/transmission_reference.h); within 1% + 1e-3 per channel.
TEST(Transmission, RoughAndThickGlassAgainstTheReferenceInEveryVoxel) {
  const Rig rig = test::small_rig(3, 64, 40);
  const auto env = std::make_shared<const Environment>(Environment::uniform(0.2));
  Scene wall_only = test::empty_scene(true);
  const glm::vec3 colours[2] = {{0.9f, 0.6f, 0.2f}, {0.1f, 0.3f, 0.8f}};
  const uint32_t stripe[2] = {add_material(wall_only, unlit(colours[0])), add_material(wall_only, unlit(colours[1]))};
  for (int k = -20; k < 20; ++k) quad(wall_only, 0.15f * k, -4.0f, 0.15f * (k + 1), 4.0f, kWallZ, stripe[k & 1]);
  Scene s = wall_only;
  const uint32_t first_glass = uint32_t(s.triangles.size());
  quad(s, -0.9f, -0.5f, -0.05f, 0.5f, kGlassZ, add_material(s, glass(0.25f, 1.5f, 0.0f)));
  PmrMaterial thick = glass(0.6f, 1.3f, 0.3f);
  thick.attenuation_distance = 0.5f;
  thick.attenuation_color[0] = 0.8f, thick.attenuation_color[1] = 0.6f, thick.attenuation_color[2] = 0.9f;
  quad(s, 0.05f, -0.5f, 0.9f, 0.5f, kGlassZ, add_material(s, thick));
  const test::Rendered out = test::render_with(s, rig, pbr_config(env));
  // the reference's sources: each view of the wall, a pixel the unlit colour of its triangle's material
  PmrParams P = test::params_for(rig);
  set_sample_pattern(1, P);
  const ref::RasterResult wall = ref::render(P, wall_only);
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  std::vector<ref::SourceImage> sources;
  for (int view = 0; view < rig.views; ++view) {
    std::vector<glm::dvec4> image(W * H, glm::dvec4(0.0));
    for (size_t p = 0; p < W * H; ++p) {
      const uint32_t key = wall.key[size_t(view) * W * H + p];
      if (key == PMR_NO_KEY) continue;
      const float* c = wall_only.materials[wall_only.triangles[key >> PMR_KEY_SUB_BITS].material].base_color;
      image[p] = glm::dvec4(c[0], c[1], c[2], 1.0);
    }
    sources.push_back(ref::make_source(int(W), int(H), image));
  }
  auto fill = [&](size_t, int view, uint32_t tri, ref::SurfacePoint& sp) {
    const PmrMaterial& m = s.materials[s.triangles[tri].material];
    const glm::dvec3 v = glm::normalize(sp.eye - sp.p);
    const double r = std::clamp(sp.roughness, 0.03, 1.0);
    const ref::TransmissionRay ray = ref::transmission_ray(sp.p, sp.n, v, sp.ior, m.thickness);
    const glm::dvec4 src =
        sample_source(sources[size_t(view)], raster_of(P, ray.end, view), ref::transmission_lod(rig.view_w, r, sp.ior));
    const glm::dvec3 color(m.attenuation_color[0], m.attenuation_color[1], m.attenuation_color[2]);
    sp.attenuation = ref::beer_lambert(glm::dvec3(1.0), color, ray.distance, m.attenuation_distance);
    sp.through = sp.attenuation * (glm::dvec3(src) + (1.0 - src.a) * 0.2);
    return true;
  };
  double worst = 0.0;
  const size_t n = compare_glass(s, rig, out, first_glass, fill, test::uniform_environment(0.2), {}, &worst);
  std::printf("[ glass    ] rough and thick glass over stripes: %zu voxels, largest error %.3f of the bound\n", n,
              worst);
  EXPECT_GT(n, size_t(500));
}

// A point light behind a rough pane (roughness 0.4, ior 1.5) shows through it as a highlight: the
// KHR_materials_transmission BTDF about the light mirrored on the pane (tests/reference btdf_light);
// every pane voxel within 1% + 1e-3 of the reference, and the light's share is large somewhere.
TEST(Transmission, ALightBehindGlassShinesThroughIt) {
  const Rig rig = test::small_rig(5, 48, 32);
  const auto env = std::make_shared<const Environment>(Environment::uniform(0.2));
  Scene wall_only = test::empty_scene(true);
  quad(wall_only, -4.0f, -4.0f, 4.0f, 4.0f, kWallZ, add_material(wall_only, unlit({0.3f, 0.3f, 0.3f})));
  SceneLight light;
  light.type = SceneLightType::Point;
  light.intensity = 3.0f;
  light.position = glm::dvec3(0.1, 0.05, 0.0);  // between the wall and the pane
  wall_only.lights.push_back(light);
  Scene s = wall_only;
  const uint32_t first_glass = uint32_t(s.triangles.size());
  quad(s, -0.7f, -0.5f, 0.7f, 0.5f, kGlassZ, add_material(s, glass(0.4f, 1.5f, 0.0f)));
  const test::Rendered out = test::render_with(s, rig, pbr_config(env)),
                       wall = test::render_with(wall_only, rig, pbr_config(env));
  ref::PunctualLight point;
  point.type = ref::LightType::Point;
  point.position = light.position;
  point.color_intensity = glm::dvec3(3.0);
  double worst = 0.0;
  const size_t n =
      compare_glass(s, rig, out, first_glass, wall_behind(wall, rig, [](const glm::dvec3& c) { return c; }),
                    test::uniform_environment(0.2), {point}, &worst);
  std::printf("[ glass    ] a light behind a rough pane: %zu voxels, largest error %.3f of the bound\n", n, worst);
  EXPECT_GT(n, size_t(300));
  double brightest = 0.0;  // the highlight through the pane: well above the wall's 0.3 times 1 - F
  for (size_t v = 0; v < out.key.size(); ++v)
    if (out.key[v] != PMR_NO_KEY && (out.key[v] >> PMR_KEY_SUB_BITS) >= first_glass)
      brightest = std::max(brightest, double(channel(out.volume, v, 0)));
  EXPECT_GT(brightest, 1.0);
}

// Beer-Lambert: a slab of thickness 0.5 with attenuationColor c and attenuationDistance 0.25 (ior 1: no
// bending, so each voxel sees the wall straight behind it) transmits the wall times c^2, the closed form.
TEST(Transmission, VolumeAttenuationFollowsBeerLambert) {
  const Rig rig = test::small_rig(3, 40, 24);
  const auto env = std::make_shared<const Environment>(Environment::uniform(0.2));
  Scene wall_only = test::empty_scene(true);
  quad(wall_only, -4.0f, -4.0f, 4.0f, 4.0f, kWallZ, add_material(wall_only, unlit({0.6f, 0.7f, 0.8f})));
  for (const glm::dvec3 c : {glm::dvec3(0.9, 0.5, 0.2), glm::dvec3(1.0, 0.25, 0.0)}) {
    Scene s = wall_only;
    const uint32_t first_glass = uint32_t(s.triangles.size());
    PmrMaterial g = glass(0.3f, 1.0f, 0.5f);
    g.attenuation_distance = 0.25f;
    for (int k = 0; k < 3; ++k) g.attenuation_color[k] = float(c[k]);
    quad(s, -0.7f, -0.5f, 0.7f, 0.5f, kGlassZ, add_material(s, g));
    const test::Rendered out = test::render_with(s, rig, pbr_config(env)),
                         wall = test::render_with(wall_only, rig, pbr_config(env));
    double worst = 0.0;
    const size_t n =
        compare_glass(s, rig, out, first_glass,
                      wall_behind(wall, rig,
                                  [&](const glm::dvec3& behind) {
                                    EXPECT_NEAR(ref::beer_lambert(behind, c, 0.5, 0.25).y, behind.y * c.y * c.y,
                                                1e-12);  // c^(0.5/0.25)
                                    return ref::beer_lambert(behind, c, 0.5, 0.25);
                                  }),
                      test::uniform_environment(0.2), {}, &worst);
    std::printf("[ glass    ] attenuation (%.2f, %.2f, %.2f): %zu voxels, largest error %.3f of the bound\n", c.x, c.y,
                c.z, n, worst);
    EXPECT_GT(n, size_t(200));
  }
}

// Where row `py` of view `view` crosses from the wall's dark to its bright side, measured in the glass's
// voxels: the pixel-center x where red passes the mean of the row's two ends (linear between centers);
// -1 when the row shows no crossing.
double measured_crossing(const test::Rendered& out, const Rig& rig, int view, int py, uint32_t first_glass) {
  const size_t W = size_t(rig.view_w), row = (size_t(view) * size_t(rig.view_h) + size_t(py)) * W;
  std::vector<double> red;
  std::vector<int> xs;
  for (size_t x = 0; x < W; ++x)
    if (out.key[row + x] != PMR_NO_KEY && (out.key[row + x] >> PMR_KEY_SUB_BITS) >= first_glass)
      red.push_back(channel(out.volume, row + x, 2)), xs.push_back(int(x));
  if (red.size() < 8) return -1.0;
  const double mid = 0.5 * (red.front() + red.back());
  for (size_t k = 0; k + 1 < red.size(); ++k)
    if (red[k] < mid && red[k + 1] >= mid) return xs[k] + 0.5 + (mid - red[k]) / (red[k + 1] - red[k]);
  return -1.0;
}

// A thick slab (ior 1.5, thicknessFactor 0.7, roughness 0) in front of a wall whose colour changes at
// x = 0.7: in views 0, N/2 and N-1 the change appears where 4c's model puts it (the view ray refracted at
// the slab's face, 0.7 along it, the end point's own view position), computed here in double precision,
// within a pixel; the shift from where the wall shows without the slab differs between the views as
// predicted. The physical slab (the ray leaving its back face parallel to the view ray) is printed next
// to it: how far the model's offset is from the physical one.
TEST(Transmission, AThickSlabShiftsTheWallByTheModelsOffsetInEachView) {
  const Rig rig = test::small_rig(9, 128, 48);
  const PmrParams P = test::params_for(rig);
  const double split = 0.7, thickness = 0.7, ior = 1.5;
  Scene s = two_tone_wall(float(split));
  const uint32_t first_glass = uint32_t(s.triangles.size());
  quad(s, -1.2f, -0.4f, 1.2f, 0.4f, kGlassZ, add_material(s, glass(0.0f, float(ior), float(thickness))));
  const auto env = std::make_shared<const Environment>(Environment::uniform(0.2));
  const test::Rendered out = test::render_with(s, rig, pbr_config(env));
  const int py = rig.view_h / 2;
  double shift[3] = {}, predicted_shift[3] = {};
  const int views[3] = {0, rig.views / 2, rig.views - 1};
  for (int k = 0; k < 3; ++k) {
    const int view = views[k];
    const glm::dvec3 eye = glm::dvec3(glm::inverse(rig.view_matrix(view))[3]);
    const glm::dvec3 n(0.0, 0.0, 1.0);
    // the wall's x seen at raster x of the row: through the model's slab, the physical slab, no slab
    auto model = [&](double x) {
      const glm::dvec3 p = on_plane(P, {x, py + 0.5}, kGlassZ, view), v = glm::normalize(eye - p);
      const ref::TransmissionRay ray = ref::transmission_ray(p, n, v, ior, thickness);
      return on_plane(P, raster_of(P, ray.end, view), kWallZ, view).x - split;
    };
    auto physical = [&](double x) {
      const glm::dvec3 p = on_plane(P, {x, py + 0.5}, kGlassZ, view), v = glm::normalize(eye - p);
      const glm::dvec3 d = ref::transmission_ray(p, n, v, ior, thickness).direction;
      const glm::dvec3 exit = p + d * (thickness / std::abs(d.z));
      return (exit + (-v) * ((exit.z - kWallZ) / v.z)).x - split;
    };
    auto direct = [&](double x) { return on_plane(P, {x, py + 0.5}, kWallZ, view).x - split; };
    const double W = rig.view_w;
    const double want = crossing(model, 0.0, W), phys = crossing(physical, 0.0, W), bare = crossing(direct, 0.0, W);
    const double got = measured_crossing(out, rig, view, py, first_glass);
    std::printf(
        "[ glass    ] view %d: the wall's edge at x %.2f through the slab (model %.2f, physical %.2f, "
        "without the slab %.2f)\n",
        view, got, want, phys, bare);
    EXPECT_NEAR(got, want, 1.0) << "view " << view;
    shift[k] = got - bare, predicted_shift[k] = want - bare;
    if (k != 1) {
      EXPECT_GT(std::abs(predicted_shift[k]), 2.0) << "the slab should visibly shift the wall in view " << view;
    }
  }
  EXPECT_GT(std::abs(predicted_shift[0] - predicted_shift[2]), 1.0) << "the views should see different shifts";
  EXPECT_NEAR(shift[0] - shift[2], predicted_shift[0] - predicted_shift[2], 1.0);
  EXPECT_NEAR(shift[1] - shift[2], predicted_shift[1] - predicted_shift[2], 1.0);
}

// Rough transmission blurs more as roughness grows (the source's mips, DESIGN 4c): four panes of
// roughness 0, 0.3, 0.6 and 1 over a striped wall; the stripes' contrast through them falls strictly,
// from clearly visible to nearly flat.
TEST(Transmission, RoughTransmissionBlursMonotonicallyWithRoughness) {
  const Rig rig = test::small_rig(3, 192, 96);
  Scene s = test::empty_scene(true);
  const uint32_t dark = add_material(s, unlit({0.1f, 0.1f, 0.1f})), light = add_material(s, unlit({0.9f, 0.9f, 0.9f}));
  for (int k = -30; k < 30; ++k) quad(s, 0.1f * k, -4.0f, 0.1f * (k + 1), 4.0f, kWallZ, (k & 1) ? dark : light);
  const float roughness[4] = {0.0f, 0.3f, 0.6f, 1.0f};
  uint32_t first[5];
  for (int k = 0; k < 4; ++k) {
    first[k] = uint32_t(s.triangles.size());
    const float x0 = -1.0f + 0.5f * float(k);
    quad(s, x0, -0.5f, x0 + 0.45f, 0.5f, kGlassZ, add_material(s, glass(roughness[k], 1.5f, 0.0f)));
  }
  first[4] = uint32_t(s.triangles.size());
  const auto env = std::make_shared<const Environment>(Environment::uniform(0.2));
  const test::Rendered out = test::render_with(s, rig, pbr_config(env));
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h), base = size_t(rig.views / 2) * W * H;
  double spread[4];
  for (int k = 0; k < 4; ++k) {
    double lo = 1e9, hi = -1e9;
    size_t n = 0;
    for (size_t y = 2; y + 2 < H; ++y)
      for (size_t x = 2; x + 2 < W; ++x) {
        bool inside = true;  // the pane's voxel with its 5x5 neighbourhood
        for (int dy = -2; dy <= 2 && inside; ++dy)
          for (int dx = -2; dx <= 2 && inside; ++dx) {
            const uint32_t key = out.key[base + (y + size_t(dy)) * W + x + size_t(dx)];
            inside =
                key != PMR_NO_KEY && (key >> PMR_KEY_SUB_BITS) >= first[k] && (key >> PMR_KEY_SUB_BITS) < first[k + 1];
          }
        if (!inside) continue;
        const double r = channel(out.volume, base + y * W + x, 0);
        lo = std::min(lo, r), hi = std::max(hi, r), ++n;
      }
    ASSERT_GT(n, size_t(50)) << "pane " << k;
    spread[k] = hi - lo;
    std::printf("[ glass    ] roughness %.1f: the stripes' contrast through the pane %.4f\n", roughness[k], spread[k]);
  }
  EXPECT_GT(spread[0], 0.5);
  for (int k = 1; k < 4; ++k) EXPECT_LT(spread[k], spread[k - 1]) << "roughness " << roughness[k];
  EXPECT_LT(spread[3], 0.02);
}

// Volume values at the ends of the float range (an infinite thickness, a vanishing attenuation distance,
// a colour channel of 0) give finite colours: the walk stays finite, the attenuation goes to 0 or 1.
TEST(Transmission, ExtremeVolumeValuesGiveFiniteColours) {
  const Rig rig = test::small_rig(3, 32, 20);
  Scene s = test::empty_scene(true);
  quad(s, -4.0f, -4.0f, 4.0f, 4.0f, kWallZ, add_material(s, unlit({0.6f, 0.7f, 0.8f})));
  PmrMaterial g = glass(0.5f, 1.5f, std::numeric_limits<float>::infinity());
  g.attenuation_distance = 1e-30f;
  g.attenuation_color[0] = 0.5f, g.attenuation_color[1] = 1.0f, g.attenuation_color[2] = 0.0f;
  quad(s, -0.7f, -0.5f, 0.7f, 0.5f, kGlassZ, add_material(s, g));
  PmrMaterial huge = glass(0.2f, 2.0f, 3e38f);
  quad(s, -0.5f, -0.3f, 0.5f, 0.3f, 0.5f, add_material(s, huge));
  const test::Rendered out = test::render_with(s, rig, pbr_config());
  size_t glass_voxels = 0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(channel(out.volume, v, c))) << "voxel " << v;
    glass_voxels += out.key[v] != PMR_NO_KEY && (out.key[v] >> PMR_KEY_SUB_BITS) >= 2;
  }
  EXPECT_GT(glass_voxels, size_t(100));
}

// Every path draws the same glass: a thin pane in front of a wall, both covering every view. The fused
// raster + encode gives the bytes of raster-then-encode; --sampling subpixel (its own source pass on
// the view raster), the multipass and duplicate baselines agree with PMR within 1% + 2e-3.
TEST(Transmission, EveryPathDrawsTheGlass) {
  Display d;
  d.width = 120, d.height = 60;
  RigConfig rc;
  rc.views = 8, rc.view_w = 64, rc.view_h = 32;
  const Rig rig = make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
  Scene s = test::empty_scene(true);
  quad(s, -9.0f, -9.0f, 9.0f, 9.0f, kWallZ, add_material(s, unlit({0.6f, 0.7f, 0.8f})));
  quad(s, -9.0f, -9.0f, 9.0f, 9.0f, kGlassZ, add_material(s, glass(0.4f, 1.5f, 0.2f)));
  PipelineConfig pc = pbr_config();
  pc.fuse_encode = false;
  const test::EncodedRender unfused = test::render_encoded(s, rig, d, pc);
  pc.fuse_encode = true;
  const test::EncodedRender fused = test::render_encoded(s, rig, d, pc);
  ASSERT_TRUE(fused.fused);
  ASSERT_EQ(fused.image, unfused.image) << "fused raster + encode";
  pc.sampling = Sampling::Subpixel;
  const test::EncodedRender subpixel = test::render_encoded(s, rig, d, pc);
  // (near the image's border the refracted ray of a sample may leave the raster and see the environment:
  // subpixel samples lie elsewhere than pixel centers, so the border is left out)
  size_t compared = 0;
  for (size_t p = 0; p < unfused.image.size() / 4; ++p) {
    const int x = int(p % size_t(d.width)), y = int(p / size_t(d.width));
    if (x < 10 || y < 10 || x >= d.width - 10 || y >= d.height - 10) continue;
    for (int c = 0; c < 4; ++c) {
      const float want = channel(unfused.image, p, c), got = channel(subpixel.image, p, c);
      ASSERT_NEAR(got, want, 0.01 * want + 2e-3) << "subpixel sampling, display pixel " << p << " channel " << c;
    }
    ASSERT_GT(channel(unfused.image, p, 0), 0.4f) << "the wall through the pane, display pixel " << p;
    ++compared;
  }
  EXPECT_GT(compared, size_t(3000));
  const test::Rendered pmr = test::render_with(s, rig, pbr_config());
  for (Method method : {Method::Multipass, Method::Duplicate}) {
    PipelineConfig mc = pbr_config();
    mc.method = method;
    const test::Rendered other = test::render_with(s, rig, mc);
    ASSERT_EQ(other.volume.size(), pmr.volume.size());
    for (size_t i = 0; i < pmr.volume.size(); ++i) {
      const float want = test::half_value(pmr.volume[i]), got = test::half_value(other.volume[i]);
      ASSERT_NEAR(got, want, 0.01 * want + 2e-3) << to_string(method) << " value " << i;
    }
  }
}

// ../shared/gltf's transmission and volume models load without a warning about either extension, and
// their glass is drawn as glass: the render differs from the same scene with transmission turned off.
TEST(TransmissionCorpus, TheKhronosGlassModelsDrawTheirGlass) {
  const std::string corpus = test::corpus_dir();
  if (corpus.empty()) GTEST_SKIP() << "../shared/gltf not found: the corpus's glass models are not rendered";
  const char* files[] = {"TransmissionTest/glTF-Binary/TransmissionTest.glb",
                         "TransmissionRoughnessTest/glTF/TransmissionRoughnessTest.gltf",
                         "AttenuationTest/glTF/AttenuationTest.gltf",
                         "GlassHurricaneCandleHolder/glTF/GlassHurricaneCandleHolder.gltf",
                         "IridescenceSuzanne/glTF/IridescenceSuzanne.gltf"};
  for (const char* file : files) {
    SCOPED_TRACE(file);
    const Scene scene = load_scene(corpus + "/" + file);
    for (const std::string& w : scene.warnings) {
      EXPECT_EQ(w.find("KHR_materials_transmission"), std::string::npos) << w;
      EXPECT_EQ(w.find("KHR_materials_volume"), std::string::npos) << w;
    }
    Scene opaque = scene;
    size_t glass = 0;
    for (PmrMaterial& m : opaque.materials) glass += m.transmission > 0.0f, m.transmission = 0.0f;
    for (SceneMaterialInputs& m : opaque.material_inputs) m.transmission = 0.0f;
    EXPECT_GT(glass, 0u) << "a transmissive material";
    glm::dvec3 lo, hi;
    scene_bounds(scene, lo, hi);
    RigConfig rc;
    rc.views = 3, rc.view_w = 96, rc.view_h = 64;
    const Rig rig = make_rig(rc, Display{}, lo, hi);
    const test::Rendered a = test::render_with(scene, rig, pbr_config()),
                         b = test::render_with(opaque, rig, pbr_config());
    size_t differ = 0;
    for (size_t i = 0; i < a.volume.size(); ++i) differ += a.volume[i] != b.volume[i];
    EXPECT_GT(differ, a.volume.size() / 200) << "the glass should look different from opaque";
  }
}

// The transmission source is budgeted before anything is allocated or written: a glass scene whose
// frame would fit the memory budget without it is refused with one line naming it.
TEST(TransmissionCorpus, TheSourceIsUnderTheMemoryBudget) {
  const std::string corpus = test::corpus_dir();
  if (corpus.empty()) GTEST_SKIP() << "../shared/gltf not found: the glass model is not rendered";
  const std::string out = test::temp_dir("glass_budget");
  const test::CliRun r = test::run("render '" + corpus +
                                   "/GlassHurricaneCandleHolder/glTF/GlassHurricaneCandleHolder.gltf' --limit "
                                   "memory=2300M --out '" +
                                   out + "/x'");
  test::expect_one_error_line(r, "a 512 MiB transmission source for the glass");
  EXPECT_FALSE(test::exists(out + "/x"));
}

}  // namespace
}  // namespace pmr
