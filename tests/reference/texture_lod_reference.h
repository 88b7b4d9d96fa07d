// Double-precision reference of filtered textures (docs/DESIGN.md section 3b): the mip chain of a
// texture, the screen-space derivatives of the source barycentrics, and the trilinear sample at the
// level of detail they give. Written apart from the host's mip build and the kernels' derivatives.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "pmr/shared.h"

namespace pmr::ref {

// Levels 0.. of `tex`, down to 1 x 1: level k's texel is the mean, in linear light (colour maps'
// RGB sRGB-decoded), of the level-0 block of 2^k x 2^k texels it covers (2^j rows once the height is 1
// at level j, the same for columns), stored as 8 bits (colour maps sRGB-encoded again).
std::vector<SceneTexture> mip_chain(const SceneTexture& tex, bool srgb);

// The derivatives of the source barycentrics of MTA m at raster point (X, Y) (16.16, 24.8) of the view
// with view coordinate `view`, per view pixel in x (dx) and y (dy).
struct BaryDerivatives {
  glm::dvec3 dx{0.0}, dy{0.0};
};
BaryDerivatives source_barycentric_derivatives(const PmrMta& m, int64_t sample_x, int64_t sample_y, int view);

// lambda = clamp(log2 rho, 0, levels - 1), rho the longer footprint axis in level-0 texels.
double texture_lod(const std::vector<SceneTexture>& chain, const glm::dvec2& duv_dx, const glm::dvec2& duv_dy);
// Trilinear sample of the chain at uv for texture-coordinate derivatives duv_dx, duv_dy.
glm::dvec4 sample_trilinear(const std::vector<SceneTexture>& chain, const glm::dvec2& uv, const glm::dvec2& duv_dx,
                            const glm::dvec2& duv_dy, bool srgb);

}  // namespace pmr::ref
