// Double-precision reference of the physically based model's material inputs at a surface point
// (docs/SHADING.md, "Materials"), read from the scene's material inputs as the loader stores them
// (Scene::material_inputs, textures, texcoords, tangents), independently of how the pipeline packs
// them for the kernels.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "reference/pbr_reference.h"

namespace pmr::ref {

// Fills base, metallic, roughness, ior, transmission, n (the interpolated normal, the normal map, then
// the back-face flip), ao, emissive, unlit, the specular weight and colour, and the clear coat (its normal: its own map on the
// interpolated normal, or that normal) of `sp` for source barycentrics b of triangle `tri`. p and eye
// are left to the caller.
void material_at(const Scene& scene, uint32_t tri, const glm::dvec3& b, bool back, SurfacePoint& sp);

}  // namespace pmr::ref
