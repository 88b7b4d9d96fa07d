// The frame's metadata in the EXR headers (docs/OUTPUTS.md), read back from files the real command line
// wrote: the attributes and their values, the matrices against the sidecar's (converted here by the
// documented formulas, not by the code under test), a projection through worldToNDC landing where the
// view drew the geometry (both ends of the rig and the quilt's center tile), identical files for a
// frame rendered twice, and exrheader showing the attributes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <ImfDoubleAttribute.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfMultiPartInputFile.h>
#include <ImfRationalAttribute.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfTimeCodeAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "output/exr_metadata.h"
#include "pmr/output.h"
#include "pmr/scene.h"
#include "pmr/version.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using test::run;
using test::temp_dir;

// A quadrilateral 1.6 wide whose left edge (y from -0.5 to 0.3) is 0.5 in front of the middle (toward
// the camera on +Z) and its right edge (y from -0.3 to 0.5) 0.5 behind: in every view both edges are
// vertical, one in front of the focal plane and one behind it (their disparities have opposite signs),
// and the lowest and highest corners lie at different depths (a flipped y would show).
const glm::vec3 kCorners[4] = {{-0.8f, -0.5f, 0.5f}, {0.8f, -0.3f, -0.5f}, {0.8f, 0.5f, -0.5f}, {-0.8f, 0.3f, 0.5f}};

// 5 views of 96x48 (view 2 is the center), a 30 degree cone (about 7 px between the edges' positions
// in views 0 and 4), frame 37 at 24 fps: time code 00:00:01:13. The quilt is 3x2, so the center view's
// tile (column 2 of the bottom row) is not where a flipped column or row would put it.
const std::string kArgs =
    " --views 5 --view-size 96x48 --display 240x135 --cone 30 --frames 37 --fps 24 --quilt 3x2 -q ";

// The quadrilateral as a .glb, written once per process and removed at exit.
std::string quad_scene() {
  struct File {
    std::string path = ::testing::TempDir() + "pmr_exr_meta_quad_" + std::to_string(getpid()) + ".glb";
    File() {
      Scene s = test::empty_scene(true);
      test::add_triangle(s, kCorners[0], kCorners[1], kCorners[2]);
      test::add_triangle(s, kCorners[0], kCorners[2], kCorners[3]);
      save_glb(s, path);
    }
    ~File() { std::remove(path.c_str()); }
  };
  static const File file;
  return file.path;
}

struct Files {
  std::string dir, encoded, views, quilt, sidecar;
  nlohmann::json json;
};

Files render_quad(const std::string& name, const std::string& extra = "") {
  Files f;
  f.dir = temp_dir(name);
  const test::CliRun r =
      run("render '" + quad_scene() + "'" + kArgs + "--write encoded,views,quilt " + extra + " --out " + f.dir);
  EXPECT_EQ(r.status, 0) << r.output;
  f.encoded = f.dir + "/frame_0037.exr";
  f.views = f.dir + "/frame_0037.views.exr";
  f.sidecar = f.dir + "/frame_0037.json";
  for (const auto& e : fs::directory_iterator(f.dir))
    if (e.path().filename().string().find("_qs") != std::string::npos) f.quilt = e.path().string();
  f.json = nlohmann::json::parse(test::read_file(f.sidecar));
  return f;
}

