// Area lights (EXT_lights_area; DESIGN section 4d): what cl/area_lights.h integrates over a light's shape
// at a point (tests/probes/area_light_probe.cl), against integration over the light's area in double
// precision; and EXT_lights_area as the loader reads it.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "area_light_probe.h"
#include "gltf_builder.h"
#include "pbr_support.h"
#include "reference/area_light_reference.h"
#include "reference/shade_reference.h"
#include "shading/lights.h"
#include "test_util.h"

namespace pmr {
namespace {

// An area light at `center` emitting along `direction`, its plane's axes `right` (made orthogonal to
// the direction) and up = -direction x right, placed as the loader places one.
SceneLight area_light(SceneLightType type, glm::dvec3 center, glm::dvec3 direction, glm::dvec3 right, double width,
                      double height) {
  SceneLight l;
  l.type = type;
  l.position = center, l.direction = glm::normalize(direction);
  l.right = glm::normalize(right - glm::dot(right, l.direction) * l.direction);
  l.up = glm::cross(-l.direction, l.right);
  l.width = width, l.height = height;
  return l;
}

// The kernels' view of `light` at each point (tests/area_light_probe.h).
std::vector<test::AreaProbeResult> probe(const SceneLight& light, const std::vector<test::AreaProbePoint>& at) {
  return test::probe_area_lights({device_light(light)}, at);
}

// The integral over the light's shape of the cosine-weighted solid angle at p about n (clamped at p's
// horizon): the sum over a fine grid of the shape's area of cos_light max(cos_n, 0) / d^2 dA.
double cosine_integral(const SceneLight& light, const glm::dvec3& p, const glm::dvec3& n, int grid = 400) {
  const double du = 2.0 / grid, dA = 0.25 * light.width * light.height * du * du;
  double sum = 0.0;
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      const double u = -1.0 + (i + 0.5) * du, v = -1.0 + (j + 0.5) * du;
      if (light.type == SceneLightType::Disk && u * u + v * v > 1.0) continue;
      const glm::dvec3 d = light.position + 0.5 * u * light.width * light.right + 0.5 * v * light.height * light.up - p;
      const double len2 = glm::dot(d, d), len = std::sqrt(len2);
      sum += std::max(0.0, -glm::dot(d, light.direction) / len) * std::max(0.0, glm::dot(d, n) / len) / len2 * dA;
    }
  return sum;
}

// The diffuse lobe's integral (Lambert's formula over the shape clipped to the horizon) against the
// integration over the light's area, within 1% of the peak: a rect and a disk over a plane, and a
// rect standing across the receivers' horizon.
TEST(AreaLights, DiffuseIntegralMatchesIntegrationOverTheLight) {
  const SceneLight over = area_light(SceneLightType::Rect, {0.2, 1.5, -0.1}, {0.1, -1.0, 0.2}, {1, 0, 0}, 2.0, 1.0);
  SceneLight disk = over;
  disk.type = SceneLightType::Disk, disk.width = disk.height = 1.2;
  // facing the receivers sideways, half below their plane
  const SceneLight across = area_light(SceneLightType::Rect, {0.0, 0.1, -1.0}, {0.0, 0.0, 1.0}, {1, 0, 0}, 1.5, 1.0);
  for (const SceneLight& light : {over, disk, across}) {
    SCOPED_TRACE(light.position.y < 1.0 ? "across the horizon" : light_type_name(light.type));
    std::vector<test::AreaProbePoint> at;
    for (double x = -2.0; x <= 2.0; x += 0.25)
      for (double z = -2.0; z <= 2.0; z += 0.25) at.push_back({0, {x, 0.0, z}, {0, 1, 0}, {0, 1, 0}});
    const std::vector<test::AreaProbeResult> got = probe(light, at);
    std::vector<double> want;
    double peak = 0.0;
    for (const test::AreaProbePoint& q : at)
      want.push_back(cosine_integral(light, q.p, q.n)), peak = std::max(peak, want.back());
    ASSERT_GT(peak, 0.1);
    double worst = 0.0;
    size_t lit = 0;
    for (size_t i = 0; i < at.size(); ++i) {
      worst = std::max(worst, std::abs(got[i].cosine - want[i]) / peak);
      lit += want[i] > 0.01 * peak;
    }
    EXPECT_LE(worst, 0.01) << "of the peak " << peak << "; at the middle point " << got[at.size() / 2].cosine << " e "
                           << got[at.size() / 2].e << ", want " << want[at.size() / 2];
    EXPECT_GT(lit, at.size() / 3);
    std::printf("[ area     ] diffuse: %zu points, worst |error| %.5f of the peak\n", at.size(), worst);
  }
}

// The vector irradiance of a small, far light is that of a point light at its center of intensity
// L A cos(theta_light): its direction toward the center, e = A cos_light / d^2 per unit luminance; a
// point behind the emitting side receives nothing.
TEST(AreaLights, ASmallFarLightIsAPointAtItsCenter) {
  const SceneLight light = area_light(SceneLightType::Rect, {0.0, 4.0, 0.0}, {0.3, -1.0, 0.0}, {0, 0, 1}, 0.1, 0.05);
  const std::vector<test::AreaProbePoint> at = {{0, {1.0, 0.0, 0.5}, {0, 1, 0}, {0, 1, 0}},
                                                {0, {0.0, 5.0, 0.0}, {0, -1, 0}, {0, -1, 0}}};
  const std::vector<test::AreaProbeResult> got = probe(light, at);
  const glm::dvec3 d = light.position - at[0].p;
  const double len = glm::length(d), cos_light = -glm::dot(d / len, light.direction);
  EXPECT_NEAR(got[0].e, 0.1 * 0.05 * cos_light / (len * len), 1e-3 * got[0].e);
  EXPECT_GT(glm::dot(got[0].l, d / len), 0.99999);
  EXPECT_EQ(got[1].e, 0.0);
  EXPECT_EQ(got[1].cosine, 0.0);
}

// The rendered voxels of a rough metal quad facing the camera under a rect light (shadows off): the
// environment's term (the reference without lights) plus L times the integral of D Vis n.l over the
// light in double precision (ref::area_specular; F0 = F90 = 1). Over the voxels whose light term is at
// least 10% of the largest, the RMS relative error is within the LTC's (tests/test_area_ltc.cpp), and
// every voxel is within 30% of its term plus 1% of the largest.
TEST(AreaLights, ShadedVoxelsMatchTheIntegralOverTheLight) {
  Scene s = test::empty_scene(false);
  test::add_triangle(s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0});
  test::add_triangle(s, {-1, -1, 0}, {1, 1, 0}, {-1, 1, 0});
  s.materials[0].metallic = 1.0f, s.materials[0].roughness = 0.5f;
  const SceneLight light = area_light(SceneLightType::Rect, {0.3, 0.2, 1.2}, {-0.1, 0.0, -1.0}, {1, 0, 0}, 1.0, 0.6);
  SceneLight placed = light;
  placed.intensity = 2.0f;
  s.lights = {placed};
  const Rig rig = test::small_rig(5, 96, 64);
  PipelineConfig pc = test::pbr_config(Method::Pmr, TextureFilter::Bilinear, nullptr);
  const test::Rendered out = test::render_with(s, rig, pc);
  test::VoxelReference ambient(s, rig, out);
  ambient.lights.clear();
  ref::AreaLight shape;
  shape.center = light.position, shape.u = 0.5 * light.width * light.right, shape.v = 0.5 * light.height * light.up;
  if (glm::dot(glm::cross(shape.u, shape.v), light.direction) < 0.0) shape.v = -shape.v;  // emits toward u x v
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  std::vector<double> want, got;
  for (size_t v = 0; v < out.key.size(); v += 3) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const PmrMta* m = ambient.mta(v);
    ASSERT_NE(m, nullptr);
    const int view = int(v / (W * H));
    const glm::dvec3 b = ref::source_barycentrics(*m, int(v % W), int((v / W) % H), view);
    const ref::SurfacePoint q = test::surface_at(s, rig, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, view);
    const double term = 2.0 * ref::area_specular(shape, q.p, q.n, glm::normalize(q.eye - q.p), 0.5, 1e-4).x;
    want.push_back(term);
    half green;
    green.setBits(out.volume[4 * v + 1]);
    got.push_back(double(float(green)) - ambient.colour(v, *m).y);
  }
  ASSERT_GT(want.size(), 1000u);
  const double peak = *std::max_element(want.begin(), want.end());
  double sum2 = 0.0, n = 0.0;
  size_t bad = 0;
  for (size_t k = 0; k < want.size(); ++k) {
    if (want[k] >= 0.1 * peak) sum2 += std::pow((got[k] - want[k]) / want[k], 2.0), n += 1.0;
    if (std::abs(got[k] - want[k]) > 0.3 * want[k] + 0.01 * peak && ++bad <= 5)
      ADD_FAILURE() << "voxel " << k << ": " << got[k] << " for " << want[k] << " (peak " << peak << ")";
  }
  const double rms = std::sqrt(sum2 / n);
  EXPECT_EQ(bad, 0u);
  EXPECT_LE(rms, 0.08);
  EXPECT_GT(n, 500.0);
  std::printf("[ area     ] shaded: %zu voxels, RMS relative error %.4f over the %.0f of at least 10%% of the peak\n",
              want.size(), rms, n);
}

