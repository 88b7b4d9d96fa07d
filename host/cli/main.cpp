// The `pmr` command line: turns every failure into one line on stderr and a non-zero exit status:
// 1 for bad input, a runtime error or running out of memory, 2 for a usage error, 3 for an internal
// error (a bug); a sequence stopped by signal N exits with 128 + N (sequence_job.cpp, interrupt.cpp).
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "cli/bench_command.h"
#include "cli/quality_command.h"
#include "cli/info_command.h"
#include "cli/options.h"
#include "cli/render_command.h"
#include "cli/verify_command.h"
#include "pmr/error.h"
#include "pmr/printable.h"
#include "pmr/version.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty() || args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
      std::fputs(pmr::main_help().c_str(), args.empty() ? stderr : stdout);
      return args.empty() ? 2 : 0;
    }
    if (args[0] == "--version" || args[0] == "version") {
      std::printf("pmr %s\n", pmr::program_version());
      return 0;
    }
    const std::string cmd = args[0];
    args.erase(args.begin());
    if (cmd == "render") return pmr::run_render(args);
    if (cmd == "bench") return pmr::run_bench(args);
    if (cmd == "quality") return pmr::run_quality(args);
    if (cmd == "info") return pmr::run_info(args);
    if (cmd == "verify") return pmr::run_verify(args);
    throw pmr::UsageError("unknown command '" + cmd + "' (try pmr --help)");
  } catch (const pmr::UsageError& e) {
    std::fprintf(stderr, "pmr: error: %s\n", pmr::terminal_text(e.what()).c_str());
    return 2;
  } catch (const pmr::Error& e) {
    // messages quote names from files: the last line of defence against escape sequences
    std::fprintf(stderr, "pmr: error: %s\n", pmr::terminal_text(e.what()).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "pmr: error: out of host memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmr: internal error: %s\n", pmr::terminal_text(e.what()).c_str());
    return 3;
  }
}