// A sidecar matrix (16 numbers, column-major) applied to a point (column vector).
glm::dvec4 apply(const nlohmann::json& m, glm::dvec4 p) {
  glm::dvec4 out(0.0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[r] += m[size_t(c * 4 + r)].get<double>() * p[c];
  return out;
}

// Imath's row-vector product p M with the division by w (what readers of worldToNDC do).
Imath::V3d row_times(const Imath::M44f& m, glm::dvec3 p) {
  const Imath::V3d v = Imath::V3d(p.x, p.y, p.z) * Imath::M44d(m);
  return v;
}

template <class T>
const T* attr(const Imf::Header& h, const char* name) {
  return h.findTypedAttribute<T>(name);
}

// The expected OpenEXR camera and NDC coordinates of world point p in view i, from the sidecar's
// OpenGL matrices: camera = view-space with z negated; NDC x = (x_ndc + 1) / 2, y = (1 - y_ndc) / 2.
void expect_matrices_of_view(const Imf::Header& h, const nlohmann::json& j, int i, const std::string& what) {
  SCOPED_TRACE(what + ", view " + std::to_string(i));
  ASSERT_TRUE(Imf::hasWorldToCamera(h));
  ASSERT_TRUE(Imf::hasWorldToNDC(h));
  const nlohmann::json& v = j["views"][size_t(i)];
  for (const glm::vec3& c : kCorners) {
    const glm::dvec4 p(glm::dvec3(c), 1.0);
    const glm::dvec4 eye = apply(v["view"], p), clip = apply(v["proj"], eye);
    const Imath::V3d cam = row_times(Imf::worldToCamera(h), glm::dvec3(p));
    EXPECT_NEAR(cam.x, eye.x, 1e-5);
    EXPECT_NEAR(cam.y, eye.y, 1e-5);
    EXPECT_NEAR(cam.z, -eye.z, 1e-5);
    const Imath::V3d ndc = row_times(Imf::worldToNDC(h), glm::dvec3(p));
    EXPECT_NEAR(ndc.x, (clip.x / clip.w + 1.0) / 2.0, 1e-5);
    EXPECT_NEAR(ndc.y, (1.0 - clip.y / clip.w) / 2.0, 1e-5);
  }
}

void expect_frame_attributes(const Imf::Header& h, const char* output, int view) {
  SCOPED_TRACE(std::string(output) + " view " + std::to_string(view));
  ASSERT_TRUE(attr<Imf::StringAttribute>(h, "software"));
  const std::string software = attr<Imf::StringAttribute>(h, "software")->value();
  EXPECT_EQ(software, std::string("pmr ") + program_version());
  EXPECT_EQ(software.rfind("pmr 0.", 0), 0u) << software;
  ASSERT_TRUE(Imf::hasFramesPerSecond(h));
  EXPECT_EQ(Imf::framesPerSecond(h).n, 24);
  EXPECT_EQ(Imf::framesPerSecond(h).d, 1u);
  // the colour is linear Rec. 709 (ITU-R BT.709 primaries, D65 white)
  ASSERT_TRUE(Imf::hasChromaticities(h));
  const Imf::Chromaticities c = Imf::chromaticities(h);
  const float want[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
  const float got[8] = {c.red.x, c.red.y, c.green.x, c.green.y, c.blue.x, c.blue.y, c.white.x, c.white.y};
  for (int k = 0; k < 8; ++k) EXPECT_FLOAT_EQ(got[k], want[k]) << "chromaticity " << k;
  ASSERT_TRUE(Imf::hasTimeCode(h));
  const Imf::TimeCode tc = Imf::timeCode(h);
  EXPECT_EQ(tc.hours(), 0);
  EXPECT_EQ(tc.minutes(), 0);
  EXPECT_EQ(tc.seconds(), 1);
  EXPECT_EQ(tc.frame(), 13);  // 37 = 24 + 13
  EXPECT_FALSE(tc.dropFrame());
  ASSERT_TRUE(attr<Imf::IntAttribute>(h, "pmrFrame"));
  EXPECT_EQ(attr<Imf::IntAttribute>(h, "pmrFrame")->value(), 37);
  ASSERT_TRUE(attr<Imf::DoubleAttribute>(h, "pmrTime"));
  EXPECT_DOUBLE_EQ(attr<Imf::DoubleAttribute>(h, "pmrTime")->value(), 37.0 / 24.0);
  ASSERT_TRUE(attr<Imf::DoubleAttribute>(h, "pmrFps"));
  EXPECT_EQ(attr<Imf::DoubleAttribute>(h, "pmrFps")->value(), 24.0);
  ASSERT_TRUE(attr<Imf::StringAttribute>(h, "pmrSidecar"));
  EXPECT_EQ(attr<Imf::StringAttribute>(h, "pmrSidecar")->value(), "frame_0037.json");
  ASSERT_TRUE(attr<Imf::StringAttribute>(h, "pmrOutput"));
  EXPECT_EQ(attr<Imf::StringAttribute>(h, "pmrOutput")->value(), output);
  ASSERT_TRUE(attr<Imf::IntAttribute>(h, "pmrView"));
  EXPECT_EQ(attr<Imf::IntAttribute>(h, "pmrView")->value(), view);
  ASSERT_TRUE(attr<Imf::IntAttribute>(h, "pmrViews"));
  EXPECT_EQ(attr<Imf::IntAttribute>(h, "pmrViews")->value(), 5);
  EXPECT_TRUE(h.find("capDate") == h.end()) << "nothing that depends on the time of day";
  EXPECT_TRUE(h.find("utcOffset") == h.end());
}

// Columns [x0, x1) and rows [y0, y1) of the pixels with alpha > 0 inside the given region.
struct Coverage {
  int x0 = 1 << 30, x1 = -1, y0 = 1 << 30, y1 = -1;
};
Coverage coverage(const std::vector<uint16_t>& rgba, int width, int rx, int ry, int rw, int rh) {
  Coverage c;
  for (int y = ry; y < ry + rh; ++y)
    for (int x = rx; x < rx + rw; ++x)
      if (rgba[(size_t(y) * size_t(width) + size_t(x)) * 4 + 3] != 0) {
        c.x0 = std::min(c.x0, x), c.x1 = std::max(c.x1, x + 1);
        c.y0 = std::min(c.y0, y), c.y1 = std::max(c.y1, y + 1);
      }
  return c;
}

// The rectangle's corners through worldToNDC, scaled to an image of width x height: their bounding box
// must be the drawn pixels' within 1 px on every side. Returns the projected left edge (x).
double expect_projection_matches(const Imath::M44f& to_ndc, const std::vector<uint16_t>& rgba, int width, int height,
                                 int rx, int ry, int rw, int rh, const std::string& what) {
  SCOPED_TRACE(what);
  double x0 = 1e30, x1 = -1e30, y0 = 1e30, y1 = -1e30;
  for (const glm::vec3& c : kCorners) {
    const Imath::V3d n = row_times(to_ndc, glm::dvec3(c));
    x0 = std::min(x0, n.x * width), x1 = std::max(x1, n.x * width);
    y0 = std::min(y0, n.y * height), y1 = std::max(y1, n.y * height);
  }
  const Coverage cov = coverage(rgba, width, rx, ry, rw, rh);
  EXPECT_GT(cov.x1, cov.x0) << "the rectangle is visible";
  EXPECT_NEAR(cov.x0, x0, 1.0);
  EXPECT_NEAR(cov.x1, x1, 1.0);
  EXPECT_NEAR(cov.y0, y0, 1.0);
  EXPECT_NEAR(cov.y1, y1, 1.0);
  return x0;
}

}  // namespace

// The time code exists only for whole frame rates up to 30 within the first 24 hours.
TEST(ExrMetadata, TimeCodeOnlyForWholeFrameRatesUpTo30) {
  int h = -1, m = -1, s = -1, f = -1;
  ASSERT_TRUE(exr_time_code(37, 24.0, h, m, s, f));
  EXPECT_EQ(h * 1000000 + m * 10000 + s * 100 + f, 113);
  ASSERT_TRUE(exr_time_code(30 * 3723 + 29, 30.0, h, m, s, f));  // 1 h 2 min 3 s and 29 frames
  EXPECT_EQ(h * 1000000 + m * 10000 + s * 100 + f, 1020329);
  EXPECT_FALSE(exr_time_code(1, 29.97, h, m, s, f));
  EXPECT_FALSE(exr_time_code(1, 60.0, h, m, s, f));
  EXPECT_FALSE(exr_time_code(1, 0.5, h, m, s, f));
  EXPECT_FALSE(exr_time_code(25L * 24 * 3600, 25.0, h, m, s, f)) << "past 23:59:59:24";
  EXPECT_TRUE(exr_time_code(25L * 24 * 3600 - 1, 25.0, h, m, s, f));
  EXPECT_EQ(h * 1000000 + m * 10000 + s * 100 + f, 23595924);
}

// (1) Every EXR of a frame carries the frame's attributes; each views part its own view name and
// matrices, the encoded image and the quilt the center view's; a frame rendered twice gives the very
// same bytes; a non-integer frame rate gets its exact rational and no time code.
TEST(ExrMetadata, EveryFileCarriesTheFramesAttributes) {
  const Files f = render_quad("exrmeta_attrs");
  ASSERT_FALSE(f.quilt.empty()) << "no quilt file";
  const nlohmann::json& j = f.json;
  ASSERT_EQ(j["views"].size(), 5u);

  {
    Imf::MultiPartInputFile in(f.encoded.c_str());
    ASSERT_EQ(in.parts(), 1);
    expect_frame_attributes(in.header(0), "encoded", 2);
    expect_matrices_of_view(in.header(0), j, 2, "encoded");
    EXPECT_FALSE(Imf::hasMultiView(in.header(0)));
  }
  {
    Imf::MultiPartInputFile in(f.views.c_str());
    ASSERT_EQ(in.parts(), 5);
    for (int i = 0; i < 5; ++i) {
      const Imf::Header& h = in.header(i);
      expect_frame_attributes(h, "views", i);
      ASSERT_TRUE(h.hasView());
      EXPECT_EQ(h.view(), "view_00" + std::to_string(i));
      EXPECT_EQ(h.view(), h.name());
      EXPECT_FALSE(Imf::hasMultiView(h)) << "multi-part files name views per part, never in multiView";
      expect_matrices_of_view(h, j, i, "views");
    }
  }
  {
    Imf::MultiPartInputFile in(f.quilt.c_str());
    const Imf::Header& h = in.header(0);
    expect_frame_attributes(h, "quilt", 2);
    const int C = j["quilt"]["columns"], R = j["quilt"]["rows"];
    const int col = 2 % C, row_from_top = R - 1 - 2 / C;  // view 0 is the bottom-left tile
    const nlohmann::json& v = j["views"][2];
    for (const glm::vec3& c : kCorners) {
      const glm::dvec4 clip = apply(v["proj"], apply(v["view"], glm::dvec4(glm::dvec3(c), 1.0)));
      const Imath::V3d n = row_times(Imf::worldToNDC(h), glm::dvec3(c));
      EXPECT_NEAR(n.x, (col + (clip.x / clip.w + 1.0) / 2.0) / C, 1e-5);
      EXPECT_NEAR(n.y, (row_from_top + (1.0 - clip.y / clip.w) / 2.0) / R, 1e-5);
    }
  }

  // rendered again: byte for byte the same files (no date or other varying attribute)
  const Files g = render_quad("exrmeta_again");
  for (const auto& [a, b] : {std::pair{f.encoded, g.encoded}, {f.views, g.views}, {f.quilt, g.quilt}})
    EXPECT_TRUE(test::read_file(a) == test::read_file(b)) << a << " and " << b << " differ";

  // NTSC rate: the exact rational, no time code
  const std::string ntsc = temp_dir("exrmeta_ntsc");
  const test::CliRun r = run("render '" + quad_scene() +
                             "' --views 3 --view-size 32x16 --display 64x36 --frames 2 --fps 29.97 -q --out " + ntsc);
  ASSERT_EQ(r.status, 0) << r.output;
  Imf::MultiPartInputFile in((ntsc + "/frame_0002.exr").c_str());
  ASSERT_TRUE(Imf::hasFramesPerSecond(in.header(0)));
  EXPECT_EQ(Imf::framesPerSecond(in.header(0)).n, 30000);
  EXPECT_EQ(Imf::framesPerSecond(in.header(0)).d, 1001u);
  EXPECT_FALSE(Imf::hasTimeCode(in.header(0)));
  EXPECT_DOUBLE_EQ(attr<Imf::DoubleAttribute>(in.header(0), "pmrTime")->value(), 2.0 / 29.97);
  EXPECT_EQ(attr<Imf::IntAttribute>(in.header(0), "pmrView")->value(), 1);
}

// (2) The rectangle's corners through each end view's worldToNDC land within 1 px of the pixels that
// view drew (a sign error in the per-view shift moves them by several pixels), and so do they through
// the quilt's worldToNDC in its center tile. worldToCamera puts the corners in front of the camera at
// z = their distance along the axis, x and y relative to the view's camera position (from the sidecar's
// rig description: cameras on a line along +X at focal_distance from the framing center).
TEST(ExrMetadata, WorldToNdcProjectsWhereTheViewDrew) {
  const Files f = render_quad("exrmeta_proj");
  const nlohmann::json& j = f.json;
  Imf::MultiPartInputFile in(f.views.c_str());
  ASSERT_EQ(in.parts(), 5);
  double left_edge[5] = {};
  for (int i : {0, 4}) {
    int w = 0, h = 0;
    std::vector<uint16_t> px;
    read_views_exr_part(f.views, i, w, h, px);
    ASSERT_EQ(w, 96);
    ASSERT_EQ(h, 48);
    left_edge[i] =
        expect_projection_matches(Imf::worldToNDC(in.header(i)), px, w, h, 0, 0, w, h, "view " + std::to_string(i));
  }
  EXPECT_GT(std::abs(left_edge[4] - left_edge[0]), 3.0) << "the end views must differ for this test to mean anything";

  // worldToCamera against the rig's geometry
  const glm::dvec3 lo(j["scene_bounds"]["min"][0], j["scene_bounds"]["min"][1], j["scene_bounds"]["min"][2]);
  const glm::dvec3 hi(j["scene_bounds"]["max"][0], j["scene_bounds"]["max"][1], j["scene_bounds"]["max"][2]);
  const glm::dvec3 center = 0.5 * (lo + hi);
  const double D = j["rig"]["focal_distance"];
  for (int i : {0, 2, 4}) {
    const double s = j["views"][size_t(i)]["offset"];
    for (const glm::vec3& c : kCorners) {
      const Imath::V3d cam = row_times(Imf::worldToCamera(in.header(i)), glm::dvec3(c));
      EXPECT_GT(cam.z, 0.0) << "in front of the camera";
      EXPECT_NEAR(cam.z, center.z + D - c.z, 1e-4) << "view " << i;
      EXPECT_NEAR(cam.x, c.x - (center.x + s), 1e-4) << "view " << i;
      EXPECT_NEAR(cam.y, c.y - center.y, 1e-4) << "view " << i;
    }
  }

  // the quilt: the center view's tile
  int qw = 0, qh = 0;
  std::vector<uint16_t> quilt;
  read_rgba_exr(f.quilt, qw, qh, quilt);
  const int C = j["quilt"]["columns"], R = j["quilt"]["rows"];
  ASSERT_EQ(qw, C * 96);
  ASSERT_EQ(qh, R * 48);
  Imf::MultiPartInputFile qin(f.quilt.c_str());
  expect_projection_matches(Imf::worldToNDC(qin.header(0)), quilt, qw, qh, (2 % C) * 96, (R - 1 - 2 / C) * 48, 96, 48,
                            "quilt, center tile");
}

// (3) exrheader, OpenEXR's own tool, shows the attributes.
TEST(ExrMetadata, ExrheaderShowsTheAttributes) {
  const char* tool = "/usr/bin/exrheader";
  if (::access(tool, X_OK) != 0) GTEST_SKIP() << tool << " is not installed (package openexr); skipped";
  const Files f = render_quad("exrmeta_exrheader");
  for (const std::string& file : {f.encoded, f.views, f.quilt}) {
    std::string out;
    FILE* p = popen((std::string(tool) + " '" + file + "' 2>&1").c_str(), "r");
    ASSERT_TRUE(p);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    EXPECT_EQ(pclose(p), 0) << out;
    SCOPED_TRACE(file);
    for (const std::string& s :
         {std::string("software (type string): \"pmr ") + program_version() + "\"",
          std::string("framesPerSecond (type rational): 24/1"), std::string("timeCode (type timecode)"),
          std::string("pmrFrame (type int): 37"), std::string("pmrSidecar (type string): \"frame_0037.json\""),
          std::string("worldToCamera (type m44f)"), std::string("worldToNDC (type m44f)"),
          std::string("chromaticities (type chromaticities)")})
      EXPECT_NE(out.find(s), std::string::npos) << "missing: " << s << "\n" << out;
    if (file == f.views) {
      EXPECT_NE(out.find("view (type string): \"view_000\""), std::string::npos) << out;
      EXPECT_NE(out.find("view (type string): \"view_004\""), std::string::npos) << out;
    }
  }
}

}  // namespace pmr
