#include "cli/render_command.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "cli/options.h"
#include "sequence/sequence_job.h"
#include "pmr/error.h"

#ifndef PMR_DEFAULT_DATA_DIR
#define PMR_DEFAULT_DATA_DIR ""
#endif

namespace pmr {

namespace {

bool file_exists(const std::string& p) { return std::ifstream(p).good(); }

std::string exe_dir() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  std::string s(buf, size_t(n));
  return s.substr(0, s.rfind('/'));
}

// The job the options describe (the compression name checked here, before anything else).
SequenceJob sequence_job(const RenderOptions& o) {
  SequenceJob job = o.job;
  job.compression = as_usage([&] { return parse_exr_compression(o.compression); });
  if (is_lossy(job.compression) && job.products.encoded)
    throw UsageError(std::string("--compression ") + to_string(job.compression) +
                     " is lossy and the encoded image interleaves views subpixel by subpixel (its ringing would "
                     "be crosstalk on the panel): write it with --write views or quilt, or choose a lossless "
                     "compression");
  return job;
}

// Test-only: the tests cannot reach a real InternalError through valid input (that is the point of one),
// so PMR_TEST_FORCE_INTERNAL_ERROR=<stage> makes the named stage throw one, to check the exit status,
// the message and that nothing was written. The one stage so far is "render-options": the render
// command once its options are parsed and checked, before the scene is read or any file is created.
void test_hook_force_internal_error(const char* stage) {
  const char* forced = std::getenv("PMR_TEST_FORCE_INTERNAL_ERROR");
  if (forced && std::string(forced) == stage)
    throw InternalError(std::string("forced at stage ") + stage + " (PMR_TEST_FORCE_INTERNAL_ERROR, a test hook)");
}

}  // namespace

std::string default_scene_path() {
  std::vector<std::string> candidates;
  if (const char* d = std::getenv("PMR_DATA_DIR")) candidates.push_back(std::string(d) + "/default_scene.glb");
  candidates.push_back(exe_dir() + "/data/default_scene.glb");
  candidates.push_back(exe_dir() + "/../data/default_scene.glb");
  candidates.push_back(std::string(PMR_DEFAULT_DATA_DIR) + "/default_scene.glb");
  for (const auto& c : candidates)
    if (file_exists(c)) return c;
  throw Error("the default scene data/default_scene.glb was not found (set PMR_DATA_DIR or give a scene file)");
}

int run_render(const std::vector<std::string>& args) {
  RenderOptions o = parse_render_options(args);
  if (o.help) {
    std::fputs(render_help().c_str(), stdout);
    return 0;
  }
  if (o.preset_help) {
    std::fputs(display_presets_help().c_str(), stdout);
    return 0;
  }
  finalize_render_options(o);
  test_hook_force_internal_error("render-options");
  if (o.job.scene.empty()) o.job.scene = default_scene_path();
  return run_sequence(sequence_job(o));
}

}  // namespace pmr
