#include "shading/studio_environment.h"

#include <cmath>

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A soft box: a rectangle in longitude phi (0 at -Z, +90 degrees at +X) and polar angle theta (0 at +Y),
// its centre and half sizes in degrees, and its radiance.
struct SoftBox {
  double phi, theta, half_phi, half_theta, radiance;
};

// Above, left (-X), right (+X) and behind the camera (+Z): a key, a fill and a rim light.
constexpr SoftBox kBoxes[] = {
    {0.0, 0.0, 180.0, 10.0, 8.0},     // the ceiling panel: every longitude down to 10 degrees
    {-90.0, 75.0, 10.0, 14.0, 16.0},  // left (-X), the key
    {90.0, 80.0, 7.0, 10.0, 10.0},    // right (+X), the fill
    {180.0, 72.0, 12.0, 8.0, 20.0},   // behind the camera (+Z), lighting the front
};

// Longitude difference a - b wrapped into (-180, 180].
double wrapped(double a, double b) {
  double d = std::fmod(a - b, 360.0);
  if (d > 180.0) d -= 360.0;
  if (d <= -180.0) d += 360.0;
  return d;
}

// Radiance of the room toward (phi, theta) in degrees: the walls' grey, or a box.
double studio_radiance(double phi, double theta) {
  for (const SoftBox& b : kBoxes)
    if (std::fabs(wrapped(phi, b.phi)) <= b.half_phi && std::fabs(theta - b.theta) <= b.half_theta) return b.radiance;
  const double y = std::cos(theta * kPi / 180.0);
  return y >= 0.0 ? 0.22 + 0.08 * y : 0.22 + 0.07 * y;  // floor 0.15 to ceiling 0.3
}

}  // namespace

EnvironmentImage studio_environment_image(int width) {
  EnvironmentImage img;
  img.width = width, img.height = width / 2;
  img.rgb.resize(size_t(img.width) * size_t(img.height) * 3);
  // direction of texel (i, j): u = 1/2 + phi / 360, v = theta / 180 (DESIGN 4b's mapping); each texel
  // the mean of 4 x 4 points, so that the boxes' borders are antialiased in the image itself
  for (int j = 0; j < img.height; ++j)
    for (int i = 0; i < img.width; ++i) {
      double sum = 0.0;
      for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
          const double u = (i + (a + 0.5) / 4.0) / img.width, v = (j + (b + 0.5) / 4.0) / img.height;
          sum += studio_radiance((u - 0.5) * 360.0, v * 180.0);
        }
      for (int c = 0; c < 3; ++c)
        img.rgb[(size_t(j) * size_t(img.width) + size_t(i)) * 3 + size_t(c)] = float(sum / 16.0);
    }
  return img;
}

}  // namespace pmr
