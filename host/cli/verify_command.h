// `pmr verify DIR --frames LIST`: what a render farm wrangler runs after an array job.
#pragma once
#include <string>
#include <vector>

namespace pmr {

int run_verify(const std::vector<std::string>& args);

}  // namespace pmr
