// Exact visibility of a light (DESIGN section 4d), by ray casting in double precision against every
// triangle of a scene: what the kernels' shadow maps approximate. Independent of the maps: no
// rasterization, no bias, no filter.
#pragma once
#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "reference/pbr_reference.h"

namespace pmr::ref {

// The fraction of the light that travels from p to the light past the casters of `scene` (its
// triangles as given, world space): the product over every caster the segment crosses of 1 - its
// opacity (caster_opacity). The segment starts `start` along its direction from p (above the
// receiver's own surface); a directional light's is unbounded, a point or spot light's ends at it.
double ray_visibility(const Scene& scene, const glm::dvec3& p, const PunctualLight& light, double start = 1e-7);

// How much of the light triangle `tri` blocks at barycentrics b (DESIGN section 4d): a transmissive
// material 1 - transmissionFactor, alphaMode MASK 1 or 0 by the cutoff, BLEND its base colour alpha
// (tests/reference/shade_reference.h, base_color), others 1.
double caster_opacity(const Scene& scene, uint32_t tri, const glm::dvec3& b);

// The product of 1 - opacity over the casters the ray o + t d crosses at t_min < t < t_max.
double transmittance(const Scene& scene, const glm::dvec3& o, const glm::dvec3& d, double t_min, double t_max);

}  // namespace pmr::ref
