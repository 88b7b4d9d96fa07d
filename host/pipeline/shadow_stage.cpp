#include "pipeline/shadow_stage.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "pipeline/scene_buffers.h"
#include "shading/environment_occlusion.h"
#include "pmr/error.h"

namespace pmr {

namespace {

// A unit vector orthogonal to unit `a`, and the third of a right-handed frame (x, y, a).
void frame_about(const glm::dvec3& a, glm::dvec3& x, glm::dvec3& y) {
  const glm::dvec3 helper = std::abs(a.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
  x = glm::normalize(glm::cross(helper, a));
  y = glm::cross(a, x);
}

void set3(float* out, const glm::dvec3& v) { out[0] = float(v.x), out[1] = float(v.y), out[2] = float(v.z); }

std::vector<glm::dvec3> corners(const glm::dvec3& lo, const glm::dvec3& hi) {
  std::vector<glm::dvec3> c;
  for (int k = 0; k < 8; ++k) c.push_back(glm::dvec3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z));
  return c;
}

// An orthographic map along `axis` over the box: square texels, half a texel's margin beyond the box
// on each side, the origin on the box's near face (every depth >= 0).
PmrShadowMap orthographic_map(const glm::dvec3& axis, const glm::dvec3& lo, const glm::dvec3& hi, int size) {
  glm::dvec3 x, y;
  frame_about(axis, x, y);
  glm::dvec3 mn(1e300), mx(-1e300);
  for (const glm::dvec3& c : corners(lo, hi)) {
    const glm::dvec3 q(glm::dot(c, x), glm::dot(c, y), glm::dot(c, axis));
    mn = glm::min(mn, q), mx = glm::max(mx, q);
  }
  const double half = std::max({0.5 * (mx.x - mn.x), 0.5 * (mx.y - mn.y), 1e-6}) * (1.0 + 2.0 / size);
  const glm::dvec3 origin = x * (0.5 * (mn.x + mx.x)) + y * (0.5 * (mn.y + mx.y)) + axis * (mn.z - 1e-3 * half);
  PmrShadowMap m{};
  set3(m.origin, origin), set3(m.right, x / half), set3(m.up, y / half), set3(m.axis, axis);
  m.size = size, m.perspective = 0, m.texel = float(2.0 * half / size);
  m.translucent = PMR_NO_TRANSLUCENT, m.weight = 1.0f;
  return m;
}

// A perspective map from `origin` along `axis`, tan(half angle) = t.
PmrShadowMap perspective_map(const glm::dvec3& origin, const glm::dvec3& axis, const glm::dvec3& x, double t,
                             double near_z, int size) {
  const glm::dvec3 y = glm::cross(axis, x);
  PmrShadowMap m{};
  set3(m.origin, origin), set3(m.right, x / t), set3(m.up, y / t), set3(m.axis, axis);
  m.size = size, m.perspective = 1, m.texel = float(2.0 * t / size), m.near_z = float(near_z);
  m.translucent = PMR_NO_TRANSLUCENT, m.weight = 1.0f;
  return m;
}

// The maps of a point or spot light seen from `origin` (spot: along `direction`, outer cone angle
// `outer`): one perspective map over a cone of at most kSpotSingleMapAngle, else a cube.
void local_maps(const SceneLight& l, const glm::dvec3& origin, const glm::dvec3& lo, const glm::dvec3& hi, int size,
                std::vector<PmrShadowMap>& maps) {
  double far = 0.0;
  for (const glm::dvec3& c : corners(lo, hi)) far = std::max(far, glm::length(c - origin));
  const double near_z = std::max(far, 1e-6) * 1e-4;
  if (l.type == SceneLightType::Spot && l.outer_cone <= kSpotSingleMapAngle) {
    glm::dvec3 x, y;
    frame_about(l.direction, x, y);
    // two texels' margin beyond the cone, for the filter's taps at its edge
    const double t = std::tan(double(l.outer_cone)) * (1.0 + 4.0 / size);
    maps.push_back(perspective_map(origin, l.direction, x, t, near_z, size));
    return;
  }
  // a cube: +X, -X, +Y, -Y, +Z, -Z (cl/lights.h picks the face of the major axis)
  const glm::dvec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const glm::dvec3 rights[6] = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {-1, 0, 0}};
  for (int f = 0; f < 6; ++f)
    maps.push_back(perspective_map(origin, axes[f], rights[f], 1.0 + 4.0 / size, near_z, size));
}

// Sample i of k on the unit disk, uniform in area (Vogel's spiral: radius sqrt((i + 1/2) / k), turned
// by the golden angle).
glm::dvec2 disk_sample(int i, int k) {
  const double r = std::sqrt((i + 0.5) / k), a = i * 2.399963229728653;
  return {r * std::cos(a), r * std::sin(a)};
}

// Sample i of k in the unit ball with density proportional to 1 / sqrt(1 - r^2): its projection onto
// any plane is uniform on the unit disk (the integral of the density along every chord at distance
// rho from the center is pi), so from every receiver the samples spread uniformly over the disk a
// sphere light shows. r = sin(phi), phi of density sin^2 phi on [0, pi/2] (by bisection of its
// distribution (phi - sin phi cos phi) / (pi / 2)); directions on a Fibonacci sphere, radii in another
// order (the golden ratio's), so the two are not correlated.
glm::dvec3 ball_sample(int i, int k) {
  const double u = std::fmod((i + 0.5) * 0.6180339887498949, 1.0);
  double lo = 0.0, hi = 1.5707963267948966;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    ((mid - std::sin(mid) * std::cos(mid)) / 1.5707963267948966 < u ? lo : hi) = mid;
  }
  const double z = 1.0 - (2.0 * i + 1.0) / k, ring = std::sqrt(std::max(0.0, 1.0 - z * z)), a = i * 2.399963229728653;
  return std::sin(0.5 * (lo + hi)) * glm::dvec3(ring * std::cos(a), ring * std::sin(a), z);
}

