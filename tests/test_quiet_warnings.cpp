// Warnings only when something is wrong (issue: an ordinary Blender scene warned on every still). The
// near plane, raised to keep the views' disparity in its fixed-point range, warns only when it cuts a
// triangle some view would show, and says what to do; otherwise --verbose notes it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "gltf_builder.h"
#include "test_util.h"

namespace pmr {
namespace {

using nlohmann::json;

// A 12 m ground plane, a 1 m upright square on it, and a camera 'cam' at `eye` looking down -Z after a
// pitch of `pitch` radians (negative: down), with a 0.6 rad vertical field of view. With `stake`, one
// thin triangle runs from 2 cm in front of the camera into the scene, in the middle of the picture.
std::string blender_like_scene(const std::string& dir, const glm::vec3& eye, float pitch, bool stake) {
  test::GltfFile g;
  std::vector<float> p = {-6,    0, -6, 6,    0, -6, 6,    0, 6, -6,    0, 6,   // ground
                          -0.5f, 0, 0,  0.5f, 0, 0,  0.5f, 1, 0, -0.5f, 1, 0};  // upright square
  std::vector<uint16_t> idx = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7};
  if (stake) {
    // along the view axis, 2 cm to 3 m in front of the camera
    const glm::vec3 fwd(0.0f, std::sin(pitch), -std::cos(pitch));
    const glm::vec3 a = eye + 0.02f * fwd, b = eye + 3.0f * fwd;
    p.insert(p.end(), {a.x - 0.01f, a.y - 0.002f, a.z, a.x + 0.01f, a.y - 0.002f, a.z, b.x, b.y - 0.2f, b.z});
    idx.insert(idx.end(), {8, 9, 10});
  }
  const int pos = g.data<float>(p, test::kFloat, "VEC3");
  const int ind = g.data<uint16_t>(idx, test::kUShort, "SCALAR");
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", ind}}}));
  g.add("nodes", {{"mesh", 0}});
  g.add("cameras", {{"name", "cam"}, {"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.05}}}});
  const float s = std::sin(pitch / 2), c = std::cos(pitch / 2);  // about +X
  g.add("nodes", {{"name", "cam"}, {"camera", 0}, {"translation", {eye.x, eye.y, eye.z}}, {"rotation", {s, 0, 0, c}}});
  g.scene({0, 1});
  return g.write(dir, stake ? "staked" : "plain");
}

const std::string kPortrait = " --preset lg-portrait --views 8 --view-size 96x128 --camera cam --shading lambert ";

TEST(QuietWarnings, AnOrdinaryBlenderSceneRendersWithoutAWarning) {
  const std::string dir = test::temp_dir("quiet_plain");
  std::filesystem::create_directories(dir);
  const std::string scene = blender_like_scene(dir, {0.0f, 3.0f, 7.0f}, -0.4f, false);
  const test::CliRun r = test::run("render '" + scene + "'" + kPortrait + "--verbose --out " + dir + "/out");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  // the raised near plane and the cameras' spacing are noted for whoever asks
  EXPECT_NE(r.output.find("note: near plane at"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("note: angular camera spacing within"), std::string::npos) << r.output;
  const test::CliRun quiet = test::run("render '" + scene + "'" + kPortrait + "--overwrite --out " + dir + "/out");
  EXPECT_EQ(quiet.output.find("note:"), std::string::npos) << quiet.output;
}

TEST(QuietWarnings, ANearPlaneThatCutsWhatAViewShowsWarnsOnceWithTheCount) {
  const std::string dir = test::temp_dir("quiet_staked");
  std::filesystem::create_directories(dir);
  const std::string scene = blender_like_scene(dir, {0.0f, 3.0f, 7.0f}, -0.4f, true);
  const test::CliRun r =
      test::run("render '" + scene + "'" + kPortrait + "--frames 0:1 --turntable 10:2 --out " + dir + "/out");
  ASSERT_EQ(r.status, 0) << r.output;
  const size_t at = r.output.find("warning: frame 0: the near plane");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cuts 1 triangle(s)", at), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--cone", at), std::string::npos) << "the warning says what to do: " << r.output;
  EXPECT_EQ(r.output.find("warning: frame 1", at), std::string::npos) << "once a run: " << r.output;
}

}  // namespace
}  // namespace pmr
