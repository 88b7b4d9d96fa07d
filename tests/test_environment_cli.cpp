// --environment and --environment-rotation on the command line: bad files and options fail with one
// line and write nothing, the sidecar records the environment, and --resume notices when it changes.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "environment_maps.h"
#include "output/checksum.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::count_entries;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::run;
using test::temp_dir;

const std::string kSmall = " --views 4 --view-size 48x24 --display 192x108 --shading pbr";

// A 64x32 sky with a sun (tests/environment_maps.h) in `dir`.
std::string write_sky(const std::string& dir, const std::string& name, double scale = 1.0) {
  std::system(("mkdir -p '" + dir + "'").c_str());
  const std::string path = dir + "/" + name;
  test::write_exr(path, test::make_map(64, 32, [scale](glm::dvec3 d) { return scale * test::sun_sky(d); }));
  return path;
}

nlohmann::json sidecar(const std::string& out) {
  std::ifstream in(out + "/frame_0000.json");
  return nlohmann::json::parse(in);
}

TEST(EnvironmentCli, BadEnvironmentsFailWithOneLineAndWriteNothing) {
  const std::string out = temp_dir("env_bad");
  expect_one_error_line(run("render" + kSmall + " --environment missing.hdr --out " + out), "missing.hdr");
  const std::string dir = temp_dir("env_bad_files");
  std::system(("mkdir -p '" + dir + "'").c_str());
  std::ofstream(dir + "/broken.exr") << "not an image";
  expect_one_error_line(run("render" + kSmall + " --environment '" + dir + "/broken.exr' --out " + out), "broken.exr");
  EnvironmentImage nan = test::make_map(8, 4, test::sun_sky);
  nan.rgb[5] = std::nanf("");
  test::write_exr(dir + "/nan.exr", nan);
  expect_one_error_line(run("render" + kSmall + " --environment '" + dir + "/nan.exr' --out " + out), "non-finite");
  const std::string sky = write_sky(dir, "sky.exr");
  expect_usage_error(run("render --views 4 --view-size 48x24 --display 192x108 --shading lambert --environment '" +
                         sky + "' --out " + out),
                     "--shading pbr");
  expect_usage_error(run("render" + kSmall + " --environment '" + sky + "' --environment-rotation inf --out " + out),
                     "--environment-rotation");
  expect_usage_error(run("render" + kSmall + " --environment '" + sky + "' --environment-rotation 1e999 --out " + out),
                     "--environment-rotation");
  expect_one_error_line(run("bench --views 4 --method pmr --frames 1 --environment missing.exr --shading pbr"),
                        "missing.exr");
  EXPECT_EQ(count_entries(out), 0u) << "nothing written for a bad environment";
}

// The sidecar records the image (file as given, checksum, rotation, intensity); --resume keeps frames
// of the same environment and refuses, or with --overwrite renders again, when the rotation or the
// file's content changed. --verbose prints the prefilter time.
TEST(EnvironmentCli, SidecarRecordsItAndResumeNoticesChanges) {
  const std::string dir = temp_dir("env_resume");
  const std::string sky = write_sky(dir, "sky.exr"), out = dir + "/out";
  const std::string env = kSmall + " --environment '" + sky + "' --environment-intensity 1.5 --out '" + out + "'";
  const test::CliRun first = run("render" + env + " --environment-rotation 30 --verbose");
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_NE(first.output.find("prefiltered in"), std::string::npos) << first.output;
  const nlohmann::json e = sidecar(out)["shading"]["environment"];
  EXPECT_EQ(e["kind"], "image");
  EXPECT_EQ(e["file"], sky);
  EXPECT_EQ(e["checksum"], checksum_file(sky));
  EXPECT_EQ(e["checksum_algorithm"], "XXH3-64");
  EXPECT_EQ(e["rotation_deg"], 30.0);
  EXPECT_EQ(e["intensity"], 1.5);

  const test::CliRun same = run("render" + env + " --environment-rotation 30 --resume");
  ASSERT_EQ(same.status, 0) << same.output;
  EXPECT_NE(same.output.find("nothing to do"), std::string::npos) << same.output;
  expect_one_error_line(run("render" + env + " --environment-rotation 45 --resume"), "shading differs");
  const test::CliRun turned = run("render" + env + " --environment-rotation 45 --resume --overwrite");
  ASSERT_EQ(turned.status, 0) << turned.output;
  EXPECT_EQ(turned.output.find("nothing to do"), std::string::npos) << turned.output;
  EXPECT_EQ(sidecar(out)["shading"]["environment"]["rotation_deg"], 45.0);

  write_sky(dir, "sky.exr", 2.0);  // the same name, other content
  expect_one_error_line(run("render" + env + " --environment-rotation 45 --resume"), "shading differs");
  const test::CliRun changed = run("render" + env + " --environment-rotation 45 --resume --overwrite");
  ASSERT_EQ(changed.status, 0) << changed.output;
  EXPECT_EQ(sidecar(out)["shading"]["environment"]["checksum"], checksum_file(sky));
}

