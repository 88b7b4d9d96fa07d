// What one frame renders: built once per frame by the frame loop (sequence/frame_renderer) and rendered
// whole by Pipeline::render. Everything that may change from frame to frame is here; what holds for the
// whole run (sizes, method, sampling, shading model, exposure, the environment image, the display)
// is the pipeline's configuration.
#pragma once
#include <vector>

#include "pmr/rig.h"
#include "pmr/scene.h"
#include "shading/environment_occlusion.h"

namespace pmr {

struct PipelineConfig;

struct FrameDescription {
  // This frame's cameras: the center view matrix, focal distance, near and far planes and the per-view
  // offsets. A glTF camera that moves gives every frame its own rig.
  Rig rig;
  // --shading pbr: the lights the frame is shaded with, world space and posed, resolved once
  // (resolve_lights: the scene's lights, else the default light unless an environment image lights the
  // scene). Empty under lambert, whose one fixed light is the rig's.
  std::vector<SceneLight> lights;
  // --shading pbr with shadows on: the directions of the environment's occlusion
  // (occlusion_directions); empty when the environment is off.
  std::vector<OcclusionDirection> occlusion;
};

// The frame of `rig` lit by `scene_lights` (posed, world space) under `config`'s shading.
FrameDescription describe_frame(const Rig& rig, const std::vector<SceneLight>& scene_lights,
                                const PipelineConfig& config);

}  // namespace pmr
