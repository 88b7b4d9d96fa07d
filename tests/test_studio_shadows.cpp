// The studio casts shadows (DESIGN section 4d): with shadows on, its soft boxes are taken out of the
// image and drawn as distant area lights of their solid angle, shadowed as directional lights of that
// size, and the walls stay an environment. These tests check the split against the studio's own image
// (numerically, not through the code's formulas) and what the renders show.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pbr_support.h"
#include "shading/environment.h"
#include "shading/lights.h"
#include "shading/studio_environment.h"
#include "test_util.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The integral of f(w) dw over the shape of distant light l (its points q on the plane tangent to the
// unit sphere, dw = dA / |q|^3), by the midpoint rule on n x n cells of its extent.
template <typename F>
double over_shape(const SceneLight& l, int n, F f) {
  double sum = 0.0;
  const double du = l.width / n, dv = l.height / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = -0.5 * l.width + (i + 0.5) * du, v = -0.5 * l.height + (j + 0.5) * dv;
      if (l.type == SceneLightType::Disk && 4.0 * (u * u / (l.width * l.width) + v * v / (l.height * l.height)) > 1.0)
        continue;
      const glm::dvec3 q = l.position + u * l.right + v * l.up;
      const double r = glm::length(q);
      sum += f(q / r) * du * dv / (r * r * r);
    }
  return sum;
}

// The solid angle the box of light l spans in the studio's image, from the image itself: each texel of
// a 2048 x 1024 image within 35 degrees of the box's centre counts with the fraction f of it the box
// covers (the image is antialiased: texel = f box + (1 - f) walls, the walls image giving the second).
double image_solid_angle(const SceneLight& l) {
  static const EnvironmentImage img = studio_environment_image(2048), walls = studio_walls_image(2048);
  double sum = 0.0;
  for (int j = 0; j < img.height; ++j)
    for (int i = 0; i < img.width; ++i) {
      const double phi = ((i + 0.5) / img.width - 0.5) * 2.0 * kPi, theta = (j + 0.5) / img.height * kPi;
      const glm::dvec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      if (glm::dot(d, l.position) < std::cos(35.0 * kPi / 180.0)) continue;
      const size_t at = (size_t(j) * size_t(img.width) + size_t(i)) * 3;
      const double f = (double(img.rgb[at]) - double(walls.rgb[at])) / (double(l.intensity) - double(walls.rgb[at]));
      sum += f * std::sin(theta) * (2.0 * kPi / img.width) * (kPi / img.height);
    }
  return sum;
}

// Each box light faces the scene (right x up points toward it), reads the box's radiance at its centre
// in the studio's image and the walls' in the walls image, and spans the solid angle the box does in
// the image, within 1%.
TEST(StudioShadows, BoxLightsSpanTheBoxesOfTheImage) {
  const std::vector<SceneLight> boxes = studio_box_lights();
  ASSERT_EQ(boxes.size(), 4u);
  const Environment studio = Environment::studio(), walls = Environment::studio_walls();
  for (const SceneLight& l : boxes) {
    SCOPED_TRACE(l.name);
    EXPECT_TRUE(l.distant);
    EXPECT_NEAR(glm::length(l.position), 1.0, 1e-12);
    EXPECT_LT(glm::length(glm::cross(l.right, l.up) - l.position), 1e-9);
    EXPECT_LT(glm::length(l.direction + l.position), 1e-12);
    EXPECT_NEAR(studio.radiance(l.position).x, double(l.intensity), 1e-3 * l.intensity);
    EXPECT_LT(walls.radiance(l.position).x, 0.31);
    const double lights = over_shape(l, 400, [](const glm::dvec3&) { return 1.0; });
    const double image = image_solid_angle(l);
    std::printf("[ studio   ] %s: solid angle %.5f sr as a light, %.5f sr in the image\n", l.name.c_str(), lights,
                image);
    EXPECT_NEAR(lights, image, 0.01 * image);
  }
}

// Turning the studio turns its box lights with it: each turned light's centre reads its box's radiance
// in the studio turned alike, and the intensity scales them as it scales the image.
TEST(StudioShadows, BoxLightsTurnAndScaleWithTheStudio) {
  for (double deg : {0.0, 37.0, 90.0, -135.0}) {
    SCOPED_TRACE(deg);
    Environment studio = Environment::studio(), walls = Environment::studio_walls();
    studio.set_rotation(deg), walls.set_rotation(deg);
    walls.set_intensity(2.5);
    const std::vector<SceneLight> boxes = studio_box_lights(), turned = walls.distant_lights();
    ASSERT_EQ(turned.size(), boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) {
      EXPECT_NEAR(studio.radiance(turned[i].position).x, double(boxes[i].intensity), 1e-3 * boxes[i].intensity);
      EXPECT_FLOAT_EQ(turned[i].intensity, 2.5f * boxes[i].intensity);
      // (the rotation's cosine and sine are the tables' floats)
      EXPECT_LT(glm::length(glm::cross(turned[i].right, turned[i].up) - turned[i].position), 1e-6);
    }
  }
  // turned off (Blender's black world), it brings no lights to shade or to shadow
  Environment off = Environment::studio_walls();
  off.set_intensity(0.0);
  EXPECT_TRUE(off.distant_lights().empty());
}

