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

bool is_default_light(const SceneLight& light) { return light.light < 0 && light.node < 0 && !light.distant; }

std::vector<SceneLight> resolve_lights(const std::vector<SceneLight>& scene_lights, const Rig& rig,
                                       const Environment* environment) {
  std::vector<SceneLight> out = scene_lights;
  if (out.empty() && !environment) out.push_back(default_light(rig.light_world()));
  if (environment)
    for (SceneLight& l : environment->distant_lights()) out.push_back(std::move(l));
  return out;
}

PmrLight device_light(const SceneLight& light) {
  PmrLight d{};
  switch (light.type) {
    case SceneLightType::Directional: d.type = PMR_LIGHT_DIRECTIONAL; break;
    case SceneLightType::Point: d.type = PMR_LIGHT_POINT; break;
    case SceneLightType::Spot: d.type = PMR_LIGHT_SPOT; break;
    case SceneLightType::Rect: d.type = PMR_LIGHT_RECT; break;
    case SceneLightType::Disk: d.type = PMR_LIGHT_DISK; break;
  }
  for (int c = 0; c < 3; ++c) {
    d.color[c] = float(double(light.color[c]) * double(light.intensity));
    d.position[c] = float(light.position[c]);
    d.direction[c] = float(light.direction[c]);
    d.half_width[c] = float(0.5 * light.width * light.right[c]);
    d.half_height[c] = float(0.5 * light.height * light.up[c]);
  }
  d.range = light.range;
  // the loader guarantees 0 <= inner < outer <= pi / 2; unused for other types
  d.cos_inner = float(std::cos(double(light.inner_cone)));
  d.cos_outer = float(std::cos(double(light.outer_cone)));
  d.distant = light.distant ? 1u : 0u;
  d.shadow = -1;  // unshadowed until shadow maps are placed (ShadowStage)
  d.shadow_samples = 1;
  return d;
}

}  // namespace pmr
