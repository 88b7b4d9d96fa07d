// An environment image's sun taken out as a light (DESIGN section 4d, host/shading/environment_lights.h):
// the rule finds it, keeps the image's power, leaves an image without one alone, and the sun then
// casts its shadow.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "environment_maps.h"
#include "pbr_support.h"
#include "shading/environment.h"
#include "shading/environment_lights.h"
#include "test_util.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The image's power per channel: the sum of radiance x solid angle over its texels.
glm::dvec3 image_power(const EnvironmentImage& img) {
  glm::dvec3 sum(0.0);
  for (int j = 0; j < img.height; ++j) {
    const double w = (2.0 * kPi / img.width) * (kPi / img.height) * std::sin((j + 0.5) / img.height * kPi);
    for (int i = 0; i < img.width; ++i)
      for (int c = 0; c < 3; ++c) sum[c] += img.rgb[(size_t(j) * size_t(img.width) + size_t(i)) * 3 + size_t(c)] * w;
  }
  return sum;
}

// A light's power per channel: luminance x colour x its solid angle (a disk of radius R at distance 1:
// 2 pi (1 - 1 / sqrt(1 + R^2))).
glm::dvec3 light_power(const SceneLight& l) {
  const double R = 0.5 * l.width, solid = 2.0 * kPi * (1.0 - 1.0 / std::sqrt(1.0 + R * R));
  return glm::dvec3(l.color[0], l.color[1], l.color[2]) * double(l.intensity) * solid;
}

// The sky's 3-degree sun (about 1000 times the sky) becomes one distant disk toward it, of about its
// solid angle; the image loses exactly the power the light gets, and no texel of it stays bright.
TEST(EnvironmentLights, TheSunOfASkyBecomesOneLight) {
  const EnvironmentImage sky = test::make_map(256, 128, test::sun_sky);
  EnvironmentImage rest = sky;
  const std::vector<SceneLight> lights = take_out_bright_regions(rest);
  ASSERT_EQ(lights.size(), 1u);
  const SceneLight& sun = lights[0];
  const double off = std::acos(std::min(1.0, glm::dot(sun.position, test::sun_direction()))) * 180.0 / kPi;
  const double solid = 2.0 * kPi * (1.0 - 1.0 / std::sqrt(1.0 + 0.25 * sun.width * sun.width));
  const glm::dvec3 before = image_power(sky), after = image_power(rest), taken = light_power(sun);
  std::printf(
      "[ env sun  ] %.2f degrees from the sun, %.5f sr (the disc: %.5f), luminance %.0f; power %.3f = %.3f + %.3f\n",
      off, solid, 2.0 * kPi * (1.0 - std::cos(3.0 * kPi / 180.0)), double(sun.intensity), before.y, after.y, taken.y);
  EXPECT_TRUE(sun.distant);
  EXPECT_LT(off, 0.5);
  EXPECT_NEAR(solid, 2.0 * kPi * (1.0 - std::cos(3.0 * kPi / 180.0)), 0.15 * solid);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(after[c] + taken[c], before[c], 1e-5 * before[c]) << "channel " << c;
  float brightest = 0.0f;
  for (float v : rest.rgb) brightest = std::max(brightest, v);
  EXPECT_LT(brightest, 5.0f);
}

// Without a sun (a sky gradient), or with a bright half (more than 5% of the image bright), nothing is
// taken out and the image stays as it was, bit for bit.
TEST(EnvironmentLights, AnImageWithoutASunKeepsItsImage) {
  const auto gradient = [](glm::dvec3 d) { return glm::dvec3(0.3, 0.5, 0.9) * (1.0 + d.y); };
  const auto half = [](glm::dvec3 d) { return glm::dvec3(d.x > 0.0 ? 500.0 : 0.2); };
  for (const auto& f : {std::function<glm::dvec3(glm::dvec3)>(gradient), std::function<glm::dvec3(glm::dvec3)>(half)}) {
    const EnvironmentImage img = test::make_map(128, 64, f);
    EnvironmentImage rest = img;
    EXPECT_TRUE(take_out_bright_regions(rest).empty());
    EXPECT_EQ(rest.rgb, img.rgb);
  }
}

// A pole on a plane under the sky with shadows on: the sun, up to the right and behind the pole as the
// camera sees it, throws the pole's shadow to the front left. In the middle view at least 20 voxels
// left of the pole read below half of what they read with shadows off, and none right of it do.
TEST(EnvironmentLights, ASunInTheImageCastsItsShadow) {
  const Rig rig = test::small_rig(3, 192, 128);  // the camera sees the plane at a grazing angle
  Scene s = test::empty_scene(false);
  s.materials[0].metallic = 0.0f, s.materials[0].roughness = 1.0f;
  test::add_triangle(s, {-3.0f, -0.6f, 2.0f}, {3.0f, -0.6f, 2.0f}, {3.0f, -0.6f, -3.0f});
  test::add_triangle(s, {-3.0f, -0.6f, 2.0f}, {3.0f, -0.6f, -3.0f}, {-3.0f, -0.6f, -3.0f});
  // the pole: 0.3 x 0.8 x 0.3, standing on the plane at the origin (its four sides); its shadow, 1.1 m
  // long, falls toward (-0.48, 0, 0.66)
  const float a = -0.15f, b = 0.15f, y0 = -0.6f, y1 = 0.2f;
  const glm::vec3 c[8] = {{a, y0, a}, {b, y0, a}, {b, y0, b}, {a, y0, b},
                          {a, y1, a}, {b, y1, a}, {b, y1, b}, {a, y1, b}};
  const int faces[4][4] = {{3, 2, 6, 7}, {1, 0, 4, 5}, {2, 1, 5, 6}, {0, 3, 7, 4}};
  for (const auto& f : faces) {
    test::add_triangle(s, c[f[0]], c[f[1]], c[f[2]]);
    test::add_triangle(s, c[f[0]], c[f[2]], c[f[3]]);
  }
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.shading = Shading::Pbr;
  pc.shadows = true;
  pc.environment = std::make_shared<const Environment>(
      Environment::with_lights_taken_out(test::make_map(256, 128, test::sun_sky), "sky"));
  ASSERT_EQ(pc.environment->distant_lights().size(), 1u);
  const test::Rendered on = test::render_with(s, rig, pc);
  pc.shadows = false;
  const test::Rendered off = test::render_with(s, rig, pc);
  const size_t W = size_t(rig.view_w), base = W * size_t(rig.view_h);  // view 1
  size_t left = 0, right = 0;
  for (size_t v = base; v < 2 * base; ++v) {
    if (on.key[v] == PMR_NO_KEY) continue;
    const double x = test::half_value(on.volume[v * 4 + 1]), y = test::half_value(off.volume[v * 4 + 1]);
    if (!(x < 0.5 * y)) continue;
    const size_t column = (v - base) % W;
    left += column + 8 < W / 2, right += column > W / 2 + 8;
  }
  std::printf("[ env sun  ] pole's shadow: %zu voxels left of it, %zu right\n", left, right);
  EXPECT_GE(left, 20u);
  EXPECT_EQ(right, 0u);
}

}  // namespace
}  // namespace pmr
