#include "cli/quality_command.h"

#include <cstdio>

#include "cli/options.h"
#include "cli/render_command.h"
#include "pmr/error.h"
#include "pmr/scene.h"
#include "quality/samples_quality.h"
#include "quality/sampling_quality.h"
#include "runtime/cl_runtime.h"

namespace pmr {

std::string quality_help() {
  return "usage: pmr quality [SCENE] [--scale K] [--also-view-size WxH ...] [render options]\n"
         "Renders frame 0 of SCENE (default: the bundled scene) with --sampling subpixel, --sampling view and\n"
         "--sampling view --bilinear, and compares each encoded image with a reference: --sampling view\n"
         "with views K times wider and taller (default 4), nearest sampling. Per sampling it prints the\n"
         "RMSE over every subpixel's colour (linear) and the fraction of subpixels differing by more than\n"
         "1/256. --also-view-size adds --sampling view at another view size (repeatable).\n"
         "The rig and display options are those of pmr render (--preset, --views, --view-size, ...);\n"
         "the cameras are spaced as render spaces them (a Looking Glass preset: angularly); the sampling\n"
         "options (--sampling, --bilinear, --blend-views) are set by\n"
         "the command itself, and nothing is written. See docs/SAMPLING.md.\n"
         "\n"
         "pmr quality [SCENE] --samples LIST [render options]\n"
         "Renders the views of frame 0 with each samples-per-pixel count of LIST (1, 4, 8, 16) and compares\n"
         "them with a reference: the views twice as wide and tall with 16 samples, box-filtered 2x2 (64\n"
         "samples per pixel). Per count it prints the RMSE over premultiplied RGBA (colour clamped to [0, 1])\n"
         "and over edge pixels (reference alpha strictly between 0 and 1, or a 3x3 neighbourhood varying by\n"
         "more than 0.1), each also as a ratio to the first count's. --shading and the rig options apply\n"
         "(use e.g. --views 8). See docs/ANTIALIASING.md.\n";
}

namespace {

int run_samples_quality(const std::vector<int>& samples, const std::vector<std::string>& rest) {
  RenderOptions o = parse_render_options(rest);
  finalize_render_options(o);
  if (o.job.pipeline.shading == Shading::Pbr)
    o.job.pipeline.environment =
        make_pipeline_environment({o.job.environment, o.job.environment_rotation_deg,
                                   o.job.pipeline.environment_intensity, o.job.pipeline.shadows});
  if (o.job.scene.empty()) o.job.scene = default_scene_path();
  const Scene scene = load_scene(o.job.scene);
  ClRuntime rt;
  const std::vector<SamplesQualityRow> rows =
      samples_quality(rt, scene, o.job.rig, o.job.display, o.job.pipeline, samples);
  std::printf("# %s: %zu triangles; %d views of %dx%d; %s; reference 64 samples per pixel; device %s\n",
              o.job.scene.c_str(), scene.triangles.size(), o.job.rig.views, o.job.rig.view_w, o.job.rig.view_h,
              to_string(o.job.pipeline.shading), rt.device_name().c_str());
  std::printf("%8s %10s %10s %10s %10s %10s %10s\n", "samples", "render_ms", "rmse", "edge_rmse", "rmse_x", "edge_x",
              "edges");
  for (const SamplesQualityRow& r : rows)
    std::printf("%8d %10.1f %10.5f %10.5f %10.3f %10.3f %9.2f%%\n", r.samples, r.render_ms, r.error.rmse,
                r.error.edge_rmse, r.error.rmse / rows[0].error.rmse, r.error.edge_rmse / rows[0].error.edge_rmse,
                100.0 * r.error.edge_fraction);
  return 0;
}

}  // namespace

int run_quality(const std::vector<std::string>& args) {
  int scale = 4;
  std::vector<std::pair<int, int>> extra;
  std::vector<std::string> rest;
  std::vector<int> samples;
  for (size_t i = 0; i < args.size(); ++i) {  // usage errors (exit 2) but for --display-config's file
    if (args[i] == "-h" || args[i] == "--help") {
      std::fputs(quality_help().c_str(), stdout);
      return 0;
    }
    if (args[i] == "--scale") {
      if (i + 1 >= args.size()) throw UsageError("option --scale needs a value (see pmr quality --help)");
      const std::string v = args[++i];
      char* end = nullptr;
      const long k = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || k < 2 || k > 16) throw UsageError("invalid --scale '" + v + "': expected 2..16");
      scale = int(k);
      continue;
    }
    if (args[i] == "--also-view-size") {  // checked as --view-size is
      if (i + 1 >= args.size()) throw UsageError("option --also-view-size needs a value (see pmr quality --help)");
      const RenderOptions r = parse_render_options({"--view-size", args[++i]});
      extra.push_back({r.job.rig.view_w, r.job.rig.view_h});
      continue;
    }
    if (args[i] == "--samples") {
      if (i + 1 >= args.size()) throw UsageError("option --samples needs a value (see pmr quality --help)");
      samples = parse_samples_list(args[++i]);
      continue;
    }
    rest.push_back(args[i]);
  }
  if (!samples.empty()) return run_samples_quality(samples, rest);
  RenderOptions o = parse_render_options(rest);
  finalize_render_options(o);
  if (o.job.scene.empty()) o.job.scene = default_scene_path();
  const Scene scene = load_scene(o.job.scene);
  ClRuntime rt;
  const std::vector<SamplingQualityRow> rows = sampling_quality(rt, scene, o.job.rig, o.job.display, scale, extra);
  std::printf("# %s: %zu triangles; %d views; display %dx%d; device %s\n", o.job.scene.c_str(), scene.triangles.size(),
              o.job.rig.views, o.job.display.width, o.job.display.height, rt.device_name().c_str());
  std::printf("%-16s %10s %10s %10s %10s %10s %10s\n", "sampling", "view", "Msamples", "render_ms", "rmse",
              "rmse_shown", "differing");
  for (const SamplingQualityRow& r : rows) {
    char view[32];
    std::snprintf(view, sizeof view, "%dx%d", r.view_w, r.view_h);
    if (r.name == "reference")
      std::printf("%-16s %10s %10.2f %10.1f %10s %10s %10s\n", r.name.c_str(), view, r.samples * 1e-6, r.render_ms, "-",
                  "-", "-");
    else
      std::printf("%-16s %10s %10.2f %10.1f %10.5f %10.5f %9.3f%%\n", r.name.c_str(), view, r.samples * 1e-6,
                  r.render_ms, r.error.rmse, r.error.rmse_shown, 100.0 * r.error.differing);
  }
  return 0;
}

}  // namespace pmr
