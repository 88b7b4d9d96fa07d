// PoCL compiles a work-group function per (kernel, local size, small grid, zero offset) and caches it
// in POCL_CACHE_DIR. A render must compile all of them before its first frame, exactly one per (kernel,
// local size) pair it launches, and nothing while frames render, however the per-frame counts (MTAs,
// tile-queue entries) change. Checked with the real command line on an empty cache, as a farm node
// starts.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <sstream>

#include "test_util.h"

namespace {

namespace fs = std::filesystem;
namespace test = pmr::test;

size_t count_files(const std::string& dir, const std::string& extension) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == extension) ++n;
  return n;
}

// The work-group functions in a PoCL cache: ".../<kernel>/<local>-...-smallgrid/<kernel>.so" as
// "<kernel>/<variant directory>".
std::multiset<std::string> built_functions(const std::string& cache) {
  std::multiset<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(cache, ec); it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (ec) break;
    const fs::path& p = it->path();
    if (p.extension() == ".so")
      out.insert(p.parent_path().parent_path().filename().string() + "/" + p.parent_path().filename().string());
  }
  return out;
}

// The "(N work-group functions: a 64x1, b 8x1, ...)" list of `pmr render --verbose`.
std::vector<std::string> announced_functions(const std::string& output) {
  const std::regex re("kernels built in [0-9.]+ s \\(([0-9]+) work-group functions: ([^)]*)\\)");
  std::smatch m;
  if (!std::regex_search(output, m, re)) return {};
  std::vector<std::string> names;
  std::stringstream list(m[2].str());
  std::string item;
  while (std::getline(list, item, ',')) names.push_back(item.substr(item.find_first_not_of(' ')));
  EXPECT_EQ(size_t(std::stoul(m[1].str())), names.size());
  return names;
}

std::set<unsigned> mta_counts(const std::string& output) {
  std::set<unsigned> counts;
  const std::regex re("; ([0-9]+) MTAs,");
  for (auto it = std::sregex_iterator(output.begin(), output.end(), re); it != std::sregex_iterator(); ++it)
    counts.insert(unsigned(std::stoul((*it)[1].str())));
  return counts;
}

// Renders with an empty cache; every function built must be one the render announced (one .so per
// announced (kernel, local size) pair: the local size is the variant directory's first number).
std::string expect_builds_before_first_frame(const std::string& name, const std::string& scene, const std::string& args,
                                             size_t frames) {
  const std::string cache = test::temp_dir(name + "_cache"), out = test::temp_dir(name + "_out");
  fs::create_directories(cache);
  const test::CliRun r =
      test::run_env("POCL_CACHE_DIR='" + cache + "'", "render " + scene + " --verbose" + args + " --out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  const std::vector<std::string> announced = announced_functions(r.output);
  const std::multiset<std::string> built = built_functions(cache);
  std::string listing;
  for (const std::string& b : built) listing += "  " + b + "\n";
  std::cout << "[ built    ] " << name << ": " << built.size() << " work-group functions\n" << listing;
  EXPECT_FALSE(announced.empty()) << r.output;
  EXPECT_EQ(built.size(), announced.size()) << "built:\n" << listing << r.output;
  for (const std::string& a : announced) {  // "bin_count 64x1" -> "bin_count/64-1-1-goffs0-smallgrid"
    const std::string kernel = a.substr(0, a.find(' ')), local = a.substr(a.find(' ') + 1);
    const std::string lx = local.substr(0, local.find('x')), ly = local.substr(local.find('x') + 1);
    EXPECT_EQ(built.count(kernel + "/" + lx + "-" + ly + "-1-goffs0-smallgrid"), 1u) << a << "\n" << listing;
  }
  EXPECT_EQ(count_files(out, ".exr"), frames) << r.output;
  return r.output;
}

}  // namespace

// A skinned, morphing tube bending for 24 frames: the MTA count changes from frame to frame.
TEST(KernelBuilds, AllBuiltBeforeTheFirstFrameOfAnAnimatedSequence) {
  const std::string dir = test::temp_dir("kb_scene");
  fs::create_directories(dir);
  const std::string scene = dir + "/tube.gltf";
  ASSERT_EQ(std::system(("python3 '" + std::string(PMR_SOURCE_DIR) + "/scripts/make_skinned_tube.py' '" + scene +
                         "' 48 20 > /dev/null")
                            .c_str()),
            0);
  const std::string args = " --frames 0:23 --views 8 --view-size 96x48 --display 320x180";
  const std::string output = expect_builds_before_first_frame("kb_fused", scene, args, 24);
  // the MTA count really changes (when PoCL chose the local size, each new count built new functions)
  EXPECT_GE(mta_counts(output).size(), 10u) << output;
}

// The other kernels: views kept (fine raster + encoder; the baselines use the same kernels) and subpixel
// sampling.
TEST(KernelBuilds, OtherPathsBuildBeforeTheFirstFrame) {
  const std::string small = " --views 8 --view-size 96x48 --display 320x180";
  expect_builds_before_first_frame("kb_views", "", " --turntable 90:3 --frames 0:2 --write encoded,views" + small, 6);
  expect_builds_before_first_frame("kb_subpixel", "", " --turntable 90:3 --frames 0:2 --sampling subpixel" + small, 3);
}
