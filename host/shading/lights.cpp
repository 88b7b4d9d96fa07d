#include "shading/lights.h"

#include <cmath>

#include <glm/gtc/constants.hpp>

namespace pmr {

SceneLight default_light(const glm::dvec3& toward) {
  SceneLight l;
  l.name = "default";
  l.light = -1;
  l.node = -1;
  l.type = SceneLightType::Directional;
  // 0.8 pi: a white rough dielectric facing it, with the default environment, comes out close to
  // Lambert's 1.0 (docs/SHADING.md)
  l.intensity = float(0.8 * glm::pi<double>());
  l.direction = -toward;
  return l;
}

bool is_default_light(const SceneLight& light) { return light.light < 0 && light.node < 0; }

std::vector<SceneLight> resolve_lights(const std::vector<SceneLight>& scene_lights, const Rig& rig, bool use_default) {
  if (!scene_lights.empty()) return scene_lights;
  if (use_default) return {default_light(rig.light_world())};
  return {};
}

PmrLight device_light(const SceneLight& light) {
  PmrLight d{};
  d.type = light.type == SceneLightType::Point  ? PMR_LIGHT_POINT
           : light.type == SceneLightType::Spot ? PMR_LIGHT_SPOT
                                                : PMR_LIGHT_DIRECTIONAL;
  for (int c = 0; c < 3; ++c) {
    d.color[c] = float(double(light.color[c]) * double(light.intensity));
    d.position[c] = float(light.position[c]);
    d.direction[c] = float(light.direction[c]);
  }
  d.range = light.range;
  // the loader guarantees 0 <= inner < outer <= pi / 2; unused for other types
  d.cos_inner = float(std::cos(double(light.inner_cone)));
  d.cos_outer = float(std::cos(double(light.outer_cone)));
  d.shadow = -1;  // unshadowed until shadow maps are placed (ShadowStage)
  d.shadow_samples = 1;
  return d;
}

}  // namespace pmr
