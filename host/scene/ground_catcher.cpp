#include "scene/ground_catcher.h"

namespace pmr {

double ground_height(const glm::dvec3& lo, const glm::dvec3& hi) { return lo.y - 1e-3 * glm::length(hi - lo); }

Scene make_ground_catcher(const glm::dvec3& lo, const glm::dvec3& hi, double half_size) {
  Scene s;
  const double y = ground_height(lo, hi), cx = 0.5 * (lo.x + hi.x), cz = 0.5 * (lo.z + hi.z);
  // counter-clockwise seen from above
  const double corners[4][2] = {{-1.0, 1.0}, {1.0, 1.0}, {1.0, -1.0}, {-1.0, -1.0}};
  for (const auto& c : corners) {
    s.positions.emplace_back(float(cx + c[0] * half_size), float(y), float(cz + c[1] * half_size));
    PmrVertexAttr a{};
    a.normal[1] = 1.0f;
    for (float& k : a.color) k = 1.0f;
    a.scale = 1.0f;
    s.attributes.push_back(a);
  }
  const uint32_t corner_of[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& t : corner_of) {
    PmrTriangle tri{};
    for (int k = 0; k < 3; ++k) tri.v[k] = t[k];
    tri.material = 0;
    tri.face_normal[1] = 1.0f;
    tri.has_normals = 1;
    s.triangles.push_back(tri);
  }
  PmrMaterial m = default_material();
  for (int c = 0; c < 3; ++c) m.base_color[c] = 0.0f;
  m.alpha_mode = PMR_ALPHA_BLEND;
  m.metallic = 0.0f, m.roughness = 1.0f;
  m.flags = PMR_MATERIAL_SHADOW_CATCHER;
  s.materials.push_back(m);
  return s;
}

}  // namespace pmr
