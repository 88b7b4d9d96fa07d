// The lights --shading pbr renders a frame with (docs/SHADING.md, "Lights"): the scene's
// KHR_lights_punctual and EXT_lights_area lights as posed for the frame (world space) when it has any; otherwise the
// default light, unless an environment image lights the scene instead. Lambert keeps its one fixed
// light (Rig::light_world) and reads none of these.
#pragma once
#include <vector>

#include "pmr/rig.h"
#include "pmr/scene.h"
#include "pmr/shared.h"
#include "shading/environment.h"

namespace pmr {

// The default light: directional, white, irradiance E = 0.8 pi, shining toward `toward` (unit, world
// space): the rig's light direction rig.light_world(), fixed in the center camera's view space, so a
// turntable does not turn it. It is the one SceneLight with light = node = -1 and the name "default".
SceneLight default_light(const glm::dvec3& toward);
bool is_default_light(const SceneLight& light);

// The lights of a frame: `scene_lights` (posed, world space), or the default light when there are
// none and no environment image lights the scene (`environment` null: the uniform one); then the
// environment's distant lights (the studio's boxes with shadows on).
std::vector<SceneLight> resolve_lights(const std::vector<SceneLight>& scene_lights, const Rig& rig,
                                       const Environment* environment);

// The kernels' light table entry of a resolved light (colour x intensity, cosines of the cone angles,
// an area light's half extents, single precision).
PmrLight device_light(const SceneLight& light);

}  // namespace pmr
