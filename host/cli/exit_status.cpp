#include "cli/exit_status.h"

#include <cstdio>
#include <exception>
#include <new>

#include "pmr/error.h"
#include "pmr/printable.h"

namespace pmr {

int run_reporting_errors(const std::function<int()>& command) {
  try {
    return command();
  } catch (const InternalError& e) {  // its message starts with "internal error: "
    std::fprintf(stderr, "pmr: %s\n", terminal_text(e.what()).c_str());
    return 3;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "pmr: error: %s\n", terminal_text(e.what()).c_str());
    return 2;
  } catch (const Error& e) {
    std::fprintf(stderr, "pmr: error: %s\n", terminal_text(e.what()).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "pmr: error: out of host memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmr: internal error: %s\n", terminal_text(e.what()).c_str());
    return 3;
  } catch (...) {
    std::fprintf(stderr, "pmr: internal error: an unknown exception\n");
    return 3;
  }
}

}  // namespace pmr
