// `pmr bench` at a tiny configuration: the CSV has the documented columns, one row per point, and the
// methods' images agree; the synthetic scene has about the requested triangle count.
#include <gtest/gtest.h>

#include <algorithm>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "test_util.h"

namespace pmr {
namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) out.push_back(f);
  return out;
}

TEST(Bench, WritesCsvWithOneRowPerPoint) {
  const std::string csv = ::testing::TempDir() + "pmr_bench_test_" + std::to_string(getpid()) + ".csv";
  const std::string cmd =
      std::string(PMR_BINARY) +
      " bench --synthetic 2000 --views 1,3,8 --method pmr,multipass,duplicate --sampling view,subpixel --frames 1"
      " --view-size 64x32 --display 320x180 --csv " +
      csv + " > /dev/null 2>&1";
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << cmd;
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("scene,method,views,view_w,view_h,display_w,display_h,triangles,frames,ms_median,ms_min,"
                         "ms_setup,ms_tile,ms_fine,ms_encode,mvoxels_per_s,peak_mem_mb",
                         0),
            0u)
      << header;
  const auto cols = split_csv(header);
  auto column = [&](const std::string& name) {
    const auto it = std::find(cols.begin(), cols.end(), name);
    EXPECT_NE(it, cols.end()) << name;
    return size_t(it - cols.begin());
  };
  const size_t mismatch = column("coverage_mismatch"), sampling = column("sampling"), samples = column("samples");
  std::string line;
  int rows = 0, subpixel_rows = 0;
  while (std::getline(in, line)) {
    const auto f = split_csv(line);
    ASSERT_EQ(f.size(), cols.size()) << line;
    EXPECT_GT(std::stod(f[9]), 0.0) << "ms_median";
    EXPECT_LE(std::stod(f[10]), std::stod(f[9])) << "ms_min <= ms_median";
    EXPECT_LT(std::stod(f[mismatch]), 0.001) << "coverage mismatch between methods: " << line;
    if (f[sampling] == "subpixel") {  // PMR only, one sample per display subpixel
      ++subpixel_rows;
      EXPECT_EQ(f[1], "pmr") << line;
      EXPECT_EQ(std::stod(f[samples]), 3.0 * 320 * 180) << line;
    } else {
      EXPECT_EQ(f[sampling], "view") << line;
      EXPECT_EQ(std::stod(f[samples]), std::stod(f[2]) * 64 * 32) << line;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 12);
  EXPECT_EQ(subpixel_rows, 3);
}

// --samples LIST: a row per sample count, recorded in the CSV; the methods agree at each count.
TEST(Bench, SweepsSamplesPerPixel) {
  const std::string csv = ::testing::TempDir() + "pmr_bench_samples_" + std::to_string(getpid()) + ".csv";
  const std::string cmd = std::string(PMR_BINARY) +
                          " bench --synthetic 2000 --views 3 --method pmr,multipass --samples 1,4 --frames 1"
                          " --view-size 64x32 --display 320x180 --csv " +
                          csv + " > /dev/null 2>&1";
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << cmd;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  const auto cols = split_csv(line);
  const size_t spp = size_t(std::find(cols.begin(), cols.end(), "samples_per_pixel") - cols.begin());
  const size_t mismatch = size_t(std::find(cols.begin(), cols.end(), "coverage_mismatch") - cols.begin());
  ASSERT_LT(spp, cols.size()) << line;
  std::vector<std::string> seen;
  while (std::getline(in, line)) {
    const auto f = split_csv(line);
    ASSERT_EQ(f.size(), cols.size()) << line;
    seen.push_back(f[1] + "/" + f[spp]);
    EXPECT_LT(std::stod(f[mismatch]), 0.001) << line;
  }
  EXPECT_EQ(seen, (std::vector<std::string>{"pmr/1", "pmr/4", "multipass/1", "multipass/4"}));
}

TEST(Bench, SyntheticSceneHasAboutTheRequestedTriangles) {
  for (size_t n : {1000u, 100000u}) {
    const Scene s = make_synthetic_scene(n);
    EXPECT_NEAR(double(s.triangles.size()), double(n), 0.02 * n + 200);
    glm::dvec3 lo, hi;
    scene_bounds(s, lo, hi);
    EXPECT_GT(hi.z - lo.z, 2.5) << "spread through the depth range";
  }
}

}  // namespace
}  // namespace pmr

namespace pmr {
namespace {

// --queue-stats prints the last frame's histograms. The duplicate baseline emits one MTA per view, so
// its views-per-MTA histogram is all ones; PMR's MTAs span several of the 8 views.
TEST(Bench, QueueStatsDescribeTheLastFrame) {
  const std::string common =
      "bench --synthetic 2000 --views 8 --frames 1 --view-size 64x32 --display 320x180 "
      "--no-check --queue-stats --method ";
  const test::CliRun dup = test::run(common + "duplicate");
  ASSERT_EQ(dup.status, 0) << dup.output;
  EXPECT_NE(dup.output.find("# queue stats of the last frame: "), std::string::npos) << dup.output;
  EXPECT_NE(dup.output.find("views per MTA (mean 1.00): 0-1: 100.0%"), std::string::npos) << dup.output;
  const test::CliRun pmr = test::run(common + "pmr");
  ASSERT_EQ(pmr.status, 0) << pmr.output;
  const size_t at = pmr.output.find("views per MTA (mean ");
  ASSERT_NE(at, std::string::npos) << pmr.output;
  EXPECT_GT(std::stod(pmr.output.substr(at + 20)), 1.5) << pmr.output;
  EXPECT_NE(pmr.output.find("ns/entry"), std::string::npos) << pmr.output;
}

}  // namespace
}  // namespace pmr
