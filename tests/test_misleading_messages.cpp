// Messages that say what went wrong (issue 21): a calibration file's values are reported as its fields
// (and the file), not as options the user never gave; an option's own value is reported as that option;
// running out of memory is reported as such, never as "not a valid glTF file".
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include "test_util.h"

namespace pmr {
namespace {

using test::CliRun;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::run;
using test::temp_dir;

const std::string kPortrait = R"({"serial": "LKG-P0", "pitch": {"value": 52.1}, "slope": {"value": -7.1},
  "center": {"value": 0.56}, "DPI": {"value": 324}, "screenW": {"value": 1536}, "screenH": {"value": 2048},
  "viewCone": {"value": 40}})";

std::string calibration_with(const std::string& dir, const std::string& name, const std::string& from,
                             const std::string& to) {
  std::string s = kPortrait;
  s.replace(s.find(from), from.size(), to);
  const std::string path = dir + "/" + name;
  std::ofstream(path) << s;
  return path;
}

TEST(MisleadingMessages, CalibrationValuesAreReportedAsTheFilesFields) {
  const std::string dir = temp_dir("calibration_messages");
  std::system(("mkdir -p '" + dir + "'").c_str());
  const std::string out = dir + "/out";
  struct Case {
    std::string name, from, to, field;  // the field changed, which the message names among others
  };
  const Case cases[] = {
      {"dpi.json", R"("DPI": {"value": 324})", R"("DPI": {"value": 1e-300})", "DPI"},
      {"slope.json", R"("slope": {"value": -7.1})", R"("slope": {"value": 1e-300})", "slope"},
      {"center.json", R"("center": {"value": 0.56})", R"("center": {"value": 1e300})", "center"},
  };
  for (const Case& c : cases) {
    const std::string path = calibration_with(dir, c.name, c.from, c.to);
    const CliRun r = run("render --display-config '" + path + "' --out " + out);
    expect_one_error_line(r, path + ": calibration fields ");
    const std::string fields = r.output.substr(r.output.find("calibration fields "));
    EXPECT_NE(fields.substr(0, fields.find(" give ")).find(c.field), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("--lens-pitch"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("--offset"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("invalid offset"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(test::exists(out));
}

TEST(MisleadingMessages, AnOptionsValueIsReportedAsThatOption) {
  const std::string out = temp_dir("option_messages") + "/out";
  const CliRun pitch = run("render --lens-pitch 1e-18 --out " + out);
  expect_usage_error(pitch, "invalid --lens-pitch 1/1000000000000000000");
  EXPECT_EQ(pitch.output.find("invalid offset"), std::string::npos) << pitch.output;
  expect_usage_error(run("render --yfov 0 --out " + out), "invalid --yfov '0'");
  expect_usage_error(run("render --yfov -5 --out " + out), "invalid --yfov '-5'");
  EXPECT_FALSE(test::exists(out));
}

// The pmr binary under an address-space budget (prlimit --as): exit status and output.
CliRun run_capped(uint64_t bytes, const std::string& args) {
  FILE* p = popen(
      ("prlimit --as=" + std::to_string(bytes) + " " + std::string(PMR_BINARY) + " " + args + " 2>&1").c_str(), "r");
  std::string output;
  char buf[4096];
  for (size_t n; p && (n = fread(buf, 1, sizeof buf, p)) > 0;) output.append(buf, n);
  const int st = p ? pclose(p) : -1;
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, output};
}

// OpenEXR's C++ reader allocates a header attribute's declared size before reading it: an
// --environment EXR declaring a 2 GB attribute in 100 bytes (the fuzzer found one of 280 bytes) is
// refused as a broken file before that allocation, also with 1 GB of address space.
TEST(MisleadingMessages, ExrAttributeLargerThanTheFileIsRefusedBeforeItIsAllocated) {
  if (std::system("prlimit --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "prlimit not found";
  const std::string dir = temp_dir("exr_attribute");
  std::system(("mkdir -p '" + dir + "'").c_str());
  std::string bytes = {'\x76', '\x2f', '\x31', '\x01', 2, 0, 0, 0};
  bytes += std::string("blob") + '\0' + "opaque" + '\0';
  bytes += {'\xf0', '\xff', '\xff', '\x7f'};  // 2^31 - 16 bytes
  bytes += std::string(64, 'x');
  std::ofstream(dir + "/sky.exr", std::ios::binary) << bytes;
  const CliRun r =
      run_capped(1000000000, "render --shading pbr --environment '" + dir + "/sky.exr' --out " + dir + "/out");
  expect_one_error_line(r, "sky.exr: not a readable OpenEXR file (");
  EXPECT_EQ(r.output.find("out of host memory"), std::string::npos) << r.output;
  EXPECT_FALSE(test::exists(dir + "/out"));
}

// Every environment input the fuzzer found (tests/fuzz/regressions/environment: header attributes and
// a data window that made OpenEXR allocate 1.6 to 1.9 GB from a few hundred bytes) is refused as a bad
// file with 1 GB of address space, not reported as running out of memory.
TEST(MisleadingMessages, FuzzedEnvironmentFilesAreRefusedWithinAGigabyte) {
  if (std::system("prlimit --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "prlimit not found";
  const std::string out = temp_dir("fuzzed_environments") + "/out";
  size_t files = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(std::string(PMR_SOURCE_DIR) + "/tests/fuzz/regressions/environment")) {
    ++files;
    const CliRun r =
        run_capped(1000000000, "render --shading pbr --environment '" + e.path().string() + "' --out " + out);
    expect_one_error_line(r, e.path().filename().string());
    EXPECT_EQ(r.output.find("out of host memory"), std::string::npos) << r.output;
  }
  EXPECT_GE(files, 3u);
  EXPECT_FALSE(test::exists(out));
}

// A glTF file whose JSON needs more memory than the process may have (a 16 MB extras array, hundreds
// of MB parsed; the address space capped with prlimit): an out-of-memory error, exit 1, never "not a
// valid glTF file".
TEST(MisleadingMessages, RunningOutOfMemoryIsNotAnInvalidFile) {
  if (std::system("prlimit --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "prlimit not found";
  const std::string dir = temp_dir("oom_message");
  std::system(("mkdir -p '" + dir + "'").c_str());
  const std::string path = dir + "/extras.gltf";
  {
    std::ofstream f(path);
    f << R"({"asset": {"version": "2.0"}, "extras": [0)";
    for (int i = 0; i < 8 << 20; ++i) f << ",0";
    f << "]}";
  }
  // the memory budget (docs/SECURITY.md) sees it coming before parsing
  CliRun r = run_capped(1000000000, "info '" + path + "'");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("out of memory: parsing the scene's JSON"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("not a valid glTF file"), std::string::npos) << r.output;
  // with the budget raised past what the process may have, the parser's allocation fails instead
  r = run_capped(1000000000, "info --limit memory=64G '" + path + "'");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("out of host memory"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("not a valid glTF file"), std::string::npos) << r.output;
}

// Each limit is named with the value the user gave: a glTF camera's tiny yfov (not "the view cone is
// too wide"), an environment's side (not its texel count), and the memory an environment decodes to.
TEST(MisleadingMessages, LimitsAreNamedWithTheValueGiven) {
  const std::string dir = temp_dir("limit_messages");
  std::filesystem::create_directories(dir);
  // a Radiance header of 33554432 x 1 texels: 33554432 texels in all, but far wider than a side may be
  std::ofstream(dir + "/wide.hdr") << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 33554432\n";
  CliRun r = run("render --environment " + dir + "/wide.hdr --out " + dir + "/o1 --views 2 --view-size 32x16");
  expect_one_error_line(r, "the image is too large (33554432x1); environments may be at most 16384 texels on a side");
  // 8192 x 4096, run-length encoded (2 MB): decoding and prefiltering it needs about 1.5 GB
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4096 +X 8192\n";
  std::string row = {2, 2, char(0x20), 0};
  for (int channel = 0; channel < 4; ++channel) {
    for (int run = 0; run < 64; ++run) row += {char(128 + 127), char(channel == 3 ? 128 : 10)};
    row += {char(128 + 64), char(channel == 3 ? 128 : 10)};
  }
  for (int y = 0; y < 4096; ++y) hdr += row;
  std::ofstream(dir + "/big.hdr", std::ios::binary) << hdr;
  r = run("render --environment " + dir + "/big.hdr --limit memory=256M --out " + dir + "/o2 --views 2 --view-size 32x16");
  expect_one_error_line(r, "out of memory: decoding the 8192x4096 environment");
  // a glTF camera with yfov 1e-7: the disparity leaves the fixed-point range; the message says why
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 1e-7, "znear": 0.1}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [-1, -1, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAAAAAAAAgD8AAAAA"}]})";
  std::ofstream(dir + "/narrow.gltf") << gltf;
  r = run("render " + dir + "/narrow.gltf --camera '#0' --out " + dir + "/o3 --views 4 --view-size 32x16");
  expect_one_error_line(r, "a vertical field of view of 5.72958e-06 degrees (the glTF camera's yfov)");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pmr
