// The exception types of the project: a message meant for the user, already complete.
// Library code throws them; only the CLI turns them into an exit status (cli/exit_status.h).
#pragma once
#include <stdexcept>
#include <string>

namespace pmr {

struct Error : std::runtime_error {
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A bug: a check of pmr's own invariants failed, whatever the input (exit status 3). The message says
// what broke; the type puts "internal error: " in front of it, once, so that users see a message to
// report rather than one about their input: throw InternalError("WideInt division by zero").
struct InternalError : Error {
  explicit InternalError(const std::string& message) : Error("internal error: " + message) {}
};

}  // namespace pmr

namespace pmr {

// A command line that cannot run as given (unknown option, bad option value, options that exclude each
// other): the CLI exits with status 2 for it, 1 for every other pmr::Error but an InternalError (3).
struct UsageError : Error {
  explicit UsageError(const std::string& message) : Error(message) {}
};

// Runs f(), reporting a pmr::Error it throws as a UsageError: for parsers that files share with the
// command line (parse_rational, parse_limits), whose refusal is a usage error when the text came from
// an option. A bug stays a bug (InternalError passes through).
template <class F>
auto as_usage(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const UsageError&) {
    throw;
  } catch (const InternalError&) {
    throw;
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
}

}  // namespace pmr
