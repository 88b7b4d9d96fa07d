// The `pmr` command line as a user meets it: one clear line and a non-zero exit for bad input, no
// partial files, and real renders whose files independent tools can open.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Imath/half.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "cli/options.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::CliRun;
using test::count_entries;
using test::exists;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::run;
using test::temp_dir;

TEST(Cli, HelpAndInfo) {
  EXPECT_EQ(run("").status, 2);
  const CliRun help = run("render --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("--lens-pitch"), std::string::npos);
  const CliRun info = run("info");
  EXPECT_EQ(info.status, 0);
  EXPECT_NE(info.output.find("device 0"), std::string::npos) << info.output;
}

// --help and the parser are made from one table (cli/options.cpp): every option --help lists is one the
// parser takes (a value it refuses is fine here, an unknown option is not).
TEST(Cli, RenderHelpListsOnlyOptionsTheParserTakes) {
  std::istringstream lines(render_help());
  std::string line;
  int listed = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("  -", 0) != 0) continue;
    const std::string name = line.substr(2, line.find_first_of(" ,", 2) - 2);
    ++listed;
    try {
      parse_render_options({name, "1"});
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find("unknown option"), std::string::npos) << name << ": " << e.what();
    }
  }
  EXPECT_GE(listed, 40) << "the test no longer finds the options in the help";
}

// pmr info SCENE: what the scene holds, without OpenCL; CesiumMan (corpus README: 19 joints, one
// animation) when the corpus is there.
TEST(Cli, InfoDescribesAScene) {
  const CliRun r = run("info " + std::string(PMR_SOURCE_DIR) + "/data/default_scene.glb");
  ASSERT_EQ(r.status, 0) << r.output;
  const Scene s = load_scene(std::string(PMR_SOURCE_DIR) + "/data/default_scene.glb");
  EXPECT_NE(r.output.find("triangles: " + std::to_string(s.triangles.size()) + ","), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("animations: 0"), std::string::npos) << r.output;
  expect_one_error_line(run("info /nonexistent/x.gltf"), "file not found");
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: CesiumMan part skipped";
  const CliRun c = run("info '" + dir + "/CesiumMan/glTF/CesiumMan.gltf'");
  ASSERT_EQ(c.status, 0) << c.output;
  EXPECT_NE(c.output.find("animations: 1"), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("19 joint(s)"), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("to 2.000 s; --frames all at 24 fps: "), std::string::npos) << c.output;  // keys end at 2 s
}

TEST(Cli, BadOptionsFailWithOneLine) {
  const std::string out = temp_dir("badopts");
  expect_usage_error(run("render --views 0 --out " + out), "--views");
  expect_usage_error(run("render --view-size 100 --out " + out), "--view-size");
  expect_usage_error(run("render --tan-slant 1/0 --out " + out), "--tan-slant");
  expect_usage_error(run("render --lens-pitch -3 --out " + out), "--lens-pitch");
  expect_usage_error(run("render --frobnicate --out " + out), "--frobnicate");
  expect_usage_error(run("render --tile 4x4 --out " + out), "--tile");
  expect_usage_error(run("render --write pictures --out " + out), "--write");
  expect_usage_error(run("render --compression lzma --out " + out), "lzma");
  expect_usage_error(run("render --cone 200 --view-size 64x32 --display 64x36 --out " + out), "cone");
  expect_usage_error(run("frobnicate"), "unknown command");
  EXPECT_EQ(count_entries(out), 0u) << "nothing written for bad options";
}

TEST(Cli, BadInputsFailBeforeWritingAnything) {
  const std::string out = temp_dir("badinputs");
  expect_one_error_line(run("render /nonexistent/scene.gltf --out " + out), "scene.gltf");
  const std::string bad = temp_dir("badscene_file");
  std::system(("mkdir -p '" + bad + "'").c_str());
  std::ofstream(bad + "/broken.gltf") << "{ \"asset\": {\"version\": \"2.0\"}, \"buffers\": [ {";
  expect_one_error_line(run("render '" + bad + "/broken.gltf' --view-size 32x16 --display 64x36 --out " + out),
                        "broken.gltf");
  EXPECT_EQ(count_entries(out), 0u);
  // an output folder that cannot be created: a path below a regular file
  std::ofstream(bad + "/file") << "x";
  expect_one_error_line(run("render --view-size 32x16 --display 64x36 --out '" + bad + "/file/sub'"), "output folder");
  // --camera beyond the scene's cameras
  expect_one_error_line(run("render --camera '#3' --view-size 32x16 --display 64x36 --out " + out),
                        "--camera '#3': the scene has 0 camera(s)");
}

