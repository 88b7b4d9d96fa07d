// Choosing the center camera (DESIGN section 2): --camera by index or by name (the node's name first,
// as Blender names camera objects, then the camera's own; several matches are an error), and --orbit
// AZ,EL, which moves the framing camera around the scene's bounding sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include "gltf_builder.h"
#include "pmr/error.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

using nlohmann::json;
using test::CliRun;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::run;
using test::temp_dir;

// A quad at the origin and five cameras, each on its own node:
//   camera 0 'cam'   on node 'Front' at (0, 0, 5);
//   camera 1 'Front' on node 'Side'  at (5, 0, 0), turned to look at the origin;
//   cameras 2 '1' and 3 'b' on two nodes both named 'Twin';
//   camera 4 'Solo'  on an unnamed node at (0, 0, 3);
//   camera 0 again on node 'Second' at (0, 0, 7): scene camera 5, its own pose (Blender exports camera
//   objects that share their data so).
std::string cameras_file(const std::string& dir) {
  test::GltfFile g;
  const int p = g.data<float>({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, test::kFloat, "VEC3");
  const int i = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, test::kUShort, "SCALAR");
  g.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"indices", i}}}));
  g.add("nodes", {{"mesh", 0}});
  for (const char* name : {"cam", "Front", "1", "b", "Solo"})
    g.add("cameras", {{"name", name}, {"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.05}}}});
  const float s = std::sqrt(0.5f);  // yaw +90 degrees: -Z turns to -X
  g.add("nodes", {{"name", "Front"}, {"camera", 0}, {"translation", {0, 0, 5}}});
  g.add("nodes", {{"name", "Side"}, {"camera", 1}, {"translation", {5, 0, 0}}, {"rotation", {0, s, 0, s}}});
  g.add("nodes", {{"name", "Twin"}, {"camera", 2}, {"translation", {0, 1, 5}}});
  g.add("nodes", {{"name", "Twin"}, {"camera", 3}, {"translation", {0, -1, 5}}});
  g.add("nodes", {{"camera", 4}, {"translation", {0, 0, 3}}});
  g.add("nodes", {{"name", "Second"}, {"camera", 0}, {"translation", {0, 0, 7}}});
  g.scene({0, 1, 2, 3, 4, 5, 6});
  return g.write(dir, "cameras");
}

// A camera whose frame is wider than the display's views (glTF aspectRatio: Blender writes its render
// size's) keeps its whole frame: the vertical field of view widens until the frame's width fits, with
// one warning that says what to do. A camera of the display's aspect, or narrower, keeps its yfov.
TEST(CameraChoice, AWiderCameraFrameWidensTheFieldOfView) {
  Display portrait;
  portrait.size_w_cm = 30.0, portrait.size_h_cm = 40.0;
  const double a = portrait.aspect(), yfov = 0.5;
  const glm::dmat4 pose = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, 10.0));
  RigConfig rc;
  rc.views = 4, rc.view_w = 60, rc.view_h = 80;
  std::vector<std::string> warnings;
  const Rig wide = make_rig(rc, portrait, glm::dvec3(-1.0), glm::dvec3(1.0), &pose, yfov, &warnings, 16.0 / 9.0);
  EXPECT_NEAR(a * std::tan(wide.yfov / 2.0), 16.0 / 9.0 * std::tan(yfov / 2.0), 1e-12) << "the frame's width fits";
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("render size"), std::string::npos) << warnings[0];
  for (double aspect : {0.0, a, 0.5}) {
    warnings.clear();
    const Rig same = make_rig(rc, portrait, glm::dvec3(-1.0), glm::dvec3(1.0), &pose, yfov, &warnings, aspect);
    EXPECT_EQ(same.yfov, yfov) << aspect;
    EXPECT_TRUE(warnings.empty()) << aspect;
  }
}

