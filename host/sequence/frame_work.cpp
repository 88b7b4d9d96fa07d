#include "sequence/frame_work.h"

#include <algorithm>
#include <cmath>

#include "pipeline/pipeline_config.h"
#include "pmr/error.h"

namespace pmr {

namespace {

uint64_t add_sat(uint64_t a, uint64_t b) { return a + b < a ? UINT64_MAX : a + b; }

uint64_t mul_sat(uint64_t a, uint64_t b) {
  uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}

// Voxels of the 3D tiles the triangle's bounding box covers over all views: its corners in the first
// and the last view bound it in every view (raster x is affine in the view index). A corner at or
// behind the near plane may reach anywhere once clipped: the whole raster then.
uint64_t blend_voxel_bound(const glm::dvec3 (&p)[3], const Rig& rig, const glm::dmat4 (&to_clip)[2], int tx, int ty) {
  const double w = rig.view_w, h = rig.view_h;
  double x0 = w, x1 = 0, y0 = h, y1 = 0;
  for (const glm::dmat4& m : to_clip)
    for (const glm::dvec3& v : p) {
      const glm::dvec4 c = m * glm::dvec4(v, 1.0);
      if (!(c.w > rig.near_eff * 0.999) || !std::isfinite(c.x) || !std::isfinite(c.y)) {
        x0 = 0, x1 = w, y0 = 0, y1 = h;
        break;
      }
      const double x = (c.x / c.w + 1.0) * 0.5 * w, y = (1.0 - c.y / c.w) * 0.5 * h;  // row 0 on top
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  x0 = std::max(x0, 0.0), y0 = std::max(y0, 0.0), x1 = std::min(x1, w), y1 = std::min(y1, h);
  if (!(x0 <= x1 && y0 <= y1)) return 0;  // off screen in every view
  auto tiles = [](double lo, double hi, int size, double extent) {
    const double last = std::min(std::floor(hi / size), std::ceil(extent / size) - 1.0);
    return uint64_t(std::max(0.0, last - std::floor(lo / size) + 1.0)) * uint64_t(size);
  };
  return tiles(x0, x1, tx, w) * tiles(y0, y1, ty, h) * uint64_t(rig.views);
}

}  // namespace

uint64_t light_evaluations_per_point(const std::vector<SceneLight>& lights) {
  uint64_t n = 0;
  for (const SceneLight& l : lights)
    n += l.type == SceneLightType::Rect   ? kRectLightEvaluations
         : l.type == SceneLightType::Disk ? kDiskLightEvaluations
                                          : 1;
  return n;
}

FrameWork estimate_frame_work(const Scene& placed, const Rig& rig, uint64_t lights, const PipelineConfig& config,
                              const ShadowCost& shadows) {
  FrameWork f;
  f.pixels = uint64_t(rig.views) * uint64_t(rig.view_w) * uint64_t(rig.view_h);
  f.lights = lights;
  f.samples = uint64_t(std::max(1, config.samples));
  const glm::dmat4 to_clip[2] = {rig.projection(0) * rig.view_matrix(0),
                                 rig.projection(rig.views - 1) * rig.view_matrix(rig.views - 1)};
  for (const PmrTriangle& t : placed.triangles) {
    if (t.material >= placed.materials.size() || placed.materials[t.material].alpha_mode != PMR_ALPHA_BLEND) continue;
    const glm::dvec3 p[3] = {glm::dvec3(placed.positions[t.v[0]]), glm::dvec3(placed.positions[t.v[1]]),
                             glm::dvec3(placed.positions[t.v[2]])};
    f.blend_fragments = add_sat(f.blend_fragments, blend_voxel_bound(p, rig, to_clip, config.tile_x, config.tile_y));
  }
  // --ground shadow: the catcher (appended by the pipeline, not in `placed`) is a BLEND layer under every
  // view pixel at most
  if (config.ground_shadow) f.blend_fragments = add_sat(f.blend_fragments, f.pixels);
  f.light_evaluations = mul_sat(add_sat(f.pixels, f.blend_fragments), f.lights);
  const uint64_t per_fragment = kUnitsPerBlendFragment + f.samples * kUnitsPerBlendSample;
  f.units = add_sat(mul_sat(f.light_evaluations, kUnitsPerLightEvaluation), mul_sat(f.blend_fragments, per_fragment));
  f.shadow_reads = mul_sat(add_sat(f.pixels, f.blend_fragments), shadows.lookups_per_point);
  f.shadow_map_triangles = mul_sat(shadows.maps, placed.triangles.size());
  f.shadow_texels = shadows.texels;
  f.units = add_sat(f.units, mul_sat(f.shadow_reads, kUnitsPerShadowRead));
  f.units = add_sat(f.units, add_sat(mul_sat(f.shadow_map_triangles, kUnitsPerShadowTriangle),
                                     mul_sat(f.shadow_texels, kUnitsPerShadowTexel)));
  return f;
}

std::string describe_frame_work(const FrameWork& f) {
  return std::to_string(f.units) + " units: " + std::to_string(f.light_evaluations) + " light evaluations ((" +
         std::to_string(f.pixels) + " view pixels + BLEND fragments) x " + std::to_string(f.lights) +
         " light evaluation(s) a point) and at most " + std::to_string(f.blend_fragments) + " BLEND fragments x " +
         std::to_string(f.samples) + " sample(s)" +
         (f.shadow_reads + f.shadow_map_triangles > 0
              ? ", " + std::to_string(f.shadow_reads) + " shadow map reads and " +
                    std::to_string(f.shadow_map_triangles) + " shadow map triangles"
              : std::string());
}

void check_frame_work(const FrameWork& f, uint64_t limit) {
  if (f.units <= limit) return;
  throw Error("the frame's estimated work is " + describe_frame_work(f) + ", more than the frame-work limit of " +
              std::to_string(limit) + " (about " + std::to_string(limit / 1000000000) +
              " s on the reference machine; raise it with --limit frame-work=N)");
}

}  // namespace pmr
