// --ground shadow (DESIGN section 4d): a horizontal shadow catcher under the scene, like Blender's
// shadow catcher. It shows only the shadow the scene casts on it: premultiplied black, of alpha
// 1 - (the irradiance that reaches it / the irradiance that would reach it unoccluded), over all the
// lights and the environment (cl/shade.h). It is an alphaMode BLEND surface, so it writes no depth and
// what stands on it is drawn over it; it casts no shadow, and the shadow maps' box leaves it out.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "pmr/scene.h"

namespace pmr {

// The catcher's height: the framing box [lo, hi]'s lowest point, less a gap of 1e-3 of the box's
// diagonal (a surface resting at the lowest point stays above it).
double ground_height(const glm::dvec3& lo, const glm::dvec3& hi);

// The catcher as a scene of its own, drawn after the scene's triangles (SceneBuffers::set_scene): a
// square at ground_height(lo, hi), centred under the box's centre (the turntable's pivot), of half side
// `half_size`, facing +Y, of one material (material 0: black, BLEND, PMR_MATERIAL_SHADOW_CATCHER).
Scene make_ground_catcher(const glm::dvec3& lo, const glm::dvec3& hi, double half_size);

}  // namespace pmr
