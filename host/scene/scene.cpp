// Scene-wide helpers shared by the loader, the synthetic scenes and the renderer.
#include <limits>

#include "pmr/error.h"
#include "pmr/scene.h"

namespace pmr {

PmrMaterial default_material() {
  PmrMaterial m{};
  for (float& c : m.base_color) c = 1.0f;
  m.texture = -1;
  m.alpha_mode = PMR_ALPHA_OPAQUE;
  m.alpha_cutoff = 0.5f;
  m.double_sided = 0;
  return m;
}

void scene_bounds(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi) {
  lo = glm::dvec3(std::numeric_limits<double>::infinity());
  hi = -lo;
  bool any = false;
  for (const PmrTriangle& t : scene.triangles) {
    for (uint32_t v : t.v) {
      if (v >= scene.positions.size()) throw Error("scene_bounds: triangle vertex index out of range");
      const glm::dvec3 p(scene.positions[v]);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
      any = true;
    }
  }
  if (!any) throw Error("scene_bounds: the scene has no triangles");
}

}  // namespace pmr