// The studio is the default, recorded in the sidecar with its rotation, and lights the scene without the
// default light; `uniform` is the earlier default (with the default light), where a rotation warns;
// `./studio` names a file; --resume notices a change of environment; lambert needs none.
TEST(EnvironmentCli, StudioByDefaultUniformByNameAndFilesByPath) {
  const std::string dir = temp_dir("env_keywords");
  const std::string out = dir + "/out";
  const test::CliRun studio = run("render" + kSmall + " --environment-rotation 20 --out '" + out + "'");
  ASSERT_EQ(studio.status, 0) << studio.output;
  EXPECT_EQ(studio.output.find("warning"), std::string::npos) << studio.output;
  nlohmann::json s = sidecar(out)["shading"];
  EXPECT_EQ(s["environment"]["kind"], "studio");
  EXPECT_EQ(s["environment"]["rotation_deg"], 20.0);
  EXPECT_EQ(s["environment"]["intensity"], 1.0);
  // the studio lights the default scene alone: its four boxes drawn as lights (shadows on), turned with
  // it (counter-clockwise seen from above: the key box, at -X 15 degrees above the horizon, toward +Z)
  ASSERT_EQ(s["lights"].size(), 4u) << "the studio lights the default scene alone";
  const double a = 20.0 * M_PI / 180.0, e = 15.0 * M_PI / 180.0;
  const nlohmann::json key = s["lights"][1];
  EXPECT_EQ(key["name"], "studio key");
  EXPECT_NEAR(key["position"][0].get<double>(), -std::cos(a) * std::cos(e), 1e-6);
  EXPECT_NEAR(key["position"][1].get<double>(), std::sin(e), 1e-6);
  EXPECT_NEAR(key["position"][2].get<double>(), std::sin(a) * std::cos(e), 1e-6);
  expect_one_error_line(run("render" + kSmall + " --environment uniform --resume --out '" + out + "'"),
                        "shading differs");

  const std::string flat = dir + "/flat";
  const test::CliRun uniform =
      run("render" + kSmall + " --environment uniform --environment-rotation 20 --out '" + flat + "'");
  ASSERT_EQ(uniform.status, 0) << uniform.output;
  EXPECT_NE(uniform.output.find("does nothing to the uniform environment"), std::string::npos) << uniform.output;
  s = sidecar(flat)["shading"];
  EXPECT_EQ(s["environment"]["kind"], "uniform");
  EXPECT_FALSE(s["environment"].contains("rotation_deg"));
  ASSERT_EQ(s["lights"].size(), 1u);
  EXPECT_EQ(s["lights"][0]["name"], "default");

  expect_one_error_line(run("render" + kSmall + " --environment ./studio --out '" + dir + "/file'"), "./studio");
  expect_usage_error(run("render --views 4 --view-size 48x24 --display 192x108 --shading lambert --environment "
                         "studio --out '" +
                         dir + "/lambert'"),
                     "--shading pbr");
  const test::CliRun lambert =
      run("render --views 4 --view-size 48x24 --display 192x108 --shading lambert --out '" + dir + "/lambert'");
  ASSERT_EQ(lambert.status, 0) << lambert.output;
  EXPECT_FALSE(sidecar(dir + "/lambert")["shading"].contains("environment"));
}

}  // namespace
}  // namespace pmr
