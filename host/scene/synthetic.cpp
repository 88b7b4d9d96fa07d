// Procedural scenes for triangle-count sweeps (`pmr bench --synthetic TRIS`).
#include <cmath>
#include <random>

#include "pmr/error.h"
#include "pmr/scene.h"

namespace pmr {

Scene make_synthetic_scene(size_t triangles, uint32_t seed) {
  if (triangles < 1 || triangles > 50000000) throw Error("invalid --synthetic: expected 1 to 50000000 triangles");
  const int stacks = 8, slices = 14;  // 2 * slices * (stacks - 1) = 196 triangles a sphere
  const size_t per_sphere = size_t(2 * slices * (stacks - 1));
  const size_t spheres = std::max<size_t>(1, (triangles + per_sphere / 2) / per_sphere);
  Scene s;
  s.materials.push_back(default_material());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // radius shrinks with the count so that the spheres keep a similar total screen coverage
  const float base_r = 0.35f / std::cbrt(float(spheres));
  for (size_t k = 0; k < spheres; ++k) {
    const glm::vec3 c(4.0f * u(rng) - 2.0f, 2.0f * u(rng) - 1.0f, 3.0f * u(rng) - 1.5f);
    const float r = base_r * (0.5f + u(rng));
    const float col[4] = {0.2f + 0.8f * u(rng), 0.2f + 0.8f * u(rng), 0.2f + 0.8f * u(rng), 1.0f};
    const uint32_t base = uint32_t(s.positions.size());
    for (int i = 0; i <= stacks; ++i) {
      const float th = float(M_PI) * float(i) / stacks;
      for (int j = 0; j < slices; ++j) {
        const float ph = 2.0f * float(M_PI) * float(j) / slices;
        const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        s.positions.push_back(c + r * n);
        PmrVertexAttr a{};
        a.normal[0] = n.x, a.normal[1] = n.y, a.normal[2] = n.z;
        for (int q = 0; q < 4; ++q) a.color[q] = col[q];
        s.attributes.push_back(a);
      }
    }
    auto at = [&](int i, int j) { return base + uint32_t(i * slices + (j % slices)); };
    for (int i = 0; i < stacks; ++i)
      for (int j = 0; j < slices; ++j) {
        // counter-clockwise seen from outside
        const uint32_t q[4] = {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)};
        const uint32_t tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
        for (int t = 0; t < 2; ++t) {
          if ((i == 0 && t == 0) || (i == stacks - 1 && t == 1)) continue;  // degenerate at the poles
          PmrTriangle pt{};
          pt.v[0] = tri[t][0], pt.v[1] = tri[t][1], pt.v[2] = tri[t][2];
          const glm::vec3 e = glm::cross(s.positions[pt.v[1]] - s.positions[pt.v[0]], s.positions[pt.v[2]] - s.positions[pt.v[0]]);
          const glm::vec3 fn = glm::length(e) > 0 ? glm::normalize(e) : glm::vec3(0, 0, 1);
          pt.face_normal[0] = fn.x, pt.face_normal[1] = fn.y, pt.face_normal[2] = fn.z;
          pt.has_normals = 1;
          s.triangles.push_back(pt);
        }
      }
  }
  return s;
}

}  // namespace pmr
