// --background environment (host/output/backdrop.h, docs/OUTPUTS.md "Backgrounds"): the environment on
// a plane at --background-depth behind every product. Expected values come from the map's own function
// along directions computed here from the sidecar's rig (DESIGN section 2's window), and from the same
// frame rendered over a transparent background, not from pmr's backdrop code.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "environment_maps.h"
#include "pmr/output.h"
#include "test_util.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;
const int kViews = 8, kW = 64, kH = 32, kDisplayW = 240, kDisplayH = 135;

// A smooth map with a strong horizontal gradient: green is a sine of the longitude (8 periods around).
glm::dvec3 stripes(glm::dvec3 d) {
  const double lon = std::atan2(d.x, -d.z);
  return {0.3, 0.5 + 0.4 * std::sin(8.0 * lon), 0.4 + 0.3 * d.y};
}

struct Render {
  nlohmann::json sidecar;
  std::vector<std::vector<uint16_t>> views;  // half RGBA per view
  std::vector<uint16_t> display;             // half RGBA
};

// The default scene, small, lit and backed by the stripes map, with `options`.
Render render(const std::string& name, const std::string& options) {
  const std::string dir = test::temp_dir("backdrop_" + name);
  std::system(("mkdir -p '" + dir + "'").c_str());
  test::write_exr(dir + "/stripes.exr", test::make_map(512, 256, stripes));
  const test::CliRun r = test::run(
      "render --views 8 --view-size 64x32 --display 240x135 --write views,encoded -q "
      "--environment " +
      dir + "/stripes.exr " + options + " --out " + dir + "/out");
  EXPECT_EQ(r.status, 0) << r.output;
  Render out;
  if (r.status != 0) return out;
  std::ifstream in(dir + "/out/frame_0000.json");
  out.sidecar = nlohmann::json::parse(in);
  for (int v = 0; v < kViews; ++v) {
    int w = 0, h = 0;
    out.views.emplace_back();
    read_views_exr_part(dir + "/out/frame_0000.views.exr", v, w, h, out.views.back());
    EXPECT_EQ(w, kW);
    EXPECT_EQ(h, kH);
  }
  int w = 0, h = 0;
  read_rgba_exr(dir + "/out/frame_0000.exr", w, h, out.display);
  EXPECT_EQ(w, kDisplayW);
  return out;
}

float at(const std::vector<uint16_t>& image, size_t pixel, int channel) {
  return test::half_value(image[pixel * 4 + size_t(channel)]);
}

// What the center camera sees along pixel (x + 1/2, y + 1/2) shifted by `shift_px` in x: the map's own
// function along the direction through the sidecar's focal-plane window.
glm::dvec3 expected_backdrop(const nlohmann::json& j, double x, int y) {
  const nlohmann::json& rig = j["rig"];
  const double t = std::tan(rig["yfov_rad"].get<double>() / 2.0), aspect = rig["aspect"].get<double>();
  glm::dmat4 view;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) view[c][r] = j["center_view"][size_t(c * 4 + r)].get<double>();
  const glm::dvec3 d((2.0 * (x + 0.5) / kW - 1.0) * aspect * t, (1.0 - 2.0 * (y + 0.5) / kH) * t, -1.0);
  return stripes(glm::normalize(glm::inverse(glm::dmat3(view)) * d));
}