// A point of the unit disk taken to the square [-1, 1]^2 by the inverse of Shirley and Chiu's concentric
// map, which preserves area: Vogel's disk samples stay as evenly spread over the square.
glm::dvec2 disk_to_square(const glm::dvec2& d) {
  const double r = glm::length(d), quarter = 4.0 / 3.14159265358979323846;
  if (r == 0.0) return d;
  if (std::abs(d.x) >= std::abs(d.y)) {
    const double a = std::copysign(r, d.x);
    return {a, a * std::atan2(d.y / a, d.x / a) * quarter};
  }
  const double b = std::copysign(r, d.y);
  return {b * (2.0 - std::atan2(d.y / b, d.x / b) * quarter), b};
}

// Sample point i of k on light l's shape: a point of its sphere (point, spot), of its rect or disk (a
// distant light's: on its shape at distance 1, so the direction toward that point of it).
glm::dvec3 light_point(const SceneLight& l, int i, int k) {
  if (!is_area_light(l)) return l.position + double(l.radius) * ball_sample(i, k);
  const glm::dvec2 s = l.type == SceneLightType::Rect ? disk_to_square(disk_sample(i, k)) : disk_sample(i, k);
  return l.position + (0.5 * s.x * l.width) * l.right + (0.5 * s.y * l.height) * l.up;
}

// The maps of light l: one per sample of its size (kShadowSamples for a light with a size, at a quarter of
// the point-like sizes), each a directional light's map along a direction of its apparent disk (a
// distant area light's: toward a point of its shape at distance 1), or a
// point or spot light's from a point of its sphere, or an area light's (a cube) from a point of its
// shape.
void light_maps(const SceneLight& l, const glm::dvec3& lo, const glm::dvec3& hi, const ShadowSizes& sizes,
                std::vector<PmrShadowMap>& maps) {
  const bool directional = l.type == SceneLightType::Directional || l.distant;
  const bool sized = has_size(l);
  const int samples = shadow_samples(l);
  const int size = std::max(kMinShadowSize / 2, (directional ? sizes.directional : sizes.local) / (sized ? 4 : 1));
  glm::dvec3 x, y;
  frame_about(l.direction, x, y);
  for (int i = 0; i < samples; ++i) {
    if (l.distant) {
      maps.push_back(orthographic_map(-glm::normalize(light_point(l, i, samples)), lo, hi, size));
    } else if (directional) {
      const glm::dvec2 d = sized ? disk_sample(i, samples) * std::tan(0.5 * double(l.angle)) : glm::dvec2(0.0);
      maps.push_back(orthographic_map(glm::normalize(l.direction + d.x * x + d.y * y), lo, hi, size));
    } else {
      local_maps(l, sized ? light_point(l, i, samples) : l.position, lo, hi, size, maps);
    }
  }
}