TEST(CameraChoice, ByIndexNodeNameOrCameraName) {
  const std::string dir = temp_dir("camera_choice");
  std::filesystem::create_directories(dir);
  const Scene scene = load_scene(cameras_file(dir));
  ASSERT_EQ(scene.cameras.size(), 6u) << "five cameras, and camera 0 placed a second time";
  EXPECT_EQ(scene.cameras[5].shared_with, 0);
  EXPECT_EQ(scene.cameras[5].world_from_camera[3], glm::dvec4(0, 0, 7, 1));
  EXPECT_EQ(scene.cameras[0].world_from_camera[3], glm::dvec4(0, 0, 5, 1));
  EXPECT_EQ(find_camera(scene, "Second"), 5);
  EXPECT_EQ(find_camera(scene, "#0"), 0);
  EXPECT_EQ(find_camera(scene, "#4"), 4);
  EXPECT_EQ(find_camera(scene, "Side"), 1);
  EXPECT_EQ(find_camera(scene, "Front"), 0) << "a node's name comes before a camera's";
  EXPECT_EQ(find_camera(scene, "cam"), 0);
  EXPECT_EQ(find_camera(scene, "Solo"), 4);
  EXPECT_EQ(find_camera(scene, "b"), 3);
  EXPECT_EQ(find_camera(scene, "1"), 2) << "a camera named 1 is chosen by its name, not taken for index 1";
  auto message = [&](const std::string& name) {
    try {
      find_camera(scene, name);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(message("Twin").find("ambiguous"), std::string::npos) << message("Twin");
  EXPECT_EQ(find_camera(scene, "cam"), 0) << "a camera's own name is the file's camera, not a further node's";
  EXPECT_NE(message("#6").find("the scene has 6 camera(s)"), std::string::npos) << message("#6");
  EXPECT_NE(message("#99999999999999999999").find("is not a number"), std::string::npos);
  EXPECT_NE(message("#x").find("is not a number"), std::string::npos);
  // a bare number is a name: none has it here, and the message shows how to write the index
  EXPECT_NE(message("4").find("no camera node or camera of the scene has that name (an index is written #4"),
            std::string::npos)
      << message("4");
  EXPECT_NE(message("side").find("no camera node or camera"), std::string::npos) << "names are case-sensitive";
  EXPECT_NE(message("\x1b[2J").find("\\x1b"), std::string::npos) << "the name is made printable";
}

// From the command line: the named camera's pose is the center view (its matrices in the sidecar), its
// index and node name are recorded; a bad name is one error line and writes nothing.
TEST(CameraChoice, NamedCameraFromTheCommandLine) {
  const std::string dir = temp_dir("camera_choice_cli");
  std::filesystem::create_directories(dir);
  const std::string file = cameras_file(dir);
  const std::string small = " --views 4 --view-size 32x16 --display 96x54 --shading lambert ";
  const CliRun r = run("render " + file + small + "--camera Side --out " + dir + "/side");
  ASSERT_EQ(r.status, 0) << r.output;
  const json s = json::parse(test::read_file(dir + "/side/frame_0000.json"));
  EXPECT_EQ(s["camera"], 1);
  EXPECT_EQ(s["camera_name"], "Side");
  // the center view of 4 views lies between views 1 and 2: their mean is the inverse of the node's pose
  const glm::dmat4 pose = glm::translate(glm::dmat4(1.0), glm::dvec3(5, 0, 0)) *
                          glm::rotate(glm::dmat4(1.0), glm::radians(90.0), glm::dvec3(0, 1, 0));
  const glm::dmat4 want = glm::inverse(pose);
  const json& v1 = s["views"][1]["view"];
  const json& v2 = s["views"][2]["view"];
  ASSERT_EQ(v1.size(), 16u);
  for (int c = 0; c < 4; ++c)  // column-major, as glm
    for (int row = 0; row < 4; ++row) {
      const double got = 0.5 * (v1[4 * c + row].get<double>() + v2[4 * c + row].get<double>());
      EXPECT_NEAR(got, want[c][row], 1e-9) << "row " << row << " column " << c;
    }
  expect_one_error_line(run("render " + file + small + "--camera Twin --out " + dir + "/twin"), "ambiguous");
  expect_one_error_line(run("render " + file + small + "--camera Nobody --out " + dir + "/nobody"),
                        "--camera 'Nobody': no camera node");
  EXPECT_FALSE(test::exists(dir + "/twin"));
  EXPECT_FALSE(test::exists(dir + "/nobody"));
  const std::string info = run("info " + file).output;
  EXPECT_NE(info.find("placed by node 'Side' (--camera '#1')"), std::string::npos) << info;
  EXPECT_NE(info.find("placed by node 'Second', a further node of camera 0 (--camera '#5')"), std::string::npos)
      << info;
  // the further node drives the rig from its own pose
  ASSERT_EQ(run("render " + file + small + "--camera Second --out " + dir + "/second").status, 0);
  const json second = json::parse(test::read_file(dir + "/second/frame_0000.json"));
  EXPECT_EQ(second["camera"], 5);
  EXPECT_EQ(second["camera_name"], "Second");
  EXPECT_NEAR(second["rig"]["focal_distance"].get<double>(), 7.0, 1e-9);
}

// A box whose sphere has center (1, 0, -1) and radius 2 sqrt(3), seen by the center camera alone.
const glm::dvec3 kLo(-1.0, -2.0, -3.0), kHi(3.0, 2.0, 1.0);

Rig orbited(double az, double el) {
  RigConfig rc;
  rc.views = 1, rc.view_w = 64, rc.view_h = 64;
  rc.orbit_az_deg = az, rc.orbit_el_deg = el;
  return make_rig(rc, Display{}, kLo, kHi);
}

// DESIGN section 2: the camera at c + D (sin az cos el, sin el, cos az cos el) looking at c with +Y up,
// as glm::lookAt builds it; the framing (D, near, far) is the unorbited one.
TEST(Orbit, TheCameraCirclesTheSphereCenterLevel) {
  const Rig straight = orbited(0.0, 0.0);
  const glm::dvec3 c = 0.5 * (kLo + kHi);
  EXPECT_TRUE(straight.center_view == glm::translate(glm::dmat4(1.0), -(c + glm::dvec3(0.0, 0.0, straight.focal))))
      << "no orbit: exactly the translation of the default framing";
  for (const auto& [az, el] : std::vector<std::pair<double, double>>{{30, 20}, {-75, -40}, {180, 0}, {90, 89}}) {
    SCOPED_TRACE("orbit " + std::to_string(az) + "," + std::to_string(el));
    const Rig rig = orbited(az, el);
    EXPECT_EQ(rig.focal, straight.focal);
    EXPECT_EQ(rig.near, straight.near);
    EXPECT_EQ(rig.far, straight.far);
    const double a = glm::radians(az), e = glm::radians(el);
    const glm::dvec3 eye =
        c + rig.focal * glm::dvec3(std::sin(a) * std::cos(e), std::sin(e), std::cos(a) * std::cos(e));
    const glm::dmat4 want = glm::lookAt(eye, c, glm::dvec3(0.0, 1.0, 0.0));
    for (int col = 0; col < 4; ++col)
      for (int row = 0; row < 4; ++row) EXPECT_NEAR(rig.center_view[col][row], want[col][row], 1e-12);
    EXPECT_EQ(rig.center_view[1][0], 0.0) << "the camera's +X stays horizontal";
    // every view's camera stays on the horizontal line through the center camera
    EXPECT_EQ(rig.view_matrix(0)[1][0], 0.0);
  }
  // positive elevation looks down: the camera above c; positive azimuth turns it toward +X
  EXPECT_GT(glm::inverse(orbited(0.0, 30.0).center_view)[3].y, c.y);
  EXPECT_GT(glm::inverse(orbited(30.0, 0.0).center_view)[3].x, c.x);
  for (const auto& [az, el] : std::vector<std::pair<double, double>>{{0, 90}, {0, -90}, {361, 0}, {0, NAN}})
    EXPECT_THROW(orbited(az, el), Error) << az << "," << el;
  RigConfig rc;
  rc.orbit_el_deg = 10.0;
  const glm::dmat4 pose(1.0);
  EXPECT_THROW(make_rig(rc, Display{}, kLo, kHi, &pose, 0.5), Error) << "not with a glTF camera";
}

// From the command line: recorded in the sidecar, compared by --resume, accepted by pmr bench, refused
// with --camera and out of range.
TEST(Orbit, FromTheCommandLine) {
  const std::string small = " --views 4 --view-size 64x32 --display 240x135 --shading lambert ";
  const std::string a = temp_dir("orbit_a");
  CliRun r = run("render --orbit 30,20" + small + "--out " + a);
  ASSERT_EQ(r.status, 0) << r.output;
  const json s = json::parse(test::read_file(a + "/frame_0000.json"));
  EXPECT_EQ(s["rig"]["orbit_deg"], json({30.0, 20.0}));
  expect_one_error_line(run("render --orbit 30,25 --resume" + small + "--out " + a),
                        "different configuration (rig.orbit_deg");
  r = run("render --orbit 30,20 --resume" + small + "--out " + a);
  EXPECT_EQ(r.status, 0) << r.output;
  const std::string c = temp_dir("orbit_refused");
  expect_usage_error(run("render --orbit 10,10 --camera 0" + small + "--out " + c), "--camera");
  for (const char* bad : {"10", "10,90", "x,1", "10,-95", "400,0", "10,"})
    expect_usage_error(run("render --orbit " + std::string(bad) + small + "--out " + c), "--orbit");
  EXPECT_FALSE(test::exists(c));
  EXPECT_NE(run("render --help").output.find("--orbit AZ,EL"), std::string::npos);
  r = run("bench --views 4 --view-size 64x32 --display 240x135 --frames 1 --method pmr --orbit 45,30");
  EXPECT_EQ(r.status, 0) << r.output;
  expect_usage_error(run("bench --views 4 --frames 1 --method pmr --orbit 0,95"), "--orbit");
}

}  // namespace
}  // namespace pmr
