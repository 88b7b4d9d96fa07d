#include "shading/environment_lights.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace pmr {

double luminance(const glm::dvec3& rgb) { return 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b; }

namespace {

constexpr double kPi = 3.14159265358979323846;

// A texel's luminance.
double luminance(const float* rgb) { return pmr::luminance(glm::dvec3(rgb[0], rgb[1], rgb[2])); }

// The median luminance of the image, from a histogram of log2 luminance (1/64 of an octave a bin,
// 2^-40 to 2^40): no copy of the image's values.
double median_luminance(const EnvironmentImage& img) {
  constexpr int kBins = 80 * 64;
  std::vector<uint64_t> hist(kBins + 1, 0);  // the last bin: zero
  const size_t n = size_t(img.width) * size_t(img.height);
  for (size_t t = 0; t < n; ++t) {
    const double y = luminance(&img.rgb[t * 3]);
    hist[y > 0.0 ? size_t(std::clamp((std::log2(y) + 40.0) * 64.0, 0.0, double(kBins - 1))) : size_t(kBins)]++;
  }
  if (hist[kBins] * 2 >= n) return 0.0;
  uint64_t below = hist[kBins];
  for (int b = 0; b < kBins; ++b)
    if ((below += hist[size_t(b)]) * 2 >= n) return std::exp2((b + 0.5) / 64.0 - 40.0);
  return 0.0;
}

glm::dvec3 texel_direction(const EnvironmentImage& img, size_t t) {
  const double u = (double(t % size_t(img.width)) + 0.5) / img.width,
               v = (double(t / size_t(img.width)) + 0.5) / img.height;
  const double phi = (u - 0.5) * 2.0 * kPi, theta = v * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

double texel_solid_angle(const EnvironmentImage& img, size_t t) {
  const double theta = (double(t / size_t(img.width)) + 0.5) / img.height * kPi;
  return (2.0 * kPi / img.width) * (kPi / img.height) * std::sin(theta);
}

// One region of bright texels, grown from a seed over its 4-neighbours (wrapping in longitude).
struct Region {
  std::vector<size_t> texels;
  double solid_angle = 0.0, power = 0.0;  // luminance x solid angle
  glm::dvec3 weighted_direction{0.0}, rim{0.0};
  size_t rim_texels = 0;
};

Region grow_region(const EnvironmentImage& img, const std::vector<uint8_t>& bright, std::vector<uint8_t>& seen,
                   size_t seed) {
  const size_t W = size_t(img.width), H = size_t(img.height);
  Region r;
  std::vector<size_t> stack = {seed};
  seen[seed] = 1;
  while (!stack.empty()) {
    const size_t t = stack.back();
    stack.pop_back();
    const double w = texel_solid_angle(img, t), y = luminance(&img.rgb[t * 3]);
    r.texels.push_back(t), r.solid_angle += w, r.power += y * w;
    r.weighted_direction += y * w * texel_direction(img, t);
    const size_t x = t % W, row = t / W;
    const size_t next[4] = {row * W + (x + 1) % W, row * W + (x + W - 1) % W, row > 0 ? t - W : t,
                            row + 1 < H ? t + W : t};
    for (size_t q : next) {
      if (q == t) continue;
      if (!bright[q]) {
        r.rim += glm::dvec3(img.rgb[q * 3], img.rgb[q * 3 + 1], img.rgb[q * 3 + 2]), ++r.rim_texels;
      } else if (!seen[q]) {
        seen[q] = 1, stack.push_back(q);
      }
    }
  }
  return r;
}

// The distant disk that takes region r's light above its rim out of the image, and the fill.
SceneLight region_light(EnvironmentImage& img, const Region& r, int index) {
  const glm::dvec3 fill = r.rim_texels ? r.rim / double(r.rim_texels) : glm::dvec3(0.0);
  glm::dvec3 power(0.0);
  for (size_t t : r.texels) {
    const double w = texel_solid_angle(img, t);
    for (int c = 0; c < 3; ++c) {
      power[c] += (double(img.rgb[t * 3 + size_t(c)]) - fill[c]) * w;
      img.rgb[t * 3 + size_t(c)] = float(fill[c]);
    }
  }
  const glm::dvec3 L = glm::max(power, glm::dvec3(0.0)) / r.solid_angle;
  const double peak = std::max({L.x, L.y, L.z, 1e-30});
  SceneLight l;
  l.name = "environment light " + std::to_string(index);
  l.light = -1, l.node = -1, l.distant = true, l.type = SceneLightType::Disk;
  for (int c = 0; c < 3; ++c) l.color[c] = float(L[c] / peak);
  l.intensity = float(peak);
  l.position = glm::normalize(r.weighted_direction);
  const glm::dvec3 helper = std::abs(l.position.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  l.right = glm::normalize(glm::cross(helper, l.position));
  l.up = glm::cross(l.position, l.right);  // right x up = position
  l.direction = -l.position;
  // a cap of the region's solid angle: 2 pi (1 - cos a); its disk at distance 1 has radius tan a
  const double cos_a = std::max(1.0 - r.solid_angle / (2.0 * kPi), 1e-6);
  l.width = l.height = 2.0 * std::sqrt(1.0 - cos_a * cos_a) / cos_a;
  l.size = float(l.height), l.aspect = 1.0f;
  return l;
}

}  // namespace

std::vector<SceneLight> take_out_bright_regions(EnvironmentImage& image) {
  std::vector<SceneLight> lights;
  const size_t n = size_t(image.width) * size_t(image.height);
  if (n == 0) return lights;
  double total = 0.0;
  for (size_t t = 0; t < n; ++t) total += luminance(&image.rgb[t * 3]) * texel_solid_angle(image, t);
  const double threshold = kBrightOverMedian * std::max(median_luminance(image), 1e-3 * total / (4.0 * kPi));
  std::vector<uint8_t> bright(n, 0), seen(n, 0);
  size_t count = 0;
  for (size_t t = 0; t < n; ++t) count += bright[t] = luminance(&image.rgb[t * 3]) > threshold;
  // more than 5% of the image bright: no few bright regions to take out (a bright sky stays a sky)
  if (count == 0 || count * 20 > n) return lights;
  std::vector<Region> regions;
  for (size_t t = 0; t < n; ++t) {
    if (!bright[t] || seen[t]) continue;
    Region r = grow_region(image, bright, seen, t);
    if (r.solid_angle <= kMaxRegionSolidAngle && r.power >= kMinRegionShare * total) regions.push_back(std::move(r));
  }
  std::stable_sort(regions.begin(), regions.end(), [](const Region& a, const Region& b) { return a.power > b.power; });
  if (regions.size() > size_t(kMaxEnvironmentLights)) regions.resize(size_t(kMaxEnvironmentLights));
  for (size_t i = 0; i < regions.size(); ++i) lights.push_back(region_light(image, regions[i], int(i + 1)));
  return lights;
}

}  // namespace pmr
