// The default framing (DESIGN section 2): the scene's bounding sphere fits the focal-plane window in
// both directions, on wide and portrait displays alike; --zoom F shows it F times larger (D / F, the
// focal plane still through the center), is recorded in the sidecar, compared by --resume and
// refused with --camera. Checked on the rig's own matrices, not on images.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "pmr/error.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::CliRun;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::run;
using test::temp_dir;

// A box whose sphere has center c = (1, 0, -1) and radius R = 0.5 |(4, 4, 4)| = 2 sqrt(3).
const glm::dvec3 kLo(-1.0, -2.0, -3.0), kHi(3.0, 2.0, 1.0);
const glm::dvec3 kCenter = 0.5 * (kLo + kHi);
const double kRadius = 0.5 * glm::length(kHi - kLo);

Display display_of_aspect(double w_cm, double h_cm) {
  Display d;
  d.size_w_cm = w_cm, d.size_h_cm = h_cm, d.viewing_distance_cm = 2.0 * h_cm;
  return d;
}

Rig framed(const Display& d, double zoom = 1.0) {
  RigConfig rc;
  rc.views = 1;  // the center camera alone: s_0 = 0
  rc.view_w = 64, rc.view_h = 64;
  rc.zoom = zoom;
  rc.framing = Framing::Sphere;
  return make_rig(rc, d, kLo, kHi);
}

