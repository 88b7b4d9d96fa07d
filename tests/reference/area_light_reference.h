// Double-precision reference of area lights (rectangles and disks of uniform radiance) under the pbr
// BRDF (docs/SHADING.md): the integrals the LTC approximation of host/shading/ltc.h stands for, by
// adaptive cubature over the light's area, and the exact form factor of a polygon. Independent of
// ltc.h: no LTC, no table, no float.
#pragma once
#include <vector>

#include <glm/glm.hpp>

namespace pmr::ref {

// A one-sided Lambertian emitter: the rectangle center + a u + b v (|a|, |b| <= 1), or the disk
// center + a u + b v (a^2 + b^2 <= 1; then u and v are orthogonal and as long as the radius). It
// emits toward normalize(cross(u, v)); a point behind its plane receives nothing.
struct AreaLight {
  bool disk = false;
  glm::dvec3 center{0.0}, u{1.0, 0.0, 0.0}, v{0.0, 1.0, 0.0};
};

// For the surface point p with unit normal n seen from the unit direction v, and roughness r (already
// clamped, alpha = r^2): (x, y) = the integrals over the light's solid angle of D Vis n.l and of
// (1 - v.h)^5 D Vis n.l, n.l > 0. A light of radiance 1 gives the specular radiance F0 (x - y) + F90 y.
// Relative accuracy about tol (adaptive cubature with a grid graded about the highlight).
glm::dvec2 area_specular(const AreaLight& light, const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v,
                         double r, double tol = 1e-5);

// The same integrals over the whole hemisphere (n = +z, v = (sqrt(1 - n.v^2), 0, n.v)): the amplitudes
// norm = x and fresnel = y of host/shading/ltc.h.
glm::dvec2 hemisphere_specular(double n_dot_v, double r, double tol = 1e-7);

// The form factor (1 / pi) x the integral of n.l > 0 over the light's solid angle, by the same cubature.
double area_form_factor(const AreaLight& light, const glm::dvec3& p, const glm::dvec3& n, double tol = 1e-7);

// The exact form factor of the spherical polygon with vertices `poly` (relative to the point, in the
// order of area_light_polygon) under the horizon of n: Lambert's formula after clipping the polygon to
// n.x >= 0; 0 if the point sees the polygon's back.
double polygon_form_factor(const std::vector<glm::dvec3>& poly, const glm::dvec3& n);

// The rectangle's four corners relative to p, ordered so that polygon_form_factor is positive in front.
std::vector<glm::dvec3> area_light_polygon(const AreaLight& rect, const glm::dvec3& p);

}  // namespace pmr::ref
