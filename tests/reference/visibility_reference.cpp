#include "reference/visibility_reference.h"

#include "reference/shade_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pmr::ref {

namespace {

// Moller-Trumbore: t of the ray's intersection with triangle (a, b, c), or infinity; *u, *v its
// barycentrics of b and c.
double ray_triangle(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c, double* u_out, double* v_out) {
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
  *u_out = u, *v_out = v;
  return glm::dot(e2, r) * inv;
}

}  // namespace

double caster_opacity(const Scene& scene, uint32_t tri, const glm::dvec3& b) {
  const PmrMaterial& m = scene.materials[scene.triangles[tri].material];
  if (m.transmission > 0.0f) return std::clamp(1.0 - double(m.transmission), 0.0, 1.0);
  if (m.alpha_mode == PMR_ALPHA_OPAQUE) return 1.0;
  const double alpha = base_color(scene, tri, b).a;
  if (m.alpha_mode == PMR_ALPHA_MASK) return alpha >= double(m.alpha_cutoff) ? 1.0 : 0.0;
  return std::clamp(alpha, 0.0, 1.0);
}

double transmittance(const Scene& scene, const glm::dvec3& o, const glm::dvec3& d, double t_min, double t_max) {
  double light = 1.0;
  for (uint32_t k = 0; k < scene.triangles.size() && light > 0.0; ++k) {
    const PmrTriangle& t = scene.triangles[k];
    double u = 0.0, v = 0.0;
    const double h = ray_triangle(o, d, glm::dvec3(scene.positions[t.v[0]]), glm::dvec3(scene.positions[t.v[1]]),
                                  glm::dvec3(scene.positions[t.v[2]]), &u, &v);
    if (h > t_min && h < t_max) light *= 1.0 - caster_opacity(scene, k, glm::dvec3(1.0 - u - v, u, v));
  }
  return light;
}

double ray_visibility(const Scene& scene, const glm::dvec3& p, const PunctualLight& light, double start) {
  const double inf = std::numeric_limits<double>::infinity();
  if (light.type == LightType::Directional) return transmittance(scene, p, -light.direction, start, inf);
  const glm::dvec3 to = light.position - p;
  const double dist = glm::length(to);
  return transmittance(scene, p, to / dist, start, dist);
}

}  // namespace pmr::ref