// How far the box's corners reach across views 0 .. N-1 (max |NDC| in x and y), and in front of the
// cameras (min w).
struct BoxReach {
  double x = 0.0, y = 0.0, w = INFINITY;
};
BoxReach box_reach(const Rig& rig, const glm::dvec3& lo, const glm::dvec3& hi, int view) {
  BoxReach r;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 p((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec4 clip = rig.projection(view) * rig.view_matrix(view) * glm::dvec4(p, 1.0);
    r.x = std::max(r.x, std::abs(clip.x / clip.w)), r.y = std::max(r.y, std::abs(clip.y / clip.w));
    r.w = std::min(r.w, clip.w);
  }
  return r;
}

// NDC of a world point seen by the rig's center camera.
glm::dvec3 ndc(const Rig& rig, const glm::dvec3& p) {
  const glm::dvec4 clip = rig.projection(0) * rig.view_matrix(0) * glm::dvec4(p, 1.0);
  return glm::dvec3(clip) / clip.w;
}

// How far the sphere's cross-section through c (in the focal plane) reaches across the window:
// x and y in NDC units of its rightmost and topmost points.
glm::dvec2 sphere_reach(const Rig& rig) {
  // the camera's right and up in world space (the rows of the view rotation)
  const glm::dvec3 right(rig.center_view[0][0], rig.center_view[1][0], rig.center_view[2][0]);
  const glm::dvec3 up(rig.center_view[0][1], rig.center_view[1][1], rig.center_view[2][1]);
  return {ndc(rig, kCenter + kRadius * right).x, ndc(rig, kCenter + kRadius * up).y};
}

nlohmann::json sidecar(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

}  // namespace

// The default, --framing box: every corner of the box inside every view, one pixel from the edges
// (1 - 2 / W in NDC), and some corner in view 0 or N-1 on that bound: no smaller distance keeps them
// all in. Wide, square and portrait displays, linear and angular spacing, orbits, a flat box.
TEST(Framing, TheBoxFillsTheFirstAndLastViews) {
  const std::pair<glm::dvec3, glm::dvec3> boxes[] = {{kLo, kHi}, {{-2.0, 0.0, -0.1}, {2.0, 3.0, 0.1}}};
  for (const auto& [w, h] : {std::pair{200.0, 100.0}, std::pair{50.0, 50.0}, std::pair{30.0, 40.0}})
    for (bool angular : {false, true})
      for (const auto& [az, el] : {std::pair{0.0, 0.0}, std::pair{35.0, 20.0}})
        for (const auto& [lo, hi] : boxes) {
          RigConfig rc;
          rc.views = 12, rc.view_w = 80, rc.view_h = 60, rc.cone_deg = 40.0;
          rc.angular_spacing = angular, rc.orbit_az_deg = az, rc.orbit_el_deg = el;
          rc.framing = Framing::Box;
          const Rig rig = make_rig(rc, display_of_aspect(w, h), lo, hi);
          SCOPED_TRACE("display " + std::to_string(w) + " x " + std::to_string(h) + (angular ? " angular" : "") +
                       " orbit " + std::to_string(az) + "," + std::to_string(el));
          EXPECT_EQ(rig.framing, Framing::Box);
          const double bx = 1.0 - 2.0 / rc.view_w, by = 1.0 - 2.0 / rc.view_h;
          double tight = INFINITY;
          for (int v = 0; v < rc.views; ++v) {
            const BoxReach r = box_reach(rig, lo, hi, v);
            // the angular cameras sit on fixed-point view coordinates, within 0.01 view pixel
            const double slack = angular ? 0.02 / rc.view_w : 1e-9;
            EXPECT_LE(r.x, bx + slack) << "view " << v;
            EXPECT_LE(r.y, by + 1e-9) << "view " << v;
            EXPECT_GT(r.w, rig.near_eff) << "view " << v;
            if (v == 0 || v == rc.views - 1) tight = std::min(tight, std::min(bx - r.x, by - r.y));
          }
          EXPECT_NEAR(tight, 0.0, angular ? 0.02 / rc.view_w : 1e-9) << "a corner touches the bound";
          EXPECT_NEAR(-(rig.center_view * glm::dvec4(0.5 * (lo + hi), 1.0)).z, rig.focal, 1e-9)
              << "the focal plane through the box's center";
        }
}

// The box fills more of the picture than the sphere, and a turntable keeps the sphere unless asked.
TEST(Framing, TheBoxIsCloserThanTheSphereAndTurntablesKeepTheSphere) {
  RigConfig rc;
  rc.views = 48, rc.view_w = 84, rc.view_h = 112, rc.cone_deg = 40.0;
  rc.framing = Framing::Box;
  const Display portrait = display_of_aspect(30, 40);
  const Rig box = make_rig(rc, portrait, kLo, kHi);
  rc.framing = Framing::Sphere;
  const Rig sphere = make_rig(rc, portrait, kLo, kHi);
  EXPECT_LT(box.focal, sphere.focal);
  const std::string dir = temp_dir("framing_turntable");
  const std::string small = " --views 4 --view-size 32x32 --display 120x68 -q --out " + dir;
  ASSERT_EQ(run("render --turntable 360:4 --frames 0" + small).status, 0);
  EXPECT_EQ(sidecar(dir + "/frame_0000.json")["rig"]["framing"], "sphere");
  ASSERT_EQ(run("render --overwrite --frames 0" + small).status, 0);
  EXPECT_EQ(sidecar(dir + "/frame_0000.json")["rig"]["framing"], "box");
  ASSERT_EQ(run("render --overwrite --turntable 360:4 --framing box --frames 0" + small).status, 0);
  EXPECT_EQ(sidecar(dir + "/frame_0000.json")["rig"]["framing"], "box");
  expect_usage_error(run("render --framing cube" + small), "--framing");
  expect_usage_error(run("render --framing box --camera 0" + small), "--framing");
}

// --framing sphere: wide (2:1), square and portrait (3:4) displays: the sphere fits in both directions and touches the
// window's edge in the tighter one.
TEST(Framing, TheBoundingSphereFitsBothDirections) {
  for (const auto& [w, h] : {std::pair{200.0, 100.0}, std::pair{50.0, 50.0}, std::pair{30.0, 40.0}}) {
    const Rig rig = framed(display_of_aspect(w, h));
    const glm::dvec2 reach = sphere_reach(rig);
    SCOPED_TRACE("display " + std::to_string(w) + " x " + std::to_string(h));
    EXPECT_LE(reach.x, 1.0 + 1e-12);
    EXPECT_LE(reach.y, 1.0 + 1e-12);
    EXPECT_NEAR(std::max(reach.x, reach.y), 1.0, 1e-12) << "the tighter direction touches the edge";
    // the center is straight ahead on the focal plane: zero parallax there
    EXPECT_NEAR(ndc(rig, kCenter).x, 0.0, 1e-12);
    EXPECT_NEAR(ndc(rig, kCenter).y, 0.0, 1e-12);
    const glm::dvec4 c_view = rig.center_view * glm::dvec4(kCenter, 1.0);
    EXPECT_NEAR(-c_view.z, rig.focal, 1e-12);
    // the portrait display frames by its width, the wide one by its height
    if (w < h) {
      EXPECT_NEAR(reach.x, 1.0, 1e-12);
    }
    if (w > h) {
      EXPECT_NEAR(reach.y, 1.0, 1e-12);
    }
    // near and far enclose the sphere
    EXPECT_GT(rig.near, 0.0);
    EXPECT_LE(rig.near, rig.focal - kRadius);
    EXPECT_GE(rig.far, rig.focal + kRadius);
  }
}

// --zoom F: D / F, the focal plane through c, the sphere F times larger on it; near stays positive
// when the camera comes inside the sphere.
TEST(Framing, ZoomScalesTheDistance) {
  for (const Display& d : {display_of_aspect(166, 93), display_of_aspect(30, 40)}) {
    const Rig one = framed(d), two = framed(d, 2.0), half = framed(d, 0.5), close = framed(d, 20.0);
    EXPECT_NEAR(two.focal, one.focal / 2.0, 1e-12 * one.focal);
    EXPECT_NEAR(half.focal, one.focal * 2.0, 1e-12 * one.focal);
    EXPECT_EQ(two.zoom, 2.0);
    EXPECT_EQ(one.zoom, 1.0);
    const glm::dvec2 r1 = sphere_reach(one), r2 = sphere_reach(two);
    EXPECT_NEAR(r2.x, 2.0 * r1.x, 1e-12);
    EXPECT_NEAR(r2.y, 2.0 * r1.y, 1e-12);
    EXPECT_NEAR(-(two.center_view * glm::dvec4(kCenter, 1.0)).z, two.focal, 1e-12);
    EXPECT_NEAR(ndc(two, kCenter).x, 0.0, 1e-12);
    EXPECT_LT(close.focal, kRadius) << "the camera is inside the sphere";
    EXPECT_GT(close.near, 0.0);
    EXPECT_LT(close.near_eff, close.far);
  }
  RigConfig rc;
  rc.zoom = 0.0;
  EXPECT_THROW(make_rig(rc, Display{}, kLo, kHi), Error);
  rc.zoom = 2.0;  // a glTF camera sets its own distance
  const glm::dmat4 pose = glm::translate(glm::dmat4(1.0), glm::dvec3(1.0, 0.0, 10.0));
  EXPECT_THROW(make_rig(rc, Display{}, kLo, kHi, &pose, 0.5), Error);
}

// Sidecars written before --zoom existed framed at 1; the default framing's distance is compared.
TEST(Framing, SidecarsCompareTheZoom) {
  SidecarInfo info;
  info.has_bounds = true, info.bounds_lo = kLo, info.bounds_hi = kHi;
  const std::string one = sidecar_json(framed(Display{}), Display{}, info);
  nlohmann::json old = nlohmann::json::parse(one);
  ASSERT_EQ(old["rig"]["zoom"], 1.0);
  old["rig"].erase("zoom");
  EXPECT_EQ(sidecar_config_difference(old.dump(), one), "");
  const std::string two = sidecar_json(framed(Display{}, 2.0), Display{}, info);
  EXPECT_EQ(sidecar_config_difference(old.dump(), two), "rig.zoom");
  EXPECT_EQ(sidecar_config_difference(one, two), "rig.zoom");
  // a portrait display framed by its height (before the sphere fit both directions): another framing
  const Display portrait = display_of_aspect(30, 40);
  const Rig now = framed(portrait);
  nlohmann::json before = nlohmann::json::parse(sidecar_json(now, portrait, info));
  before["rig"]["focal_distance"] = kRadius / std::tan(now.yfov / 2.0);
  ASSERT_NE(before["rig"]["focal_distance"].get<double>(), now.focal);
  EXPECT_EQ(sidecar_config_difference(before.dump(), sidecar_json(now, portrait, info)), "rig.focal_distance");
  // with a glTF camera the distance is not compared: an animated camera moves it from frame to frame
  info.rig_config.camera = 0;
  before = nlohmann::json::parse(sidecar_json(now, portrait, info));
  before["rig"]["focal_distance"] = 2.0 * now.focal;
  EXPECT_EQ(sidecar_config_difference(before.dump(), sidecar_json(now, portrait, info)), "");
}

// From the command line: recorded, compared by --resume, refused with --camera and out of range.
TEST(Framing, ZoomFromTheCommandLine) {
  const std::string small = " --views 4 --view-size 64x32 --display 240x135 ";
  const std::string a = temp_dir("zoom_one"), b = temp_dir("zoom_two");
  ASSERT_EQ(run("render" + small + "--out " + a).status, 0);
  CliRun r = run("render --zoom 2" + small + "--out " + b);
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json one = sidecar(a + "/frame_0000.json"), two = sidecar(b + "/frame_0000.json");
  EXPECT_EQ(two["rig"]["zoom"], 2.0);
  EXPECT_NEAR(two["rig"]["focal_distance"].get<double>(), one["rig"]["focal_distance"].get<double>() / 2.0, 1e-9);
  expect_one_error_line(run("render --zoom 3 --resume" + small + "--out " + b), "different configuration (rig.zoom");
  const std::string c = temp_dir("zoom_refused");
  expect_usage_error(run("render --zoom 2 --camera 0" + small + "--out " + c), "--camera");
  expect_usage_error(run("render --zoom 0" + small + "--out " + c), "--zoom");
  expect_usage_error(run("render --zoom x" + small + "--out " + c), "--zoom");
  EXPECT_FALSE(test::exists(c));
  EXPECT_NE(run("render --help").output.find("--zoom F"), std::string::npos);
}

}  // namespace pmr
