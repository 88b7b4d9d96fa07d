// The frame's shadow maps (DESIGN section 4d): each light's maps placed over the box of the scene's
// posed geometry, rendered once per frame before any fine raster (cl/shadow.cl), and read by the shading
// of every view, every path and every product (cl/lights.h, shadow_visibility_lanes), so a shadow costs one
// pass per light whatever the number of views. This stage owns the maps and their depths.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "pipeline/launcher.h"
#include "pipeline/shadow_sizes.h"
#include "pipeline/transmission_stage.h"
#include "pmr/scene.h"
#include "pmr/shared.h"
#include "runtime/cl_runtime.h"
#include "shading/environment_occlusion.h"

namespace pmr {

class SceneBuffers;

// What a shading kernel binds for the shadows: the maps and their depths.
struct ShadowBinding {
  const ClBuffer* maps;
  const ClBuffer* depth;
};

// A light's maps in the frame's table: the first, and how many (0: none, 1, or 6 for a cube).
struct ShadowSlot {
  int first = -1;
  int count = 0;
  int samples = 1;  // groups of count / samples maps, one per sample of a light's size
};

// A frame's maps: slots[i] says which are light i's, `occlusion` which are the environment's
// occlusion maps (count 0: none).
struct ShadowPlacement {
  std::vector<PmrShadowMap> maps;
  std::vector<ShadowSlot> slots;
  ShadowSlot occlusion;
};

// The maps of `lights` (world space, posed) over the world box [lo, hi] of every caster and receiver:
// a directional light's orthographic map covers the box seen along its direction; a point light's
// cube and a spot light's map look from its position, their near plane 1e-4 of the farthest corner's
// distance. slots[i]: light i's maps (none after the first kMaxShadowedLights). Then one orthographic
// map of kOcclusionSize a side per direction of the environment's occlusion. Sizes are halved until
// all fit kShadowTexelBudget (not below kMinShadowSize). Depth offsets are packed in order.
// `translucent`: every map gets a translucent layer (add_translucent_layers), counted in the budget.
ShadowPlacement place_shadow_maps(const std::vector<SceneLight>& lights,
                                  const std::vector<OcclusionDirection>& occlusion, const glm::dvec3& lo,
                                  const glm::dvec3& hi, const ShadowSizes& sizes, bool translucent);
// Gives every map a translucent layer (two values a texel) after the depths of all maps.
void add_translucent_layers(std::vector<PmrShadowMap>& maps);
// Values (4 bytes each) of all of `maps`: depths, and the translucent layers' pairs.
uint64_t shadow_texels(const std::vector<PmrShadowMap>& maps);

class ShadowStage {
 public:
  // `program`: the main program (shadow.cl).
  ShadowStage(Launcher& launcher, const ClProgram& program, const ShadowSizes& sizes);
  // Places the maps of the frame's lights and of the environment's occlusion over the scene's posed
  // box (none when `on` is false or the scene is empty), with translucent layers when the scene has
  // BLEND or transmissive materials: placement() then says which maps are whose.
  void place(bool on, const std::vector<SceneLight>& lights, const std::vector<OcclusionDirection>& occlusion,
             const SceneBuffers& scene);
  // Renders the placed maps from the scene's posed triangles (the shading kernels' inputs: frame
  // parameters P, any pass's transmission source), unless the maps and the triangles are those of the
  // last frame rendered (a still scene renders its maps once). `warm`: the warm-up frame, which
  // launches each kernel once whatever was placed.
  void render(const SceneBuffers& scene, const PmrParams& P, const SourceBinding& source, FrameEvents& ev, bool warm);
  const ShadowPlacement& placement() const { return placed_; }
  const std::vector<PmrShadowMap>& maps() const { return placed_.maps; }
  // The placed maps' depths as floats (after the frame).
  std::vector<float> read_depth() const;
  ShadowBinding binding() const { return {&maps_buffer_, &depth_}; }
  size_t device_bytes() const { return maps_buffer_.size() + depth_.size(); }

 private:
  Launcher& launcher_;
  const ClRuntime& rt_;
  ShadowSizes sizes_;
  ClKernel clear_, raster_;
  ShadowPlacement placed_;
  // what the depths hold: the maps and the geometry generation they were rendered from
  std::vector<PmrShadowMap> rendered_;
  uint64_t rendered_generation_ = 0;
  ClBuffer maps_buffer_, depth_, params_;
};

}  // namespace pmr
