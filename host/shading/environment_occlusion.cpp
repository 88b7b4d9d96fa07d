#include "shading/environment_occlusion.h"

#include <cmath>

#include "shading/environment_lights.h"

namespace pmr {

std::vector<OcclusionDirection> occlusion_directions(const Environment* env, double uniform_intensity) {
  std::vector<OcclusionDirection> out;
  if (!env && !(uniform_intensity > 0.0)) return out;
  const int k = kOcclusionDirections;
  for (int i = 0; i < k; ++i) {
    // Fibonacci sphere about +Y: equal areas in height, turned by the golden angle
    const double y = 1.0 - (2.0 * i + 1.0) / k, ring = std::sqrt(std::max(0.0, 1.0 - y * y)), a = i * 2.399963229728653;
    const glm::dvec3 d(ring * std::cos(a), y, ring * std::sin(a));
    double w = 1.0;
    if (env) w = luminance(env->prefiltered(d, kOcclusionWeightRoughness));
    if (w > 0.0 && std::isfinite(w)) out.push_back({d, w});
  }
  return out;
}

}  // namespace pmr
