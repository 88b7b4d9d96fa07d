// The kernels' area lights at given points (cl/area_lights.h's area_light_lanes, through
// tests/probes/area_light_probe.cl): what tests/test_area_lights.cpp and tests/test_area_ltc.cpp check.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "pmr/shared.h"

namespace pmr::test {

struct AreaProbePoint {
  int light = 0;         // index into the lights
  glm::dvec3 p, n, v;    // the point, its unit shading normal, the unit direction toward the view
  double r = 0.5;        // roughness (clamped)
  double coat_r = -1.0;  // the clear coat's roughness about n; < 0: no coat
};

// Per unit luminance (AreaLanes): the vector irradiance's direction l and size e, the diffuse lobe's
// cosine integral, the GGX lobe's D Vis n.l and (1 - v.h)^5 D Vis n.l over the light, the coat's.
struct AreaProbeResult {
  glm::dvec3 l;
  double e, cosine, lobe, schlick, coat;
};

std::vector<AreaProbeResult> probe_area_lights(const std::vector<PmrLight>& lights,
                                               const std::vector<AreaProbePoint>& at);

}  // namespace pmr::test
