// How the `pmr` command line ends: every failure becomes one line on stderr and an exit status.
//   0 success; 1 bad input, a runtime error or running out of memory; 2 a usage error (pmr::UsageError);
//   3 an internal error, a bug: pmr::InternalError (an invariant of pmr's own failed) or any exception that
//   is not a pmr::Error. A sequence stopped by signal N exits with 128 + N (sequence_job.cpp, interrupt.cpp).
#pragma once
#include <functional>

namespace pmr {

// Runs `command` and returns its status, or the status of the exception it throws, after printing the
// exception's message (sanitized for the terminal: messages quote names from files) to stderr.
int run_reporting_errors(const std::function<int()>& command);

}  // namespace pmr
