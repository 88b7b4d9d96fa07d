// The one exception type of the project: a message meant for the user, already complete.
// Library code throws it; only the CLI turns it into an exit status.
#pragma once
#include <stdexcept>
#include <string>

namespace pmr {

struct Error : std::runtime_error {
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace pmr

namespace pmr {

// A command line that cannot run as given (unknown option, bad option value, options that exclude each
// other): the CLI exits with status 2 for it, 1 for everything else a pmr::Error reports.
struct UsageError : Error {
  explicit UsageError(const std::string& message) : Error(message) {}
};

// Runs f(), reporting a pmr::Error it throws as a UsageError: for parsers that files share with the
// command line (parse_rational, parse_limits), whose refusal is a usage error when the text came from
// an option.
template <class F>
auto as_usage(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
}

}  // namespace pmr
