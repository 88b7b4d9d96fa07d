// The kernels' headers (cl/*.h) each include what they read, so that no header depends on what its
// includer happened to define above it, and each puts cl/common.h's FP_CONTRACT pragma before its first
// function: a function defined before the pragma is compiled with contracted multiply-adds and rounds
// differently from the C++ references (and from the same function in another include order).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

const fs::path kCl = fs::path(PMR_SOURCE_DIR) / "cl";

std::vector<std::string> kernel_headers() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kCl))
    if (e.path().extension() == ".h") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// The lines of `name` with every #include "x.h" of cl/ expanded in place, each header once (the
// include guards' effect), as the compiler reads them.
void expand(const std::string& name, std::set<std::string>& seen, std::vector<std::string>& out) {
  if (!seen.insert(name).second) return;
  std::ifstream in(kCl / name);
  const std::regex include(R"re(^#include "([a-z_]+\.h)")re");
  std::smatch m;
  for (std::string line; std::getline(in, line);) {
    if (std::regex_search(line, m, include) && fs::exists(kCl / m[1].str())) expand(m[1].str(), seen, out);
    else out.push_back(line);
  }
}

TEST(KernelHeaders, TheContractPragmaPrecedesEveryFunction) {
  const std::regex function(R"(^(inline|PMR_HOT|kernel) )");
  const auto headers = kernel_headers();
  ASSERT_GE(headers.size(), 20u);
  for (const std::string& h : headers) {
    std::set<std::string> seen;
    std::vector<std::string> lines;
    expand(h, seen, lines);
    bool pragma = false;
    for (const std::string& line : lines) {
      if (line.rfind("#pragma OPENCL FP_CONTRACT OFF", 0) == 0) pragma = true;
      if (std::regex_search(line, function)) {
        EXPECT_TRUE(pragma) << h << " defines a function before cl/common.h's pragma: " << line;
        break;
      }
    }
  }
}

TEST(KernelHeaders, EveryHeaderCompilesAlone) {
  const ClRuntime& rt = test::runtime();
  for (const std::string& h : kernel_headers()) {
    const std::map<std::string, std::string> alone = {
        {"header_alone.cl", "#include \"" + h + "\"\nkernel void header_alone(global int* x) { x[0] = 1; }\n"}};
    // the tile and vector sizes the pipeline passes (host/pipeline/pipeline.cpp); the filter's and the
    // sample count's defaults are the headers' own
    const std::string options = "-cl-std=CL1.2 -DPMR_TILE_X=16 -DPMR_TILE_Y=2 -DPMR_TILE_V=16 -DPMR_VW=16";
    EXPECT_NO_THROW(rt.build_program({"header_alone.cl"}, options, &alone)) << h;
  }
}

}  // namespace
}  // namespace pmr