TEST(Cli, SmallRenderWritesReadableFiles) {
  const std::string out = temp_dir("small");
  const CliRun r =
      run("render --views 8 --view-size 64x32 --display 480x270 --write encoded,views --verbose --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("fine raster"), std::string::npos) << "--verbose prints stage times";
  int w = 0, h = 0;
  std::vector<uint16_t> img;
  read_rgba_exr(out + "/frame_0000.exr", w, h, img);
  EXPECT_EQ(w, 480);
  EXPECT_EQ(h, 270);
  EXPECT_EQ(read_exr_part_names(out + "/frame_0000.views.exr").size(), 8u);
  std::ifstream js(out + "/frame_0000.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  ASSERT_EQ(j["views"].size(), 8u);
  EXPECT_EQ(j["views"][0]["proj"].size(), 16u);
  EXPECT_EQ(count_entries(out), 3u) << "no temporary files left";
  if (exists("/usr/bin/exrheader")) {
    EXPECT_EQ(std::system(("exrheader " + out + "/frame_0000.exr > /dev/null").c_str()), 0);
  }
}

// The main job: the default scene at the full paper-8k configuration. Every subpixel of the encoded
// image is the right channel of the right view (checked against the views file and a direct
// evaluation of the encoder formula), and all 96 views appear.
TEST(Cli, DefaultScenePaper8k) {
  const std::string out = temp_dir("paper8k");
  const CliRun r = run("render --write encoded,views --verbose --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  std::printf("%s", r.output.c_str());
  int w = 0, h = 0;
  std::vector<uint16_t> img;
  read_rgba_exr(out + "/frame_0000.exr", w, h, img);
  ASSERT_EQ(w, 7680);
  ASSERT_EQ(h, 4320);
  if (exists("/usr/bin/exrheader")) {
    EXPECT_EQ(std::system(("exrheader " + out + "/frame_0000.exr > /dev/null").c_str()), 0);
  }
  const int N = 96, VW = 1024, VH = 512;
  ASSERT_EQ(read_exr_part_names(out + "/frame_0000.views.exr").size(), size_t(N));
  std::vector<std::vector<uint16_t>> views(N);
  std::vector<size_t> covered(N, 0);
  for (int v = 0; v < N; ++v) {
    int vw = 0, vh = 0;
    read_views_exr_part(out + "/frame_0000.views.exr", v, vw, vh, views[size_t(v)]);
    ASSERT_EQ(vw, VW);
    ASSERT_EQ(vh, VH);
    for (size_t p = 0; p < size_t(VW) * VH; ++p) covered[size_t(v)] += views[size_t(v)][p * 4 + 3] != 0;
  }
  const Display d;
  std::set<int> shown;
  size_t mismatches = 0, lit = 0;
  for (int i = 0; i < h; ++i)
    for (int jx = 0; jx < w; ++jx)
      for (int k = 0; k < 3; ++k) {
        const int v = (((18 * jx + 6 * k - i) % N) + N) % N;  // DESIGN section 5 for paper-8k
        if (jx % 97 == 0 && i % 89 == 0) {
          ASSERT_EQ(v, encode_view_index(d, N, jx, i, k));
        }
        const int px = int((jx + (k + 0.5) / 3.0) / w * VW), py = int((i + 0.5) / h * VH);
        const uint16_t want = views[size_t(v)][(size_t(py) * VW + px) * 4 + size_t(k)];
        const uint16_t got = img[(size_t(i) * w + jx) * 4 + size_t(k)];
        mismatches += got != want;
        if (want != 0) {
          shown.insert(v);
          ++lit;
        }
      }
  std::printf("lit subpixels: %zu of %zu; view 0 covers %zu voxels\n", lit, size_t(w) * h * 3, covered[0]);
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(shown.size(), size_t(N)) << "every view contributes lit subpixels";
  EXPECT_GT(lit, size_t(w) * h * 3 / 20) << "the scene fills a fair part of the display";
  // disparity: the outermost views differ
  EXPECT_NE(views[0], views[size_t(N - 1)]);
  for (int v = 0; v < N; ++v) EXPECT_GT(covered[size_t(v)], size_t(VW) * VH / 20) << "view " << v;
}

}  // namespace
}  // namespace pmr