// EXT_lights_area as a file gives it: types, sizes by the node's largest scale, axes, luminance (pmr
// info, the sidecar), and one-line errors for bad values.
TEST(AreaLights, TheLoaderPlacesThemByTheirNodes) {
  using namespace test::gltf_builder_detail;
  const std::string dir = test::temp_dir("area_lights");
  std::filesystem::create_directories(dir);
  auto file = [&](const nlohmann::json& first, const std::string& name) {
    GltfFile g;
    const int p = g.data<float>({-1, -1, 0, 1, -1, 0, 0, 1, 0}, kFloat, "VEC3");
    g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", p}}}}}));
    std::vector<int> roots = {g.add("nodes", {{"mesh", 0}})};
    // turned -90 degrees about X (facing down), scaled 2 (the largest of 2, 1, 0.5)
    roots.push_back(g.add("nodes", {{"translation", {0, 3, 0}},
                                    {"rotation", {-0.7071067811865476, 0, 0, 0.7071067811865476}},
                                    {"scale", {2, 1, 0.5}},
                                    {"extensions", {{"EXT_lights_area", {{"light", 0}}}}}}));
    roots.push_back(
        g.add("nodes", {{"translation", {0, 0, 2}}, {"extensions", {{"EXT_lights_area", {{"light", 1}}}}}}));
    g.doc["extensionsUsed"] = {"EXT_lights_area"};
    g.doc["extensions"]["EXT_lights_area"]["lights"] = {first, {{"type", "disk"}, {"size", 2.0}}};
    g.scene(roots);
    return g.write(dir, name);
  };
  const nlohmann::json key = {{"type", "rect"}, {"intensity", 250.0}, {"size", 0.5}, {"rect", {{"aspect", 3.0}}}};
  const test::CliRun info = test::run("info " + file(key, "area"));
  EXPECT_NE(info.output.find("rect, node 1 (unnamed), color (1, 1, 1), intensity 250 nits"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("toward (0, -1, 0), 3 x 1 m"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("disk, node 2 (unnamed), color (1, 1, 1), intensity 1000 nits"), std::string::npos);
  EXPECT_NE(info.output.find("diameter 2 m"), std::string::npos) << info.output;
  const std::string out = dir + "/out";
  ASSERT_EQ(
      test::run("render " + file(key, "area") + " -q --views 2 --view-size 32x16 --display 64x36 --out " + out).status,
      0);
  const std::string sidecar = test::read_file(out + "/frame_0000.json");
  EXPECT_NE(sidecar.find("\"type\": \"rect\""), std::string::npos) << sidecar;
  EXPECT_NE(sidecar.find("\"width\": 3.0"), std::string::npos) << sidecar;
  const std::pair<nlohmann::json, const char*> bad[] = {
      {{{"type", "sphere"}}, "has unknown type 'sphere' (rect or disk expected)"},
      {{{"size", 1}}, "has no type"},
      {{{"type", "rect"}, {"size", 0}}, "size must be a number above 0"},
      {{{"type", "disk"}, {"intensity", -1}}, "intensity must be a finite number >= 0"},
      {{{"type", "rect"}, {"rect", {{"aspect", "wide"}}}}, "aspect must be a number above 0"}};
  for (const auto& [light, message] : bad)
    test::expect_one_error_line(test::run("info " + file(light, "bad")),
                                std::string("EXT_lights_area light 0 ") + message);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pmr
