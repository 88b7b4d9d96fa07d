// `pmr quality`: how close --sampling subpixel, view and view --bilinear come to a finer reference
// (host/quality/sampling_quality.h).
#pragma once
#include <string>
#include <vector>

namespace pmr {

int run_quality(const std::vector<std::string>& args);
std::string quality_help();

}  // namespace pmr
