// `pmr bench`: performance sweeps over view count, per method, with a CSV of per-stage times.
#pragma once
#include <string>
#include <vector>

namespace pmr {

int run_bench(const std::vector<std::string>& args);

}  // namespace pmr
