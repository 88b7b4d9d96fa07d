// The frame-work budget (docs/SECURITY.md, "Frame work"): what one frame will cost, estimated from
// the scene, the rig and the configuration before the frame renders, so that a small file cannot
// hold a job for hours (1000 point lights, hundreds of stacked BLEND layers). Two parts, weighted so
// that a unit is about a nanosecond of the 2-core development machine (measured with pmr bench):
// - light evaluations: every view pixel and every BLEND fragment is shaded once per light (shading is
//   once per pixel, not per sample: 100 lights add 392, 406 and 410 ms to a 16-view frame at 1, 4
//   and 16 samples);
// - shadows (DESIGN section 4d): every shaded point reads one map per sample of each shadowed light
//   (2.2 ns a read: a sun of 32 samples added 3.5 s to a 96-view frame of 50M pixels), and every map
//   is cleared and rasterized from every triangle once;
// - BLEND fragments: each BLEND triangle's fragments, sorted into the nearest layers once per fragment
//   and composited per sample; bounded by the voxels of the 3D tiles its screen bounding box covers
//   in every view (an upper bound of its tile-queue entries times the tile's voxels).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/shadow_sizes.h"
#include "pmr/rig.h"
#include "pmr/scene.h"

namespace pmr {

struct PipelineConfig;

struct FrameWork {
  uint64_t pixels = 0;             // views x W x H
  uint64_t lights = 0;             // light evaluations per shaded point (light_evaluations_per_point)
  uint64_t blend_fragments = 0;    // upper bound of the BLEND triangles' voxels (the ground catcher's: every pixel)
  uint64_t samples = 1;            // per pixel
  uint64_t light_evaluations = 0;  // (pixels + blend_fragments) x lights
  uint64_t shadow_reads = 0;       // (pixels + blend_fragments) x maps read per point
  uint64_t shadow_map_triangles = 0, shadow_texels = 0;  // map passes x triangles; texels cleared
  uint64_t units = 0;                                    // the weighted sum the budget limits
};

// An area light costs a point's shading as much as this many point-like lights (its polygon integrated
// three times: measured on the bundled scene at 96 views, a 2 x 1 m rect light added 0.8 s and a disk
// 2.1 s to a frame whose one sun costs about 0.1 s).
constexpr uint64_t kRectLightEvaluations = 8;
constexpr uint64_t kDiskLightEvaluations = 24;

// The light evaluations of one shaded point under `lights`: one per point-like light, an area light's
// weight above.
uint64_t light_evaluations_per_point(const std::vector<SceneLight>& lights);

// Weights: units per light evaluation, per BLEND fragment, and per BLEND fragment and sample.
constexpr uint64_t kUnitsPerLightEvaluation = 4;
constexpr uint64_t kUnitsPerBlendFragment = 14;
constexpr uint64_t kUnitsPerBlendSample = 2;
// ... per shadow map read, per triangle of a map pass, per map texel
constexpr uint64_t kUnitsPerShadowRead = 2;
constexpr uint64_t kUnitsPerShadowTriangle = 20;
constexpr uint64_t kUnitsPerShadowTexel = 1;

// The estimate for one frame of `placed` (posed) seen by `rig`, shaded with `lights` light evaluations
// per point (light_evaluations_per_point) of lights whose
// shadows cost `shadows` (none: shadow_cost of no lights).
FrameWork estimate_frame_work(const Scene& placed, const Rig& rig, uint64_t lights, const PipelineConfig& config,
                              const ShadowCost& shadows = {});

// Throws pmr::Error naming --limit frame-work when the estimate exceeds `limit`.
void check_frame_work(const FrameWork& work, uint64_t limit);

// The estimate in words, for pmr info.
std::string describe_frame_work(const FrameWork& work);

}  // namespace pmr
