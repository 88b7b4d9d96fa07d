#include "reference/transmission_reference.h"

#include <algorithm>
#include <cmath>

namespace pmr::ref {

TransmissionRay transmission_ray(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v, double ior,
                                 double thickness) {
  TransmissionRay r;
  r.direction = -v;
  r.end = p;
  if (!(thickness > 0.0)) return r;
  const double eta = ior >= 1.0 ? 1.0 / ior : 1.0;
  const glm::dvec3 t = glm::refract(-v, n, eta);
  if (glm::length(t) > 0.0) r.direction = glm::normalize(t);
  r.distance = thickness;
  r.end = p + r.direction * thickness;
  return r;
}

glm::dvec3 beer_lambert(const glm::dvec3& light, const glm::dvec3& color, double distance,
                        double attenuation_distance) {
  if (std::isinf(attenuation_distance)) return light;
  const double e = distance / attenuation_distance;
  return light * glm::dvec3(std::pow(color.x, e), std::pow(color.y, e), std::pow(color.z, e));
}

double transmission_lod(int view_w, double r, double ior) {
  return std::log2(double(view_w)) * r * std::clamp(2.0 * ior - 2.0, 0.0, 1.0);
}

}  // namespace pmr::ref
