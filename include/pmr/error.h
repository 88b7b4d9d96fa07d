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
