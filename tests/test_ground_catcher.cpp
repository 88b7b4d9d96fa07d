// --ground shadow (DESIGN section 4d; host/scene/ground_catcher.h): the shadow catcher under the scene
// shows the shadow cast on it as black of alpha 1 - V, casts none itself, and changes nothing else.
#include <gtest/gtest.h>

#include <cmath>

#include "pbr_support.h"
#include "reference/visibility_reference.h"
#include "scene/ground_catcher.h"
#include "shadow_support.h"
#include "test_util.h"

namespace pmr {
namespace {

// A box standing at y = -0.5, its framing box [lo, hi] the box itself.
Scene box_alone() {
  Scene s = test::empty_scene(false);
  test::add_box(s, {-0.3f, -0.5f, -0.3f}, {0.3f, 0.1f, 0.3f});
  s.lights = {test::make_light(SceneLightType::Directional, {0, 0, 0}, {0.6, -1.0, 0.8}, 3.0f)};
  return s;
}

// 3 views of 96 x 64 framing [-1, 1]^3 from 40 degrees above: the catcher fills the lower views.
Rig rig_from_above() {
  RigConfig rc;
  rc.views = 3, rc.view_w = 96, rc.view_h = 64;
  rc.orbit_el_deg = 40.0;
  return make_rig(rc, Display{}, glm::dvec3(-1.0), glm::dvec3(1.0));
}

test::Rendered render_with_catcher(const Scene& s, const Rig& rig, PipelineConfig pc, const Scene* catcher) {
  pc.debug_outputs = true;
  Pipeline p(test::runtime(), pc);
  p.set_scene(s, catcher);
  p.configure(rig, nullptr);
  test::Rendered r;
  r.times = p.render(rig);
  p.read_debug(r.key, r.depth, r.count);
  p.read_volume(r.volume);
  return r;
}

// Where view `view`'s ray through pixel (x, y) meets the plane y = h (false: it does not, ahead).
bool on_plane(const Rig& rig, int view, double x, double y, double h, glm::dvec3& p) {
  const glm::dmat4 inv = glm::inverse(rig.projection(view) * rig.view_matrix(view));
  const double nx = 2.0 * x / rig.view_w - 1.0, ny = 1.0 - 2.0 * y / rig.view_h;
  const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
  const glm::dvec3 o = glm::dvec3(a) / a.w, d = glm::dvec3(b) / b.w - o;
  if (std::abs(d.y) < 1e-12) return false;
  const double t = (h - o.y) / d.y;
  p = o + t * d;
  return t > 0.0;
}

// Under a sun alone (a black environment), where only the catcher covers a voxel it is black of alpha
// 1 - V, V the sun's visibility ray-cast at the catcher's point: mean |alpha - (1 - V)| at most 0.02,
// with both the shadow (alpha near 1) and open ground (alpha near 0) seen.
TEST(GroundCatcher, ItsAlphaIsTheShadowCastOnIt) {
  const Scene s = box_alone();
  const glm::dvec3 lo(-0.3, -0.5, -0.3), hi(0.3, 0.1, 0.3);
  const Rig rig = rig_from_above();
  const Scene catcher = make_ground_catcher(lo, hi, 10.0);
  PipelineConfig pc = test::pbr_config();
  pc.shadows = true, pc.environment_intensity = 0.0;
  const test::Rendered out = render_with_catcher(s, rig, pc, &catcher);
  const ref::PunctualLight sun = test::reference_light(s.lights[0]);
  const double h = ground_height(lo, hi);
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  double sum = 0.0;
  size_t compared = 0, shadowed = 0, open = 0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] != PMR_NO_KEY) continue;  // an opaque winner: the box
    const float alpha = test::half_value(out.volume[v * 4 + 3]);
    glm::dvec3 p;
    if (!on_plane(rig, int(v / (W * H)), double(v % W) + 0.5, double((v / W) % H) + 0.5, h, p)) continue;
    if (std::abs(p.x) > 3.0 || std::abs(p.z) > 3.0) continue;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(out.volume[v * 4 + size_t(c)], 0u) << "the catcher is black";
    const double expected = 1.0 - ref::ray_visibility(s, p, sun);
    sum += std::abs(alpha - expected), ++compared;
    shadowed += alpha > 0.9f, open += alpha < 0.1f;
  }
  const double mean = sum / double(compared);
  std::printf("[ ground   ] %zu catcher voxels: %zu shadowed, %zu open, mean |alpha - (1 - V)| %.4f\n", compared,
              shadowed, open, mean);
  EXPECT_LE(mean, 0.02);
  EXPECT_GT(shadowed, 200u);
  EXPECT_GT(open, 3000u);
}

// The catcher casts no shadow (on the box, from a sun below its top) and changes no voxel the box
// wins: the box's colours are those rendered without it, bit for bit (the shadow maps and the
// environment's occlusion leave the catcher out), under the uniform environment.
TEST(GroundCatcher, ChangesNothingElse) {
  const Scene s = box_alone();
  const Rig rig = rig_from_above();
  const Scene catcher = make_ground_catcher({-0.3, -0.5, -0.3}, {0.3, 0.1, 0.3}, 10.0);
  PipelineConfig pc = test::pbr_config();
  pc.shadows = true;
  const test::Rendered with = render_with_catcher(s, rig, pc, &catcher), without = test::render_with(s, rig, pc);
  size_t box = 0, differ = 0;
  for (size_t v = 0; v < with.key.size(); ++v) {
    if (without.key[v] == PMR_NO_KEY) continue;
    ++box;
    EXPECT_EQ(with.key[v], without.key[v]);
    for (int c = 0; c < 4; ++c) differ += with.volume[v * 4 + size_t(c)] != without.volume[v * 4 + size_t(c)];
  }
  EXPECT_GT(box, 500u);
  EXPECT_EQ(differ, 0u);
}

// The command line: --ground shadow needs pbr with shadows, records the catcher's height in the
// sidecar, and --resume tells a folder rendered without it apart.
TEST(GroundCatcher, CommandLine) {
  const std::string out = test::temp_dir("ground");
  const std::string small = " --views 4 --view-size 48x24 --display 160x90 --environment uniform --out " + out;
  test::expect_usage_error(test::run("render --ground shadow --shading lambert" + small), "--ground shadow");
  test::expect_usage_error(test::run("render --ground shadow --shadows off" + small), "--ground shadow");
  test::expect_usage_error(test::run("render --ground grass" + small), "--ground");
  ASSERT_EQ(test::run("render --ground shadow" + small).status, 0);
  const std::string sidecar = test::read_file(out + "/frame_0000.json");
  EXPECT_NE(sidecar.find("\"ground\""), std::string::npos) << sidecar;
  EXPECT_NE(sidecar.find("\"kind\": \"shadow\""), std::string::npos);
  EXPECT_EQ(test::run("render --ground shadow --resume" + small).status, 0);
  test::expect_one_error_line(test::run("render --resume" + small), "shading differs");
}

}  // namespace
}  // namespace pmr
