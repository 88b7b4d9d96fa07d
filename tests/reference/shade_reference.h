// Double-precision reference of DESIGN section 4 (shading) for one voxel.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "pmr/shared.h"

namespace pmr::ref {

// Perspective-correct barycentrics of voxel (px, py, view) in the MTA's SOURCE triangle; `view` is the
// view's view coordinate (PmrParams.view_coord: its index with linear spacing).
glm::dvec3 source_barycentrics(const PmrMta& m, int px, int py, int view);
// The same at raster point (X, Y) in fixed point (16.16, 24.8): a --sampling subpixel sample.
glm::dvec3 source_barycentrics_at(const PmrMta& m, int64_t sample_x, int64_t sample_y, int view);
// Bilinear sample at uv ((0, 0) = the image's top-left corner) with the texture's wrap modes; colour
// textures decode sRGB, data textures are linear.
glm::dvec4 sample_texture(const SceneTexture& tex, const glm::dvec2& uv, bool srgb);
// KHR_texture_transform of a slot applied to uv.
glm::dvec2 transformed_uv(const SceneTextureSlot& slot, const glm::dvec2& uv);
// The slot's texture at source barycentrics b of triangle t (its TEXCOORD set interpolated, then its
// transform), or nothing (false, out untouched) when the slot has none.
bool sample_slot(const Scene& scene, const PmrTriangle& t, const glm::dvec3& b, const SceneTextureSlot& slot,
                 glm::dvec4& out);
// Unlit base colour (factor * texture * COLOR_0) at source barycentrics b of triangle `tri`.
glm::dvec4 base_color(const Scene& scene, uint32_t tri, const glm::dvec3& b);
// Lit colour (alpha = 1) with the light direction `light` (world space, unit).
glm::dvec4 shade(const Scene& scene, uint32_t tri, const glm::dvec3& b, bool back, const glm::dvec3& light);

}  // namespace pmr::ref
