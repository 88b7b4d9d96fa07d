#include "reference/visibility_reference.h"

#include <cmath>
#include <limits>

namespace pmr::ref {

namespace {

// Moller-Trumbore: t of the ray's intersection with triangle (a, b, c), or infinity.
double ray_triangle(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c) {
  const double inf = std::numeric_limits<double>::infinity();
  const glm::dvec3 e1 = b - a, e2 = c - a, q = glm::cross(d, e2);
  const double det = glm::dot(e1, q);
  if (std::abs(det) < 1e-300) return inf;
  const double inv = 1.0 / det;
  const glm::dvec3 s = o - a;
  const double u = glm::dot(s, q) * inv;
  if (u < 0.0 || u > 1.0) return inf;
  const glm::dvec3 r = glm::cross(s, e1);
  const double v = glm::dot(d, r) * inv;
  if (v < 0.0 || u + v > 1.0) return inf;
  return glm::dot(e2, r) * inv;
}

bool casts(const Scene& scene, const PmrTriangle& t) {
  const PmrMaterial& m = scene.materials[t.material];
  return m.alpha_mode != PMR_ALPHA_BLEND && !(m.transmission > 0.0f);
}

}  // namespace

double nearest_caster(const Scene& scene, const glm::dvec3& o, const glm::dvec3& d, double t_min) {
  double best = std::numeric_limits<double>::infinity();
  for (const PmrTriangle& t : scene.triangles) {
    if (!casts(scene, t)) continue;
    const double h = ray_triangle(o, d, glm::dvec3(scene.positions[t.v[0]]), glm::dvec3(scene.positions[t.v[1]]),
                                  glm::dvec3(scene.positions[t.v[2]]));
    if (h > t_min && h < best) best = h;
  }
  return best;
}

double ray_visibility(const Scene& scene, const glm::dvec3& p, const PunctualLight& light, double start) {
  if (light.type == LightType::Directional) return std::isinf(nearest_caster(scene, p, -light.direction, start));
  const glm::dvec3 to = light.position - p;
  const double dist = glm::length(to);
  return nearest_caster(scene, p, to / dist, start) >= dist ? 1.0 : 0.0;
}

}  // namespace pmr::ref
