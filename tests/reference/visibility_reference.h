// Exact visibility of a light (DESIGN section 4d), by ray casting in double precision against every
// triangle of a scene: what the kernels' shadow maps approximate. Independent of the maps: no
// rasterization, no bias, no filter.
#pragma once
#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "reference/pbr_reference.h"

namespace pmr::ref {

// Whether the segment from p toward the light reaches it past every caster of `scene` (its triangles as
// given, world space): 1 or 0. Casters: every triangle but alphaMode BLEND and transmissive ones. The
// segment starts `start` along its direction from p (above the receiver's own surface); a directional
// light's is unbounded, a point or spot light's ends at the light.
double ray_visibility(const Scene& scene, const glm::dvec3& p, const PunctualLight& light, double start = 1e-7);

// The nearest intersection of the ray o + t d (t > t_min) with a caster, t; infinity where none.
double nearest_caster(const Scene& scene, const glm::dvec3& o, const glm::dvec3& d, double t_min);

}  // namespace pmr::ref