// At the default depth every view shows the same backdrop, the map seen by the center camera (within
// the 512x256 map's bilinear error and half precision), alpha 1; objects cover it with their coverage:
// C = C_transparent + (1 - a) B.
TEST(Backdrop, AtTheFocalPlaneEveryViewShowsTheSameBackdropUnderTheObjects) {
  const Render bare = render("focal_bare", "");
  const Render backed = render("focal", "--background environment");
  ASSERT_EQ(backed.views.size(), size_t(kViews));
  ASSERT_EQ(bare.views.size(), size_t(kViews));
  EXPECT_EQ(backed.sidecar["background"]["kind"], "environment");
  EXPECT_EQ(backed.sidecar["background"]["depth"], "focal");
  EXPECT_EQ(backed.sidecar["background"]["parallax"], 0.0);
  size_t empty = 0, edges = 0;
  double worst_map = 0.0, worst_edge = 0.0;
  for (int v = 0; v < kViews; ++v)
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const size_t p = size_t(y) * kW + size_t(x);
        const float a = at(bare.views[size_t(v)], p, 3);
        EXPECT_EQ(at(backed.views[size_t(v)], p, 3), 1.0f);
        const glm::dvec3 want = expected_backdrop(backed.sidecar, x, y);
        for (int c = 0; c < 3; ++c) {
          const double got = at(backed.views[size_t(v)], p, c);
          if (a == 0.0f) {
            if (at(bare.views[0], p, 3) == 0.0f) {  // view 0 sees the backdrop there too
              EXPECT_EQ(backed.views[size_t(v)][p * 4 + size_t(c)], backed.views[0][p * 4 + size_t(c)]) << v;
            }
            worst_map = std::max(worst_map, std::abs(got - want[c]));
          } else if (a < 1.0f) {
            // the backdrop under an edge: the same pixel's backdrop, by the map's function
            const double over = at(bare.views[size_t(v)], p, c) + (1.0 - a) * want[c];
            worst_edge = std::max(worst_edge, std::abs(got - over));
          }
        }
        empty += a == 0.0f, edges += a > 0.0f && a < 1.0f;
      }
  EXPECT_GT(empty, size_t(kViews * kW * kH / 4));
  EXPECT_GT(edges, size_t(kViews * 20));
  EXPECT_LE(worst_map, 0.004);
  EXPECT_LE(worst_edge, 0.006);
}

// With --background-depth Z the backdrop shifts from view 0 to view N-1 by Delta(Z) = k (1 - D / Z) view
// pixels (DESIGN section 2, k = the sidecar's disparity at infinity), as a surface at Z would; a depth
// whose disparity exceeds 1 pixel between neighbouring views is clamped to it (parallax recorded).
TEST(Backdrop, ADepthShiftsTheBackdropByItsDisparity) {
  const Render focal = render("depth_focal", "--background environment");
  ASSERT_FALSE(focal.sidecar.is_null());
  const double D = focal.sidecar["rig"]["focal_distance"].get<double>();
  const double k = focal.sidecar["rig"]["disparity_px_at_infinity"].get<double>();
  ASSERT_GT(k, 2.0 * (kViews - 1)) << "the test needs a rig whose infinity is clamped";
  const double f = 3.0 / k, Z = D / (1.0 - f);  // three view pixels from view 0 to view 7
  char depth[64];
  std::snprintf(depth, sizeof depth, "%.17g", Z);
  const Render deep = render("depth_z", std::string("--background environment --background-depth ") + depth);
  ASSERT_EQ(deep.views.size(), size_t(kViews));
  EXPECT_NEAR(deep.sidecar["background"]["parallax"].get<double>(), f, 1e-9);
  const Render bare = render("depth_bare", "");
  const double shift = k * (1.0 - D / Z);
  double worst = 0.0, moved = 0.0;
  size_t compared = 0;
  const std::vector<uint16_t>&first = deep.views[0], &last = deep.views[kViews - 1];
  for (int y = 0; y < kH; ++y)
    for (int x = 8; x < kW - 8; ++x) {
      const size_t p = size_t(y) * kW + size_t(x);
      const double src = x - shift;
      const int x0 = int(std::floor(src));
      const size_t q0 = size_t(y) * kW + size_t(x0), q1 = q0 + 1;
      const bool clear = at(bare.views[kViews - 1], p, 3) == 0.0f && at(bare.views[0], q0, 3) == 0.0f &&
                         at(bare.views[0], q1, 3) == 0.0f;
      if (!clear) continue;
      const double fx = src - x0, g = at(last, p, 1);
      const double shifted = (1.0 - fx) * at(first, q0, 1) + fx * at(first, q1, 1);
      worst = std::max(worst, std::abs(g - shifted));
      moved = std::max(moved, std::abs(g - double(at(first, p, 1))));
      ++compared;
    }
  EXPECT_GT(compared, size_t(kW * kH / 4));
  EXPECT_LE(worst, 0.004);  // linear interpolation of a smooth row
  EXPECT_GT(moved, 0.05) << "the views should differ";
  // infinity asks for k / (N - 1) pixels between neighbours: clamped to one
  const Render far = render("depth_inf", "--background environment --background-depth inf");
  EXPECT_NEAR(far.sidecar["background"]["parallax"].get<double>(), (kViews - 1) / k, 1e-9);
}