// The environment's occlusion maps (shading/environment_occlusion.h): one orthographic map of
// kOcclusionSize a side along each direction, weighted by the environment's radiance about it.
void occlusion_maps(const std::vector<OcclusionDirection>& occlusion, const glm::dvec3& lo, const glm::dvec3& hi,
                    std::vector<PmrShadowMap>& maps) {
  for (const OcclusionDirection& d : occlusion) {
    maps.push_back(orthographic_map(-d.toward, lo, hi, kOcclusionSize));
    maps.back().weight = float(d.weight);
  }
}

// The texels of the maps of `lights` (the first kMaxShadowedLights) at `sizes`.
uint64_t texels_needed(const std::vector<SceneLight>& lights, const ShadowSizes& sizes) {
  uint64_t n = 0;
  for (size_t i = 0; i < lights.size() && i < size_t(kMaxShadowedLights); ++i) {
    std::vector<PmrShadowMap> maps;
    light_maps(lights[i], glm::dvec3(-1.0), glm::dvec3(1.0), sizes, maps);
    n += shadow_texels(maps);
  }
  return n;
}

}  // namespace

ShadowPlacement place_shadow_maps(const std::vector<SceneLight>& lights,
                                  const std::vector<OcclusionDirection>& occlusion, const glm::dvec3& lo,
                                  const glm::dvec3& hi, const ShadowSizes& wanted, bool translucent) {
  ShadowSizes sizes = wanted;
  const uint64_t occlusion_texels = uint64_t(occlusion.size()) * kOcclusionSize * kOcclusionSize;
  while ((texels_needed(lights, sizes) + occlusion_texels) * (translucent ? 3 : 1) > kShadowTexelBudget &&
         std::max(sizes.directional, sizes.local) > kMinShadowSize) {
    sizes.directional = std::max(kMinShadowSize, sizes.directional / 2);
    sizes.local = std::max(kMinShadowSize, sizes.local / 2);
  }
  ShadowPlacement out;
  std::vector<PmrShadowMap>& maps = out.maps;
  out.slots.assign(lights.size(), ShadowSlot{});
  for (size_t i = 0; i < lights.size() && i < size_t(kMaxShadowedLights); ++i) {
    const SceneLight& l = lights[i];
    out.slots[i].first = int(maps.size());
    light_maps(l, lo, hi, sizes, maps);
    out.slots[i].count = int(maps.size()) - out.slots[i].first;
    out.slots[i].samples = shadow_samples(l);
  }
  if (!occlusion.empty()) {
    out.occlusion.first = int(maps.size());
    occlusion_maps(occlusion, lo, hi, maps);
    out.occlusion.count = out.occlusion.samples = int(occlusion.size());
  }
  uint64_t offset = 0;
  for (PmrShadowMap& m : maps) {
    m.offset = uint32_t(offset);
    offset += uint64_t(m.size) * uint64_t(m.size);
  }
  if (translucent) add_translucent_layers(maps);
  return out;
}

ShadowCost shadow_cost(const std::vector<SceneLight>& lights, size_t occlusion_directions, const ShadowSizes& sizes) {
  ShadowCost c;
  for (size_t i = 0; i < lights.size() && i < size_t(kMaxShadowedLights); ++i) {
    std::vector<PmrShadowMap> maps;
    light_maps(lights[i], glm::dvec3(-1.0), glm::dvec3(1.0), sizes, maps);
    c.maps += maps.size(), c.texels += shadow_texels(maps), c.lookups_per_point += uint64_t(shadow_samples(lights[i]));
  }
  c.maps += occlusion_directions, c.lookups_per_point += occlusion_directions;
  c.texels += uint64_t(occlusion_directions) * kOcclusionSize * kOcclusionSize;
  return c;
}

void add_translucent_layers(std::vector<PmrShadowMap>& maps) {
  uint64_t offset = 0;
  for (const PmrShadowMap& m : maps) offset += uint64_t(m.size) * uint64_t(m.size);
  for (PmrShadowMap& m : maps) {
    m.translucent = uint32_t(offset);
    offset += 2 * uint64_t(m.size) * uint64_t(m.size);
  }
}

