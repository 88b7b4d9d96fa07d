// The scene on the device, and everything shading reads: geometry and materials (set_scene), the posed
// geometry of a frame (update_geometry), the frame's lights and camera positions (upload_frame), and the
// run's tables (sRGB decoding, the split-sum table, the environment image). Shading kernels take these
// as their leading arguments in one order (cl/shade_inputs.h, PMR_SHADE_PARAMS), bound by bind_shading alone.
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/frame_description.h"
#include "pipeline/shadow_stage.h"
#include "pipeline/transmission_stage.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"

namespace pmr {

struct PipelineConfig;

class SceneBuffers {
 public:
  // The run's tables: sRGB decoding, the split-sum table (pbr) and the environment image (pbr).
  SceneBuffers(const ClRuntime& rt, const PipelineConfig& config);
  // The scene's triangles, then those of `catcher` (--ground shadow: make_ground_catcher, a scene of
  // its own), which cast no shadow and lie outside bounds_lo()..bounds_hi().
  void set_scene(const Scene& scene, const Scene* catcher = nullptr);
  // The posed geometry of a frame of the scene given to set_scene (same counts), and its catcher as it
  // was: copied, not reallocated.
  void update_geometry(const Scene& posed);
  // The frame's light table (light i with its shadow maps shadows.slots[i], then an entry with the
  // environment's occlusion maps when there are any) and each view's camera position in world space
  // (the view vector of pbr).
  void upload_frame(const FrameDescription& frame, const ShadowPlacement& shadows);
  // Binds the frame parameters `params`, the shading inputs, the frame's shadow maps and the pass's
  // transmission source as arguments 0 .. of `k` (the order of PMR_SHADE_PARAMS); returns the index of
  // the kernel's next argument.
  cl_uint bind_shading(ClKernel& k, const ClBuffer& params, const ShadowBinding& shadows,
                       const SourceBinding& source) const;
  // The world box of the posed geometry (set_scene, update_geometry): where shadow maps are placed.
  const glm::dvec3& bounds_lo() const { return bounds_lo_; }
  const glm::dvec3& bounds_hi() const { return bounds_hi_; }
  // Counts set_scene and update_geometry calls: unchanged, the device holds the same triangles.
  uint64_t geometry_generation() const { return geometry_generation_; }

  uint32_t num_vertices() const { return num_vertices_; }
  // pbr and a triangle with a transmissive material: frames need the transmission source
  bool transmissive() const { return transmissive_; }
  // a triangle with an alphaMode BLEND material (scene_blended): frames composite BLEND layers
  bool blended() const { return blended_; }
  // a triangle with a transmissive material, whatever the shading: casts a partial shadow
  bool translucent_casters() const { return translucent_casters_; }
  uint32_t num_triangles() const { return num_triangles_; }
  // the scene's own triangles, which cast shadows: the first num_triangles() less the catcher's
  uint32_t caster_triangles() const { return caster_triangles_; }
  const ClBuffer& positions() const { return positions_; }
  const ClBuffer& triangles() const { return tris_; }
  const ClBuffer& materials() const { return materials_; }
  const std::vector<SceneLight>& scene_lights() const { return scene_lights_; }  // as in the file, rest pose
  size_t device_bytes() const;

 private:
  void upload_environment(const PipelineConfig& config);

  const ClRuntime& rt_;
  bool mips_;  // --texture-filter trilinear: the textures' mip chains are built and uploaded
  bool pbr_;
  bool transmissive_ = false, blended_ = false, translucent_casters_ = false;
  uint32_t num_vertices_ = 0, num_triangles_ = 0, caster_triangles_ = 0;
  // the catcher's geometry, its indices already past the scene's vertices and materials
  std::vector<glm::vec3> catcher_positions_;
  std::vector<PmrVertexAttr> catcher_attributes_;
  std::vector<PmrTriangle> catcher_triangles_;
  bool has_tangents_ = false;
  std::vector<SceneLight> scene_lights_;
  glm::dvec3 bounds_lo_{0.0}, bounds_hi_{0.0};
  uint64_t geometry_generation_ = 0;
  void set_bounds(const std::vector<glm::vec3>& positions);
  ClBuffer positions_, attrs_, tris_, materials_, textures_, texels_, texcoords_, tangents_;
  ClBuffer lut_, split_sum_, ltc_, sheen_albedo_, env_, env_data_;  // the run's tables
  ClBuffer lights_, eyes_;                                          // the frame's
};

}  // namespace pmr
