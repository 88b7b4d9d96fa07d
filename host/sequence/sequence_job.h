// `pmr render`: a sequence of frames (one frame is a sequence of one) from loading to the summary.
#pragma once
#include "cli/options.h"

namespace pmr {

// Runs the job; returns the process exit code (0, or 128 + signal when interrupted). Throws pmr::Error
// with one line on bad input or a failed write.
int run_sequence(const RenderOptions& options);

}  // namespace pmr
