// The `pmr` command line: dispatches to the commands; cli/exit_status.h turns every failure into one
// line on stderr and the documented exit status.
#include <cstdio>
#include <string>
#include <vector>

#include "cli/bench_command.h"
#include "cli/exit_status.h"
#include "cli/info_command.h"
#include "cli/options.h"
#include "cli/quality_command.h"
#include "cli/render_command.h"
#include "cli/verify_command.h"
#include "output/interrupt.h"
#include "pmr/error.h"
#include "pmr/version.h"

int main(int argc, char** argv) {
  pmr::ignore_write_signals();
  std::vector<std::string> args(argv + 1, argv + argc);
  return pmr::run_reporting_errors([&]() -> int {
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
  });
}