// V = 1 gives the studio: the walls' irradiance plus the boxes' (integrated numerically over each box
// light's shape above the horizon) equals the studio's within 2%, for normals toward every box, the
// walls, the floor and between.
TEST(StudioShadows, WallsPlusBoxLightsAddUpToTheStudio) {
  const Environment studio = Environment::studio(), walls = Environment::studio_walls();
  const std::vector<SceneLight> boxes = walls.distant_lights();
  const glm::dvec3 normals[] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}, {0, 0, 1},
                                {0, 0, -1}, {1, 1, 1},  {-1, 1, 0}, {0, 1, -1}, {1, -1, 1}};
  for (const glm::dvec3& d : normals) {
    const glm::dvec3 n = glm::normalize(d);
    // I(n) is irradiance / pi: the cosine-weighted mean radiance
    double split = walls.irradiance(n).x;
    for (const SceneLight& l : boxes)
      split +=
          l.intensity / kPi * over_shape(l, 200, [&](const glm::dvec3& w) { return std::max(0.0, glm::dot(n, w)); });
    const double whole = studio.irradiance(n).x;
    std::printf("[ studio   ] n (%.2f %.2f %.2f): I = %.4f as lights and walls, %.4f as the image\n", n.x, n.y, n.z,
                split, whole);
    EXPECT_NEAR(split, whole, 0.02 * whole);
  }
}

PipelineConfig studio_config(bool shadows) {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.shading = Shading::Pbr;
  pc.shadows = shadows;
  pc.environment = std::make_shared<const Environment>(shadows ? Environment::studio_walls() : Environment::studio());
  return pc;
}

// With shadows on, a white rough dielectric facing the camera still reads 0.8 to 1.0 (nothing occludes
// it), and within 3% of what the studio's image gives it.
TEST(StudioShadows, AnUnoccludedWhiteDielectricReadsAsUnderTheImage) {
  const Rig rig = test::small_rig(5, 40, 24);
  const Scene s = test::white_rough_square();
  const test::Rendered on = test::render_with(s, rig, studio_config(true)),
                       off = test::render_with(s, rig, studio_config(false));
  double lo = 1e9, hi = -1e9, worst = 0.0;
  size_t covered = 0;
  for (size_t v = 0; v < on.key.size(); ++v) {
    if (on.key[v] == PMR_NO_KEY) continue;
    ++covered;
    for (int c = 0; c < 3; ++c) {
      const double a = test::half_value(on.volume[v * 4 + size_t(c)]),
                   b = test::half_value(off.volume[v * 4 + size_t(c)]);
      lo = std::min(lo, a), hi = std::max(hi, a), worst = std::max(worst, std::abs(a - b) / b);
    }
  }
  std::printf("[ studio   ] shadows on: white rough dielectric %.3f to %.3f, at most %.2f%% from the image's\n", lo, hi,
              100.0 * worst);
  EXPECT_GT(covered, size_t(500));
  EXPECT_GE(lo, 0.8);
  EXPECT_LE(hi, 1.0);
  EXPECT_LE(worst, 0.03);
}

// A slab held over a floor under the studio with shadows on: the floor under it loses the ceiling's
// light and the walls' above the slab's edges (the environment's occlusion), but the boxes low on the
// walls and the walls' lower parts still reach it. At least 30 voxels of view 1 read below 0.85 of
// what they read with shadows off, at 0.4 or more on average, while most voxels read nearly as before
// (the median ratio within 5% of 1: the slab hides a little of every floor point's sky).
TEST(StudioShadows, ASlabShadowsTheFloorUnderIt) {
  const Rig rig = test::small_rig(3, 96, 64);
  Scene s = test::empty_scene(true);
  s.materials[0].metallic = 0.0f, s.materials[0].roughness = 1.0f;
  for (float& c : s.materials[0].base_color) c = 0.8f;
  test::add_triangle(s, {-3.0f, -0.6f, 1.0f}, {3.0f, -0.6f, 1.0f}, {3.0f, -0.6f, -3.0f});
  test::add_triangle(s, {-3.0f, -0.6f, 1.0f}, {3.0f, -0.6f, -3.0f}, {-3.0f, -0.6f, -3.0f});
  test::add_triangle(s, {-0.8f, 0.2f, 0.6f}, {0.8f, 0.2f, 0.6f}, {0.8f, 0.2f, -0.6f});
  test::add_triangle(s, {-0.8f, 0.2f, 0.6f}, {0.8f, 0.2f, -0.6f}, {-0.8f, 0.2f, -0.6f});
  const test::Rendered on = test::render_with(s, rig, studio_config(true)),
                       off = test::render_with(s, rig, studio_config(false));
  const size_t base = size_t(rig.view_w) * size_t(rig.view_h);  // view 1
  std::vector<double> ratio;
  size_t dark = 0;
  double dark_sum = 0.0;
  for (size_t v = base; v < 2 * base; ++v) {
    if (on.key[v] == PMR_NO_KEY) continue;
    const double x = test::half_value(on.volume[v * 4]), y = test::half_value(off.volume[v * 4]);
    if (y <= 0.0) continue;
    ratio.push_back(x / y);
    if (x < 0.85 * y) ++dark, dark_sum += x / y;
  }
  ASSERT_GT(ratio.size(), size_t(300));
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  const double median = ratio[ratio.size() / 2];
  std::printf(
      "[ studio   ] slab over a floor: %zu of %zu voxels below 0.85 of the unshadowed (mean %.3f), median "
      "ratio %.3f\n",
      dark, ratio.size(), dark ? dark_sum / double(dark) : 0.0, median);
  EXPECT_GE(dark, size_t(30));
  EXPECT_GE(dark_sum, 0.4 * double(dark));
  EXPECT_NEAR(median, 1.0, 0.05);
}

}  // namespace
}  // namespace pmr
