#include "reference/blend_reference.h"

namespace pmr::ref {

glm::dvec4 composite_blend(const std::vector<BlendFragment>& far_to_near, const glm::dvec4& behind, size_t exact) {
  const size_t rest = far_to_near.size() > exact ? far_to_near.size() - exact : 0;
  glm::dvec4 c = behind;
  if (rest > 0) {  // the rule's one layer
    glm::dvec3 sum_ca(0.0);
    double sum_a = 0.0, transmittance = 1.0;
    for (size_t k = 0; k < rest; ++k) {
      sum_ca += far_to_near[k].colour * far_to_near[k].alpha;
      sum_a += far_to_near[k].alpha;
      transmittance *= 1.0 - far_to_near[k].alpha;
    }
    const double a = 1.0 - transmittance;
    const glm::dvec3 colour = sum_a > 0.0 ? sum_ca / sum_a * a : glm::dvec3(0.0);
    c = glm::dvec4(colour + (1.0 - a) * glm::dvec3(c), a + (1.0 - a) * c.w);
  }
  for (size_t k = rest; k < far_to_near.size(); ++k) {
    const BlendFragment& f = far_to_near[k];
    c = glm::dvec4(f.colour * f.alpha + (1.0 - f.alpha) * glm::dvec3(c), f.alpha + (1.0 - f.alpha) * c.w);
  }
  return c;
}

}  // namespace pmr::ref
