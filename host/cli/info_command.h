// `pmr info`: the OpenCL devices, or with a scene file what the scene holds.
#pragma once
#include <string>
#include <vector>

namespace pmr {

int run_info(const std::vector<std::string>& args);

}  // namespace pmr
