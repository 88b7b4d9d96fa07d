// Double-precision reference of transmission (DESIGN section 4c step 2, docs/SHADING.md): the refracted
// ray and its end point, Beer-Lambert attenuation and the level of detail the source is read at. The
// kernels' cl/transmission.h computes the same in float.
#pragma once
#include <vector>

#include <glm/glm.hpp>

namespace pmr::ref {

// The view ray -v (v unit, toward the eye) refracted at unit normal n, Snell with eta = 1 / ior (ior 0:
// straight on), travelling `thickness` along it from p; thickness 0 (a thin surface): straight on, no
// travel.
struct TransmissionRay {
  glm::dvec3 direction, end;
  double distance = 0.0;
};
TransmissionRay transmission_ray(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v, double ior,
                                 double thickness);
// light x color^(distance / attenuation_distance) per channel (an infinite distance: no attenuation).
glm::dvec3 beer_lambert(const glm::dvec3& light, const glm::dvec3& color, double distance, double attenuation_distance);
// The source's level of detail: log2(view_w) x r x clamp(2 ior - 2, 0, 1), r the clamped roughness.
double transmission_lod(int view_w, double r, double ior);

// One view's transmission source: its image (premultiplied RGBA, [y][x]) and mip chain, level k of
// max(1, w >> k) x max(1, h >> k) pixels, each the 2x2 box mean of the level before (the last row or
// column of an odd side left out), down to 1 x 1.
struct SourceImage {
  std::vector<int> w, h;
  std::vector<std::vector<glm::dvec4>> levels;
};
SourceImage make_source(int w, int h, const std::vector<glm::dvec4>& image);
// Trilinear at raster point (x, y) (level-0 pixels, centers at + 1/2), bilinear per level clamped to
// the edge, the level clamped to the chain; (0, 0, 0, 0) off the raster.
glm::dvec4 sample_source(const SourceImage& s, const glm::dvec2& raster, double lod);

}  // namespace pmr::ref