uint64_t shadow_texels(const std::vector<PmrShadowMap>& maps) {
  uint64_t n = 0;
  for (const PmrShadowMap& m : maps)
    n += uint64_t(m.size) * uint64_t(m.size) * (m.translucent == PMR_NO_TRANSLUCENT ? 1 : 3);
  return n;
}

std::vector<float> ShadowStage::read_depth() const {
  std::vector<float> out(size_t(shadow_texels(placed_.maps)));
  if (!out.empty()) rt_.read(depth_, out.data(), out.size() * sizeof(float));
  return out;
}

ShadowStage::ShadowStage(Launcher& launcher, const ClProgram& program, const ShadowSizes& sizes)
    : launcher_(launcher),
      rt_(launcher.runtime()),
      sizes_(sizes),
      clear_(program, "shadow_clear"),
      raster_(program, "shadow_raster") {
  maps_buffer_ = rt_.buffer(sizeof(PmrShadowMap), "shadow maps");
  params_ = rt_.buffer(sizeof(PmrParams), "shadow pass parameters", CL_MEM_READ_ONLY);
  depth_ = rt_.buffer(16, "shadow depths");
}

void ShadowStage::place(bool on, const std::vector<SceneLight>& lights,
                        const std::vector<OcclusionDirection>& occlusion, const SceneBuffers& scene) {
  placed_ = ShadowPlacement{};
  placed_.slots.assign(lights.size(), ShadowSlot{});
  if (!on || scene.caster_triangles() == 0) return;
  placed_ = place_shadow_maps(lights, occlusion, scene.bounds_lo(), scene.bounds_hi(), sizes_,
                              scene.blended() || scene.translucent_casters());
  const uint64_t texels = shadow_texels(placed_.maps);
  if (texels >= (uint64_t(1) << 32)) throw Error("the lights' shadow maps need more than 2^32 texels");
  if (depth_.size() < texels * 4) {
    rendered_.clear();
    depth_ = ClBuffer(), depth_ = rt_.buffer(size_t(texels * 4), "shadow depths");
  }
  rt_.rewrite(maps_buffer_, placed_.maps, "shadow maps");
}

void ShadowStage::render(const SceneBuffers& scene, const PmrParams& P, const SourceBinding& source, FrameEvents& ev,
                         bool warm) {
  rt_.write(params_, &P, sizeof P);
  const cl_uint next = scene.bind_shading(raster_, params_, binding(), source);
  if (warm) {  // one launch of each kernel, so that frames compile nothing
    clear_.args(depth_, cl_uint(0), cl_uint(0), cl_uint(0));
    ev.add(kShadow, launcher_.launch(clear_, 1, 64));
    raster_.args_from(next, cl_uint(0), depth_);
    ev.add(kShadow, launcher_.launch(raster_, 1, 64));
    return;
  }
  const std::vector<PmrShadowMap>& maps = placed_.maps;
  const bool same = maps.size() == rendered_.size() && rendered_generation_ == scene.geometry_generation() &&
                    std::memcmp(maps.data(), rendered_.data(), maps.size() * sizeof(PmrShadowMap)) == 0;
  if (same) return;
  rendered_ = maps, rendered_generation_ = scene.geometry_generation();
  for (size_t k = 0; k < maps.size(); ++k) {
    const PmrShadowMap& m = maps[k];
    const uint32_t texels = uint32_t(m.size) * uint32_t(m.size);
    clear_.args(depth_, cl_uint(m.offset), cl_uint(texels), cl_uint(0));
    ev.add(kShadow, launcher_.launch(clear_, texels, 64));
    if (m.translucent != PMR_NO_TRANSLUCENT) {
      clear_.args(depth_, cl_uint(m.translucent), cl_uint(texels), cl_uint(1));
      ev.add(kShadow, launcher_.launch(clear_, texels, 64));
    }
    raster_.args_from(next, cl_uint(k), depth_);
    ev.add(kShadow, launcher_.launch(raster_, scene.caster_triangles(), 64));  // not the ground catcher
  }
}

}  // namespace pmr