// The encoded image is opaque, and a subpixel no object covers shows its view's backdrop at the view
// pixel the encoder reads (DESIGN section 5: the nearest one), in either sampling.
TEST(Backdrop, TheEncodedImageShowsTheBackdropEverywhere) {
  for (const char* sampling : {"view", "subpixel"}) {
    SCOPED_TRACE(sampling);
    const std::string s = std::string("--sampling ") + sampling;
    const Render backed = render(std::string("encoded_") + sampling, "--background environment " + s);
    const Render bare = render(std::string("encoded_bare_") + sampling, s);
    ASSERT_EQ(backed.display.size(), size_t(kDisplayW) * kDisplayH * 4);
    ASSERT_EQ(bare.display.size(), backed.display.size());
    size_t clear = 0;
    double worst = 0.0;
    for (int i = 0; i < kDisplayH; ++i)
      for (int jx = 0; jx < kDisplayW; ++jx) {
        const size_t p = size_t(i) * kDisplayW + size_t(jx);
        EXPECT_EQ(at(backed.display, p, 3), 1.0f);
        if (at(bare.display, p, 3) != 0.0f) continue;
        for (int k = 0; k < 3; ++k) {
          const double u = (jx + (k + 0.5) / 3.0) / kDisplayW, t = (i + 0.5) / kDisplayH;
          const size_t q = size_t(std::floor(t * kH)) * kW + size_t(std::floor(u * kW));
          // the backdrop is the same in every view: any view that does not cover that pixel shows it
          for (int v = 0; v < kViews; ++v)
            if (at(bare.views[size_t(v)], q, 3) == 0.0f) {
              worst = std::max(worst, std::abs(double(at(backed.display, p, k)) - at(backed.views[size_t(v)], q, k)));
              break;
            }
        }
        ++clear;
      }
    EXPECT_GT(clear, size_t(kDisplayW * kDisplayH / 4));
    EXPECT_EQ(worst, 0.0);
  }
}

TEST(Backdrop, OptionsAreCheckedAndTheSidecarIsCompared) {
  const std::string out = test::temp_dir("backdrop_usage");
  const std::string small = " --views 4 --view-size 48x24 --display 160x90 --out " + out;
  test::expect_usage_error(test::run("render --background-depth 3" + small), "--background-depth");
  test::expect_usage_error(test::run("render --background environment --background-depth -1" + small),
                           "--background-depth");
  test::expect_usage_error(test::run("render --background environment --shading lambert" + small), "pbr");
  test::expect_usage_error(test::run("render --background sky" + small), "environment");
  test::expect_resume_compares("--background environment", "\"kind\": \"environment\"", "background");
  // a scene without triangles never starts the encoder that draws the encoded image's backdrop
  const std::string empty = test::temp_dir("backdrop_empty_scene");
  std::system(("mkdir -p '" + empty + "'").c_str());
  std::ofstream(empty + "/empty.gltf") << R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{}]})";
  test::expect_one_error_line(test::run("render " + empty + "/empty.gltf --background environment" + small),
                              "without triangles");
  EXPECT_FALSE(test::exists(out)) << "nothing is written";
}

}  // namespace
}  // namespace pmr
