#include "shading/studio_environment.h"

#include <cmath>

#include <glm/glm.hpp>

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

// The walls' radiance toward polar angle theta (degrees): grey, from 0.15 at the floor to 0.3 at the ceiling.
double wall_radiance(double theta) {
  const double y = std::cos(theta * kPi / 180.0);
  return y >= 0.0 ? 0.22 + 0.08 * y : 0.22 + 0.07 * y;
}

// Radiance of the room toward (phi, theta) in degrees: the walls' grey, or a box when `boxes`.
double studio_radiance(double phi, double theta, bool boxes) {
  if (boxes)
    for (const SoftBox& b : kBoxes)
      if (std::fabs(wrapped(phi, b.phi)) <= b.half_phi && std::fabs(theta - b.theta) <= b.half_theta) return b.radiance;
  return wall_radiance(theta);
}

// The image of the room, each texel the mean of 4 x 4 points, so that the boxes' borders are
// antialiased in the image itself. Direction of texel (i, j): u = 1/2 + phi / 360, v = theta / 180
// (DESIGN 4b's mapping).
EnvironmentImage room_image(int width, bool boxes) {
  EnvironmentImage img;
  img.width = width, img.height = width / 2;
  img.rgb.resize(size_t(img.width) * size_t(img.height) * 3);
  for (int j = 0; j < img.height; ++j)
    for (int i = 0; i < img.width; ++i) {
      double sum = 0.0;
      for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
          const double u = (i + (a + 0.5) / 4.0) / img.width, v = (j + (b + 0.5) / 4.0) / img.height;
          sum += studio_radiance((u - 0.5) * 360.0, v * 180.0, boxes);
        }
      for (int c = 0; c < 3; ++c)
        img.rgb[(size_t(j) * size_t(img.width) + size_t(i)) * 3 + size_t(c)] = float(sum / 16.0);
    }
  return img;
}

// The unit direction of (phi, theta) in degrees: phi from -Z toward +X, theta from +Y.
glm::dvec3 direction_of(double phi, double theta) {
  const double p = phi * kPi / 180.0, t = theta * kPi / 180.0;
  return {std::sin(t) * std::sin(p), std::cos(t), -std::sin(t) * std::cos(p)};
}

// Box b as a distant light: the ceiling (every longitude) a disk of the cap's angular radius, whose
// solid angle 2 pi (1 - cos) is the cap's; the others a rect of half height tan(half_theta) along the
// meridian and the half width that gives it the patch's solid angle dphi (cos(theta - h) - cos(theta + h)):
// a centred rect of half sides a, b at distance 1 subtends 4 atan(a b / sqrt(1 + a^2 + b^2)).
SceneLight box_light(const SoftBox& b, const char* name) {
  SceneLight l;
  l.name = name, l.light = -1, l.node = -1, l.distant = true;
  l.intensity = float(b.radiance);
  const double h = b.half_theta * kPi / 180.0;
  if (b.half_phi >= 180.0) {  // a cap about the pole
    l.type = SceneLightType::Disk;
    l.position = {0.0, 1.0, 0.0}, l.right = {1.0, 0.0, 0.0}, l.up = {0.0, 0.0, -1.0};
    l.width = l.height = 2.0 * std::tan(h);
  } else {
    l.type = SceneLightType::Rect;
    l.position = direction_of(b.phi, b.theta);
    l.up = glm::normalize(glm::dvec3(0.0, 1.0, 0.0) - l.position * l.position.y);  // along the meridian, up
    l.right = glm::cross(l.up, l.position);                                        // right x up = position
    const double t0 = b.theta * kPi / 180.0;
    const double solid = 2.0 * b.half_phi * kPi / 180.0 * (std::cos(t0 - h) - std::cos(t0 + h));
    const double q = std::tan(0.25 * solid), y = std::tan(h);
    l.height = 2.0 * y, l.width = 2.0 * q * std::sqrt((1.0 + y * y) / (y * y - q * q));
  }
  l.direction = -l.position;
  l.size = float(l.height), l.aspect = float(l.width / l.height);
  return l;
}

}  // namespace

EnvironmentImage studio_environment_image(int width) { return room_image(width, true); }

EnvironmentImage studio_walls_image(int width) { return room_image(width, false); }

std::vector<SceneLight> studio_box_lights() {
  const char* names[] = {"studio ceiling", "studio key", "studio fill", "studio rim"};
  std::vector<SceneLight> out;
  for (size_t i = 0; i < sizeof kBoxes / sizeof kBoxes[0]; ++i) out.push_back(box_light(kBoxes[i], names[i]));
  return out;
}

}  // namespace pmr
