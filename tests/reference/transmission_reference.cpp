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

SourceImage make_source(int w, int h, const std::vector<glm::dvec4>& image) {
  SourceImage s;
  s.w.push_back(w), s.h.push_back(h), s.levels.push_back(image);
  while (s.w.back() > 1 || s.h.back() > 1) {
    const int pw = s.w.back(), ph = s.h.back(), lw = std::max(1, pw / 2), lh = std::max(1, ph / 2);
    const std::vector<glm::dvec4>& prev = s.levels.back();
    std::vector<glm::dvec4> level(size_t(lw) * size_t(lh));
    for (int y = 0; y < lh; ++y)
      for (int x = 0; x < lw; ++x) {
        const int x0 = std::min(2 * x, pw - 1), x1 = std::min(2 * x + 1, pw - 1);
        const int y0 = std::min(2 * y, ph - 1), y1 = std::min(2 * y + 1, ph - 1);
        level[size_t(y * lw + x)] = 0.25 * (prev[size_t(y0 * pw + x0)] + prev[size_t(y0 * pw + x1)] +
                                            prev[size_t(y1 * pw + x0)] + prev[size_t(y1 * pw + x1)]);
      }
    s.w.push_back(lw), s.h.push_back(lh), s.levels.push_back(std::move(level));
  }
  return s;
}

namespace {

glm::dvec4 bilinear_level(const SourceImage& s, int k, const glm::dvec2& raster) {
  const int w = s.w[size_t(k)], h = s.h[size_t(k)];
  const double tx = raster.x * w / s.w[0] - 0.5, ty = raster.y * h / s.h[0] - 0.5;
  const double fx0 = std::floor(tx), fy0 = std::floor(ty), fx = tx - fx0, fy = ty - fy0;
  auto at = [&](int x, int y) {
    return s.levels[size_t(k)][size_t(std::clamp(y, 0, h - 1) * w + std::clamp(x, 0, w - 1))];
  };
  const int x0 = int(fx0), y0 = int(fy0);
  return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), fx), glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), fx), fy);
}

}  // namespace

glm::dvec4 sample_source(const SourceImage& s, const glm::dvec2& raster, double lod) {
  if (!(raster.x >= 0.0 && raster.x <= s.w[0] && raster.y >= 0.0 && raster.y <= s.h[0])) return glm::dvec4(0.0);
  const double l = std::clamp(lod, 0.0, double(s.levels.size() - 1));
  const int k = int(l);
  const double f = l - k;
  const glm::dvec4 a = bilinear_level(s, k, raster);
  return f == 0.0 ? a : glm::mix(a, bilinear_level(s, k + 1, raster), f);
}

double transmission_lod(int view_w, double r, double ior) {
  return std::log2(double(view_w)) * r * std::clamp(2.0 * ior - 2.0, 0.0, 1.0);
}

}  // namespace pmr::ref
