// The sequence job: load, frame, skip what --resume finds complete, then render frame after frame while
// the writer thread compresses and writes the previous one; progress, clean interruption, a summary.
#include "sequence/sequence_job.h"

#include <csignal>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "output/checksum.h"
#include "output/interrupt.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/quilt.h"
#include "runtime/cl_runtime.h"
#include "sequence/folder_guard.h"
#include "sequence/frame_files.h"
#include "sequence/frame_list.h"
#include "sequence/frame_renderer.h"
#include "sequence/frame_writer.h"
#include "sequence/progress.h"
#include "sequence/range_warning.h"
#include "sequence/resume_plan.h"
#include "sequence/shard.h"
#include "shading/environment.h"

namespace pmr {

namespace {

namespace fs = std::filesystem;

std::string base_name(const std::string& path) { return fs::path(path).filename().string(); }

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int run_sequence(const RenderOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  // options given as text, checked here: a bad one is a usage error (exit 2)
  const ExrCompression compression = as_usage([&] { return parse_exr_compression(o.compression); });
  std::vector<long> frames;
  if (o.frames != "all") frames = as_usage([&] { return parse_frame_list(o.frames); });  // before the long work: fail early
  as_usage([&] { check_name_covers_frames(o.name, frames.size()); });
  // Everything that can be checked cheaply is checked before the long work starts; the output folder is
  // created only once every input has been read and checked (below).
  check_output_dir(o.out_dir);
  make_encode_params(o.display, o.rig.views, o.rig.view_w, o.rig.view_h);

  for (const auto& w : o.option_warnings) std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());
  // The environment image, prefiltered once for every frame (before the scene: a bad file fails fast).
  std::shared_ptr<const Environment> environment;
  std::string environment_checksum;
  if (!o.environment_file.empty()) {
    environment = std::make_shared<const Environment>(Environment::make(
        {o.environment_file, o.environment_rotation_deg, o.pipeline.environment_intensity}));
    environment_checksum = checksum_file(o.environment_file);
    if (o.verbose) {
      const PmrEnvironment& h = environment->tables().header;
      std::fprintf(stderr, "pmr: environment %s: %ux%u, prefiltered in %.2f s (%.1f MB of tables)\n",
                   o.environment_file.c_str(), h.levels[0].width, h.levels[0].height, environment->prefilter_seconds(),
                   double(environment->tables().data.size() * sizeof(float)) / 1e6);
    }
  }
  // the pipeline's configuration: the sidecars a resumed run expects need it too (which lights)
  PipelineConfig pc = o.pipeline;
  pc.environment = environment;
  const Scene scene = load_scene(o.scene, o.input_limits);
  for (const auto& w : scene.warnings) std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());
  SequenceSpec spec;
  select_animation(scene, o.animation, spec);
  spec.fps = o.fps;
  spec.turntable = o.turntable;
  spec.turntable_deg = o.turntable_deg;
  spec.turntable_frames = o.turntable ? o.turntable_frames : 1;
  if (o.frames == "all") {
    long first = 0, last = 0;
    animation_frame_range(scene, spec, first, last);
    if (last - first >= 10000000) throw Error("--frames all would be " + std::to_string(last - first + 1) + " frames; give a range");
    if (last > kMaxFrame)
      throw Error("--frames all would reach frame " + std::to_string(last) + ", beyond " + std::to_string(kMaxFrame));
    for (long f = first; f <= last; ++f) frames.push_back(f);
    as_usage([&] { check_name_covers_frames(o.name, frames.size()); });
  }
  std::vector<long> job_frames;  // every shard's frames (the folder guard's "this job")
  if (!o.shard.empty()) {
    job_frames = frames;
    const Shard shard = parse_shard(o.shard, o.shard_count, o.shard_first, [](const char* n) { return std::getenv(n); });
    const size_t all = frames.size();
    frames = shard_frames(frames, shard);
    if (!o.quiet)
      std::fprintf(stderr, "pmr: %s: shard %ld of %ld, %zu of %zu frame(s)\n", shard.source.c_str(), shard.index,
                   shard.count, frames.size(), all);
  }
  std::vector<std::string> warnings;
  FrameRenderer renderer(scene, spec, o.rig, o.display, &warnings);
  for (const auto& w : warnings) std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());
  if (const std::string w = frames_outside_animation(scene, spec, frames, o.frames == "all"); !w.empty())
    std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());
  const Rig& rig = renderer.rig();
  const bool need_volume = o.write_views || o.write_quilt || o.preview;
  QuiltLayout quilt;
  if (o.write_quilt)
    quilt = o.quilt.empty() ? choose_quilt_layout(rig.views, rig.view_w, rig.view_h)
                            : as_usage([&] { return parse_quilt_layout(o.quilt, rig.views, rig.view_w, rig.view_h); });
  else if (!o.quilt.empty())
    throw UsageError("--quilt needs --write quilt");
  const int center_view = rig.views / 2;
  auto paths = [&](long f) { return frame_paths(o, f, quilt, rig.aspect); };
  check_frame_file_names(o, frames, quilt, rig.aspect);  // not after the first frame was rendered

  SidecarInfo info;
  info.scene = o.scene;
  info.tile_x = o.pipeline.tile_x;
  info.tile_y = o.pipeline.tile_y;
  info.tile_v = o.pipeline.tile_v;
  info.method = to_string(o.pipeline.method);
  info.sampling = to_string(o.pipeline.sampling);
  info.shading = to_string(o.pipeline.shading);
  info.exposure_ev = o.pipeline.exposure_ev;
  info.environment_intensity = o.pipeline.environment_intensity;
  info.environment_file = o.environment_file;
  info.environment_checksum = environment_checksum;
  info.environment_rotation_deg = o.environment_rotation_deg;
  info.camera = o.rig.camera;
  info.has_bounds = true;
  info.bounds_lo = renderer.bounds_lo();
  info.bounds_hi = renderer.bounds_hi();
  info.compression = to_string(compression);
  info.warnings = scene.warnings;
  info.warnings.insert(info.warnings.end(), warnings.begin(), warnings.end());
  info.fps = spec.fps;
  info.animation = spec.animation;
  info.animation_name = spec.animation_label;
  info.turntable = spec.turntable;
  info.turntable_deg = spec.turntable_deg;
  info.turntable_frames = spec.turntable ? spec.turntable_frames : 0;
  info.pivot = renderer.pivot();
  info.display_source = o.display_source;
  info.scene_checksum = scene.source_checksum;
  for (const SceneInputFile& f : scene.input_files) info.scene_files.push_back({f.path, f.checksum});
  info.allow_outside_scene_folder = o.input_limits.allow_outside_scene_folder;
  if (o.has_calibration) {
    const LookingGlassCalibration& c = o.calibration;
    info.display_config_checksum = c.checksum;
    info.calibration_serial = c.serial;
    info.calibration = {{"pitch", c.pitch},         {"slope", c.slope},       {"center", c.center},
                        {"DPI", c.dpi},             {"screenW", c.screen_w},  {"screenH", c.screen_h},
                        {"viewCone", c.view_cone},  {"fringe", c.fringe},     {"flipImageX", c.flip_x},
                        {"flipImageY", c.flip_y},   {"flipSubp", c.flip_subp}, {"invView", c.inv_view},
                        {"CellPatternMode", c.cell_pattern}, {"subpixelCells", double(c.cells.size())}};
  }
  auto frame_info = [&](long frame, const FramePaths& p, double angle, std::vector<SceneLight> lights) {
    SidecarInfo i = info;
    i.frame = int(frame);
    i.time = double(frame) / spec.fps;
    i.turntable_angle = angle;
    i.lights = std::move(lights);
    const std::pair<const char*, const std::string*> kinds[] = {
        {"encoded", &p.encoded}, {"views", &p.views}, {"quilt", &p.quilt}, {"preview_encoded", &p.encoded_png},
        {"preview_center", &p.center_png}, {"preview_quilt", &p.quilt_png}};
    for (const auto& [kind, path] : kinds)
      if (!path->empty()) i.outputs.push_back({kind, base_name(*path)});
    if (o.write_quilt) i.quilt_columns = quilt.columns, i.quilt_rows = quilt.rows;
    if (o.preview) i.center_view = center_view;
    i.depth = o.write_depth;
    return i;
  };

  prepare_output_dir(o.out_dir);
  // One folder, one configuration: no other configuration rendering into it now, none left beside
  // this run's frames (folder_guard.h). Held until the end of the run.
  const FolderGuard folder_guard(o.out_dir, o.name, o.shard.empty() ? frames : job_frames,
                                 sidecar_json(rig, o.display, frame_info(0, paths(0), 0.0, renderer.frame_lights(0, pc))),
                                 o.overwrite, o.quiet);

  const ResumePlan plan = plan_resume(frames, o.resume, o.overwrite, paths, [&](long f, const FramePaths& p) {
    return sidecar_json(rig, o.display, frame_info(f, p, 0.0, renderer.frame_lights(f, pc)));
  });
  // --quiet: errors and warnings only
  if (!o.quiet)
    for (const std::string& note : plan.notes) std::fprintf(stderr, "pmr: %s\n", note.c_str());
  const std::vector<long>& todo = plan.todo;
  const long skipped = plan.kept;
  const long total = long(todo.size());
  if (!o.quiet)
    std::fprintf(stderr, "pmr: %s: %zu triangles, %d views of %dx%d -> %dx%d display%s; %ld frame(s)%s\n",
                 o.scene.c_str(), scene.triangles.size(), rig.views, rig.view_w, rig.view_h, o.display.width,
                 o.display.height, o.pipeline.sampling == Sampling::Subpixel ? " (subpixel sampling)" : "", total,
                 skipped ? (", " + std::to_string(skipped) + " already complete").c_str() : "");
  if (todo.empty()) {
    if (!o.quiet) std::fprintf(stderr, "pmr: nothing to do\n");
    return 0;
  }

  ClRuntime runtime;
  pc.fuse_encode = !need_volume;  // the volume is only kept when a product needs it
  pc.debug_outputs = o.write_depth;  // per-voxel depth
  Pipeline pipeline(runtime, pc);
  renderer.attach(pipeline, o.write_encoded ? &o.display : nullptr);  // builds every kernel the frames use
  if (o.verbose) {
    std::string variants;
    for (const std::string& v : pipeline.kernel_variants()) variants += (variants.empty() ? "" : ", ") + v;
    std::fprintf(stderr, "pmr: device %s; kernels built in %.2f s (%zu work-group functions: %s)\n",
                 runtime.device_name().c_str(), pipeline.kernel_build_seconds(), pipeline.kernel_variants().size(),
                 variants.c_str());
  }

  install_interrupt_handlers();
  FrameWriter writer(2);
  Progress progress(total, o.quiet);
  double render_s = 0.0, pose_s = 0.0, upload_s = 0.0;
  long rendered = 0;
  const auto t_loop = std::chrono::steady_clock::now();
  for (long f : todo) {
    if (interrupt_signal()) break;
    const FramePaths p = paths(f);
    const FrameRenderer::Frame fr = renderer.render(f);
    if (interrupt_signal()) break;  // the frame in flight is abandoned
    render_s += fr.times.wall / 1000.0;
    pose_s += fr.pose_ms / 1000.0;
    upload_s += fr.upload_ms / 1000.0;
    if (!fr.visible) progress.message("pmr: warning: frame " + std::to_string(f) + ": nothing visible, written as a transparent image");
    if (o.verbose) {
      // the fused path and --sampling subpixel write the display image from the fine raster's tiles
      const bool subpixel = pc.sampling == Sampling::Subpixel, tiled_encode = pipeline.fused() || subpixel;
      const char* encode_label = subpixel ? " + subpixel samples" : " + encode (fused)";
      char line[320];
      std::snprintf(line, sizeof line,
                    "pmr: frame %ld: pose %.2f ms, upload %.2f ms; stage times (ms): vertex %.2f, setup %.2f, tile raster %.2f, "
                    "fine raster%s %.2f, %s %.2f; %u MTAs, %llu tile-queue entries, %d queue regrowth(s)",
                    f, fr.pose_ms, fr.upload_ms, fr.times.vertex, fr.times.setup, fr.times.bin, tiled_encode ? encode_label : "",
                    fr.times.fine, tiled_encode ? "straddling alpha" : "encode", fr.times.encode, fr.times.mtas,
                    (unsigned long long)fr.times.bin_entries, fr.times.retries);
      progress.message(line);
    }
    FrameFiles files;
    files.frame = f;
    files.compression = compression;
    files.sidecar_path = p.sidecar;
    files.sidecar_text = sidecar_json(fr.rig, o.display, frame_info(f, p, fr.angle, fr.lights));
    files.has_meta = true;  // the EXR header attributes (docs/OUTPUTS.md)
    files.meta.frame = f, files.meta.time = double(f) / spec.fps, files.meta.fps = spec.fps;
    files.meta.sidecar = base_name(p.sidecar), files.meta.rig = fr.rig;
    files.meta.center_view = center_view, files.meta.quilt = quilt;
    if (o.write_encoded) {
      files.encoded_path = p.encoded;
      files.display_w = o.display.width, files.display_h = o.display.height;
      files.display = writer.spare_buffer();
      if (renderer.has_geometry()) pipeline.read_display(files.display);
      else files.display.assign(size_t(o.display.width) * o.display.height * 4, 0);
    }
    files.encoded_png = p.encoded_png;
    if (need_volume) {
      files.views_path = p.views;
      files.quilt_path = p.quilt;
      files.quilt_png = p.quilt_png;
      files.center_png = p.center_png;
      files.quilt = quilt;
      files.center_view = center_view;
      files.view_w = rig.view_w, files.view_h = rig.view_h, files.views = rig.views;
      // pixels of a view are non-square: the view spans the display's aspect A
      files.pixel_aspect = float(rig.aspect * rig.view_h / rig.view_w);
      files.volume = writer.spare_buffer();
      if (renderer.has_geometry()) pipeline.read_volume(files.volume);
      else files.volume.assign(size_t(rig.views) * rig.view_w * rig.view_h * 4, 0);
      if (o.write_depth) {
        files.near = fr.rig.near_eff, files.far = fr.rig.far;
        std::vector<uint32_t> keys, count;
        if (renderer.has_geometry()) pipeline.read_debug(keys, files.depth, count);
        else files.depth.assign(size_t(rig.views) * rig.view_w * rig.view_h, std::numeric_limits<float>::infinity());
      }
    }
    writer.submit(std::move(files));
    ++rendered;
    progress.frame_done(rendered, f, fr.times.wall);
  }
  try {
    writer.finish();
  } catch (...) {
    progress.close();
    throw;
  }
  progress.close();
  const long written = writer.frames_written();
  if (const int sig = interrupt_signal(); sig && written < total) {
    std::fprintf(stderr, "pmr: interrupted by %s: %ld of %ld frame(s) written (%ld already complete); nothing partial "
                 "was left: rerun with --resume to finish\n",
                 sig == SIGTERM ? "SIGTERM" : "SIGINT", written, total, skipped);
    return 128 + sig;
  }
  const double wall = seconds_since(t_loop);
  const double n = double(std::max(1L, rendered));
  if (!o.quiet)
    std::fprintf(stderr,
                 "pmr: %ld frame(s) in %.2f s (%.2f s/frame; %ld skipped): render %.0f ms/frame (+ pose %.1f, upload %.1f), write %.0f "
                 "ms/frame on the writer thread (%s, %.1f MB/frame); total %.2f s\n",
                 rendered, wall, wall / n, skipped, 1000.0 * render_s / n, 1000.0 * pose_s / n, 1000.0 * upload_s / n,
                 1000.0 * writer.write_seconds() / n, to_string(compression), double(writer.bytes_written()) / n / 1e6,
                 seconds_since(t0));
  if (!o.quiet && rendered == 1)
    for (const std::string& path : paths(todo[0]).images()) std::fprintf(stderr, "pmr: wrote %s\n", path.c_str());
  if (!o.quiet && rendered == 1) std::fprintf(stderr, "pmr: wrote %s\n", paths(todo[0]).sidecar.c_str());
  return 0;
}

}  // namespace pmr
