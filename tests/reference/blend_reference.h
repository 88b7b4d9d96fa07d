// Double-precision reference of alphaMode BLEND (DESIGN section 4c step 3, docs/SHADING.md): the
// fragments of one sample composited with premultiplied "over" far to near, exactly up to `exact`
// fragments and beyond them by the rule for the rest. The kernels' cl/blend.h computes the same by
// depth peeling in float and fixed point.
#pragma once
#include <vector>

#include <glm/glm.hpp>

namespace pmr::ref {

// A BLEND fragment: its shaded colour c and opacity a.
struct BlendFragment {
  glm::dvec3 colour;
  double alpha = 0.0;
};

// The fragments (ordered far to near) over `behind` (premultiplied RGBA: the opaque result, or zero):
// C = c a + (1 - a) C, A = a + (1 - a) A. The nearest `exact` fragments composite so; the farther ones
// form one layer directly behind them: A = 1 - prod(1 - a_k), colour (sum c_k a_k / sum a_k) A.
glm::dvec4 composite_blend(const std::vector<BlendFragment>& far_to_near, const glm::dvec4& behind, size_t exact = 8);

}  // namespace pmr::ref
