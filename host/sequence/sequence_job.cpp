// The sequence job: load, frame, skip what --resume finds complete, then render frame after frame while
// the writer thread compresses and writes the previous one; progress, clean interruption, a summary.
#include "sequence/sequence_job.h"

#include <time.h>

#include <csignal>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "output/backdrop.h"
#include "output/checksum.h"
#include "output/interrupt.h"
#include "pipeline/transmission_stage.h"
#include "pmr/error.h"
#include "pmr/memory_budget.h"
#include "pmr/output.h"
#include "pmr/quilt.h"
#include "runtime/cl_runtime.h"
#include "sequence/folder_guard.h"
#include "sequence/frame_files.h"
#include "sequence/frame_list.h"
#include "sequence/frame_names.h"
#include "sequence/frame_renderer.h"
#include "sequence/frame_writer.h"
#include "sequence/progress.h"
#include "sequence/range_warning.h"
#include "sequence/resume_plan.h"
#include "sequence/shard.h"
#include "pmr/printable.h"
#include "shading/environment.h"

namespace pmr {

namespace {

namespace fs = std::filesystem;

std::string base_name(const std::string& path) { return fs::path(path).filename().string(); }

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Warnings name the scene's file, which is a stranger's name on a farm: made safe for the terminal.
void warn(const std::string& w) { std::fprintf(stderr, "pmr: warning: %s\n", terminal_text(w).c_str()); }

// One run of a job, step by step (run()).
class SequenceRun {
 public:
  explicit SequenceRun(const SequenceJob& job) : job_(job), products_(job.products) {}
  int run();
  int guarded_run();  // run() once the output folder exists

 private:
  void check_before_loading();
  void load_inputs();
  std::shared_ptr<const Environment> make_backdrop_environment() const;
  void choose_frames();
  void check_frame_memory() const;
  void adopt_folder_names();
  void prepare_frames();
  SidecarInfo frame_info(long frame, const FramePaths& p, double angle, std::vector<SceneLight> lights) const;
  std::string expected_sidecar(long frame, const FramePaths& p) const {
    const FrameDescription d = renderer_->describe(frame, pc_);
    return sidecar_json(d.rig, job_.display, frame_info(frame, p, 0.0, d.lights));
  }
  FramePaths paths(long f) const { return frame_paths(products_, f, quilt_, renderer_->rig().aspect); }
  void print_header() const;
  int print_outputs() const;
  int render_frames();
  void finish_writing(FrameWriter& writer, Progress& progress);
  FrameFiles frame_files(long f, const FrameRenderer::Frame& fr, Pipeline& pipeline, FrameWriter& writer) const;
  std::shared_ptr<const BackdropLayers> backdrop_layers(const Rig& rig, Pipeline& pipeline) const;
  void shown_display(FrameFiles& files, Pipeline& pipeline) const;
  void print_frame_stages(long f, const FrameRenderer::Frame& fr, const Pipeline& pipeline, Progress& progress) const;
  void print_summary(const FrameWriter& writer) const;

  const SequenceJob& job_;
  FrameProducts products_;  // the job's, with the names the folder's frames have (adopt_folder_names)
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  PipelineConfig pc_;  // the job's, with the environment: the sidecars a resumed run expects need it too
  std::string environment_checksum_;
  Scene scene_;
  SequenceSpec spec_;
  std::vector<long> frames_;      // this shard's frames, in job order
  std::vector<long> job_frames_;  // every shard's frames (the folder guard's "this job"); empty: no shards
  RigConfig rig_config_;          // the job's, its --camera resolved against the scene
  std::unique_ptr<FrameRenderer> renderer_;
  std::vector<std::string> rig_warnings_;
  QuiltLayout quilt_;
  int center_view_ = 0;
  bool need_volume_ = false;
  bool near_warned_ = false;                             // the raised near plane's warning was given
  std::unique_ptr<const ViewTransform> view_transform_;  // the previews' (null: none written)
  // --background environment: the environment it shows, and the last rig's backdrop
  std::shared_ptr<const Environment> backdrop_environment_;
  mutable Rig backdrop_rig_;
  mutable std::shared_ptr<const BackdropLayers> backdrop_;
  mutable bool backdrop_warned_ = false;
  SidecarInfo info_;                                     // what every frame's sidecar shares
  ResumePlan plan_;
  // the summary's sums
  double render_s_ = 0.0, pose_s_ = 0.0, upload_s_ = 0.0, loop_s_ = 0.0, loop_cpu_s_ = 0.0;
  long rendered_ = 0;
  Progress* progress_ = nullptr;  // while frames render: for the slow-frame notice
  long frame_in_flight_ = 0;
};

// Everything that can be checked cheaply, before the long work starts.
void SequenceRun::check_before_loading() {
  set_memory_budget(job_.input_limits.memory);
  // options given as text, checked here: a bad one is a usage error (exit 2)
  if (job_.frames != "all") frames_ = as_usage([&] { return parse_frame_list(job_.frames); });
  as_usage([&] { check_name_covers_frames(products_.name, frames_.size()); });
  // the output folder is created only once every input has been read and checked (run())
  check_output_dir(products_.out_dir);
  make_encode_params(job_.display, job_.rig.views, job_.rig.view_w, job_.rig.view_h);
  if (!job_.quilt_layout.empty() && !products_.quilt) throw UsageError("--quilt needs --write quilt");
  if (products_.preview || job_.view_transform_given) {  // a bad config or name fails before the scene is read
    view_transform_ = std::make_unique<const ViewTransform>(make_view_transform(job_.view_transform));
    if (!products_.preview) warn("the view transform applies to the PNG previews, which need --preview: ignored");
  }
  for (const auto& w : job_.warnings) warn(w);
}

// The environment image, prefiltered once for every frame (before the scene: a bad file fails fast),
// then the scene.
void SequenceRun::load_inputs() {
  pc_ = job_.pipeline;
  pc_.tile_queue_limit = job_.input_limits.tile_queue;
  // A frame still rendering after a few seconds says so (Pipeline::render calls this while waiting).
  if (!job_.quiet)
    pc_.slow_frame = [this](double seconds, uint64_t entries) {
      if (progress_)
        progress_->message("pmr: frame " + std::to_string(frame_in_flight_) + ": rendering, " +
                           std::to_string(long(seconds)) + " s so far (" + std::to_string(entries) +
                           " tile-queue entries)");
    };
  if (job_.pipeline.shading == Shading::Pbr) {
    const EnvironmentSource& source = job_.environment;
    pc_.environment = make_pipeline_environment(
        {source, job_.environment_rotation_deg, job_.pipeline.environment_intensity, job_.pipeline.shadows});
    if (source.kind == EnvironmentSource::Kind::File) environment_checksum_ = checksum_file(source.file);
    if (job_.verbose)
      std::fprintf(stderr, "pmr: environment %s\n", environment_summary(source, pc_.environment.get()).c_str());
  }
  if (job_.background.environment) backdrop_environment_ = make_backdrop_environment();
  scene_ = load_scene(job_.scene, job_.input_limits, job_.variant);
  for (const auto& w : scene_.warnings) warn(w);
}

// --background environment shows the whole environment: the pipeline's when it has nothing taken out as
// lights (shadows off), else made again without taking them out.
std::shared_ptr<const Environment> SequenceRun::make_backdrop_environment() const {
  if (pc_.environment && !job_.pipeline.shadows) return pc_.environment;
  EnvironmentOptions o{job_.environment, job_.environment_rotation_deg, job_.pipeline.environment_intensity, false};
  return std::make_shared<const Environment>(Environment::make(o));
}

// The animation, --frames all, this shard's part; then the framing (FrameRenderer) and the layout.
void SequenceRun::choose_frames() {
  spec_ = resolve_sequence(scene_, job_.sequence, job_.input_limits);
  if (job_.frames == "all") {
    long first = 0, last = 0;
    animation_frame_range(scene_, spec_, first, last);
    if (last - first >= kMaxFramesPerRun)
      throw Error("--frames all would be " + std::to_string(last - first + 1) + " frames; give a range");
    if (last > kMaxFrame)
      throw Error("--frames all would reach frame " + std::to_string(last) + ", beyond " + std::to_string(kMaxFrame));
    for (long f = first; f <= last; ++f) frames_.push_back(f);
    as_usage([&] { check_name_covers_frames(products_.name, frames_.size()); });
  }
  if (!job_.shard.empty()) {
    job_frames_ = frames_;
    const Shard shard =
        parse_shard(job_.shard, job_.shard_count, job_.shard_first, [](const char* n) { return std::getenv(n); });
    const size_t all = frames_.size();
    frames_ = shard_frames(frames_, shard);
    if (!job_.quiet)
      std::fprintf(stderr, "pmr: %s: shard %ld of %ld, %zu of %zu frame(s)\n", shard.source.c_str(), shard.index,
                   shard.count, frames_.size(), all);
  }
  rig_config_ = job_.rig;
  if (!job_.camera.empty()) rig_config_.camera = find_camera(scene_, job_.camera);
  renderer_ = std::make_unique<FrameRenderer>(scene_, spec_, rig_config_, job_.display, &rig_warnings_);
  for (const auto& w : rig_warnings_) warn(w);
  if (const std::string w = frames_outside_animation(scene_, spec_, frames_, job_.frames == "all"); !w.empty()) warn(w);
  if (job_.background.environment && products_.encoded && !renderer_->has_geometry())
    throw Error("--background environment encodes its backdrop with the renderer's encoder, which a scene "
                "without triangles does not start: write the views or the quilt (--write)");
  const Rig& rig = renderer_->rig();
  need_volume_ = products_.views || products_.quilt || products_.preview;
  if (products_.quilt)
    quilt_ = job_.quilt_layout.empty()
                 ? choose_quilt_layout(rig.views, rig.view_w, rig.view_h)
                 : as_usage([&] { return parse_quilt_layout(job_.quilt_layout, rig.views, rig.view_w, rig.view_h); });
  center_view_ = rig.views / 2;
  adopt_folder_names();
  check_frame_file_names(products_, frames_, quilt_, rig.aspect);  // not after the first frame was rendered
  check_frame_memory();
}

// A frame re-rendered into a folder keeps the names its frames have: the command line alone cannot
// tell a sequence's frame 12 (--frames 12) from a still, but the folder's sidecars can.
void SequenceRun::adopt_folder_names() {
  const FolderNames kind = folder_quilt_names(products_, quilt_, renderer_->rig().aspect);
  const bool sequence = kind == FolderNames::Sequence;
  if ((kind != FolderNames::Sequence && kind != FolderNames::Still) || sequence == products_.sequence) return;
  products_.sequence = sequence;
  if (!job_.quiet && !frames_.empty())
    std::fprintf(stderr, "pmr: note: the folder's quilts are named as %s; these frames' are too (%s)\n",
                 sequence ? "a sequence's" : "stills'",
                 terminal_text(std::filesystem::path(paths(frames_.front()).quilt).filename().string()).c_str());
}

// The images of a frame, checked against the memory budget before anything is created: the view
// volume on the device and, when written, up to three host copies (one read back, one queued, one
// being written) plus the encoder's output; the display image (RGBA and the subpixels' alpha)
// likewise; depth 12 bytes a voxel and sample on the device and as many read back, then 4 a voxel per
// host copy; with glass, the transmission source on the device. The device buffers are checked again as they are allocated.
void SequenceRun::check_frame_memory() const {
  const Rig& rig = renderer_->rig();
  const uint64_t voxels = uint64_t(rig.views) * uint64_t(rig.view_w) * uint64_t(rig.view_h);
  const uint64_t display = products_.encoded ? uint64_t(job_.display.width) * uint64_t(job_.display.height) * 14 : 0;
  // (BLEND layers, the ground catcher's too, are composited in the view volume: such a scene keeps one
  // even for the encoded image)
  const bool pbr = pc_.shading == Shading::Pbr;
  const uint64_t volume = need_volume_ || scene_blended(scene_, pbr) || pc_.ground_shadow ? voxels * 8 : 0;
  const uint64_t depth = need_volume_ && products_.depth ? voxels * (24 * uint64_t(pc_.samples) + 3 * 4) : 0;
  const uint64_t glass =
      pbr && scene_transmissive(scene_) ? TransmissionStage::bytes_for(rig.views, rig.view_w, rig.view_h) : 0;
  // --background environment: its volume on the host and, to encode it, on the device
  const uint64_t backdrop = job_.background.environment ? 2 * voxels * 8 + display : 0;
  check_memory(
      5 * volume + 5 * display + depth + glass + backdrop,
      std::to_string(rig.views) + " views of " + std::to_string(rig.view_w) + "x" + std::to_string(rig.view_h) + " (" +
          std::to_string(volume >> 20) + " MiB a view volume, on the device and in up to four copies being written" +
          (glass ? ", and a " + std::to_string(glass >> 20) + " MiB transmission source for the glass" : "") + ")");
}

// The settings of the pipeline configuration `p` that the sidecar records.
static RenderSettings render_settings(const PipelineConfig& p) {
  RenderSettings r;
  r.method = p.method, r.sampling = p.sampling, r.samples = p.samples, r.texture_filter = p.texture_filter;
  r.shading = p.shading, r.exposure_ev = p.exposure_ev, r.environment_intensity = p.environment_intensity;
  r.shadows = p.shadows, r.shadow_sizes = p.shadow_sizes, r.environment_occlusion = p.environment_occlusion;
  r.ground_shadow = p.ground_shadow;
  r.clear_glass = p.clear_glass && p.shading == Shading::Pbr;
  r.tile_x = p.tile_x, r.tile_y = p.tile_y, r.tile_v = p.tile_v;
  return r;
}

// What every frame's sidecar shares: the job's configuration, the sequence as resolved, what the run
// read and how it framed the scene.
void SequenceRun::prepare_frames() {
  SidecarInfo& info = info_;
  info.scene = job_.scene;
  info.rig_config = rig_config_;
  if (rig_config_.camera >= 0) info.camera_name = scene_.cameras[size_t(rig_config_.camera)].node_name;
  if (scene_.variant >= 0) info.variant = scene_.variants[size_t(scene_.variant)], info.variant_index = scene_.variant;
  info.render = render_settings(job_.pipeline);
  info.display_source = job_.display_source;
  info.sequence = spec_;
  info.compression = job_.compression;
  if (products_.preview && !view_transform_->is_standard()) info.view_transform = view_transform_->record();
  info.background = job_.background;
  info.input_limits = job_.input_limits;
  info.environment = job_.environment;
  info.environment_checksum = environment_checksum_;
  info.environment_rotation_deg = job_.environment_rotation_deg;
  info.has_bounds = true;
  info.bounds_lo = renderer_->bounds_lo();
  info.bounds_hi = renderer_->bounds_hi();
  info.pivot = renderer_->pivot();
  info.warnings = scene_.warnings;
  info.warnings.insert(info.warnings.end(), rig_warnings_.begin(), rig_warnings_.end());
  info.scene_checksum = scene_.source_checksum;
  for (const SceneInputFile& f : scene_.input_files) info.scene_files.push_back({f.path, f.checksum});
}

SidecarInfo SequenceRun::frame_info(long frame, const FramePaths& p, double angle,
                                    std::vector<SceneLight> lights) const {
  SidecarInfo i = info_;
  i.frame = int(frame);
  i.time = double(frame) / spec_.fps;
  i.turntable_angle = angle;
  i.lights = std::move(lights);
  const std::pair<const char*, const std::string*> kinds[] = {{"encoded", &p.encoded},
                                                              {"views", &p.views},
                                                              {"quilt", &p.quilt},
                                                              {"preview_encoded", &p.encoded_png},
                                                              {"preview_center", &p.center_png},
                                                              {"preview_quilt", &p.quilt_png}};
  for (const auto& [kind, path] : kinds)
    if (!path->empty()) i.outputs.push_back({kind, base_name(*path)});
  if (products_.quilt) i.quilt_columns = quilt_.columns, i.quilt_rows = quilt_.rows;
  if (products_.preview) i.center_view = center_view_;
  i.depth = products_.depth;
  i.depth_empty = products_.depth_empty;
  return i;
}

// --print-outputs: the files of each frame of the job, one JSON line a frame on stdout, so that a tool
// driving pmr (the Blender add-on) never expands --name itself. Nothing is rendered or created.
int SequenceRun::print_outputs() const {
  for (long f : frames_) {
    const FramePaths p = paths(f);
    nlohmann::json line = {{"frame", f}, {"sidecar", base_name(p.sidecar)}, {"outputs", nlohmann::json::object()}};
    for (const auto& [kind, file] : frame_info(f, p, 0.0, {}).outputs) line["outputs"][kind] = file;
    std::printf("%s\n", line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  }
  return 0;
}

void SequenceRun::print_header() const {
  if (job_.quiet) return;
  const Rig& rig = renderer_->rig();
  std::fprintf(stderr, "pmr: %s: %zu triangles, %d views of %dx%d -> %dx%d display%s; %zu frame(s)%s\n",
               terminal_text(job_.scene).c_str(), scene_.triangles.size(), rig.views, rig.view_w, rig.view_h,
               job_.display.width, job_.display.height,
               job_.pipeline.sampling == Sampling::Subpixel ? " (subpixel sampling)" : "", plan_.todo.size(),
               plan_.kept ? (", " + std::to_string(plan_.kept) + " already complete").c_str() : "");
  if (!job_.verbose) return;
  // what is not worth a warning unless it shows (near_warned_, the rig's angular spacing warning)
  if (rig.near_eff > rig.near)
    std::fprintf(stderr, "pmr: note: near plane at %g, not %g: the views' disparity stays in its fixed-point range\n",
                 rig.near_eff, rig.near);
  if (rig.angular && rig.views > 1)
    std::fprintf(stderr, "pmr: note: angular camera spacing within %.3g view pixels of the exact cameras\n",
                 spacing_error(rig).view_px);
}

int SequenceRun::run() {
  check_before_loading();
  load_inputs();
  choose_frames();
  prepare_frames();
  // before anything is written: the first frame's sidecar, and room for its outputs' checksums
  check_sidecar_size(expected_sidecar(0, paths(0)).size() + (uint64_t(64) << 10));
  if (job_.print_outputs) return print_outputs();
  // A run refused before it wrote anything (a budget met in the first frame) leaves no folder it made.
  const bool created = prepare_output_dir(products_.out_dir);
  try {
    return guarded_run();
  } catch (...) {
    std::error_code ec;
    if (created) fs::remove(products_.out_dir, ec);  // only if empty (its own lock is gone by now)
    throw;
  }
}

int SequenceRun::guarded_run() {
  // One folder, one configuration: no other configuration rendering into it now, none left beside
  // this run's frames (folder_guard.h). Held until the end of the run.
  const FolderGuard folder_guard(products_.out_dir, products_.name, job_frames_.empty() ? frames_ : job_frames_,
                                 expected_sidecar(0, paths(0)), job_.overwrite, job_.quiet);
  // what writers of this host left when killed (SIGKILL); other hosts' may still be writing (NFS)
  if (const size_t removed = remove_dead_temporaries(products_.out_dir); removed > 0 && !job_.quiet)
    std::fprintf(stderr, "pmr: removed %zu temporary file(s) that writers on this host left when they were killed\n",
                 removed);
  plan_ = plan_resume(
      frames_, job_.resume, job_.overwrite, [&](long f) { return paths(f); },
      [&](long f, const FramePaths& p) { return expected_sidecar(f, p); });
  if (!job_.quiet)  // --quiet: errors and warnings only
    for (const std::string& note : plan_.notes) std::fprintf(stderr, "pmr: %s\n", note.c_str());
  print_header();
  if (plan_.todo.empty()) {
    if (!job_.quiet) std::fprintf(stderr, "pmr: nothing to do\n");
    return 0;
  }
  return render_frames();
}

// The products of a rendered frame, read back from the device into buffers the writer gave back.
FrameFiles SequenceRun::frame_files(long f, const FrameRenderer::Frame& fr, Pipeline& pipeline,
                                    FrameWriter& writer) const {
  const FramePaths p = paths(f);
  const Rig& rig = renderer_->rig();
  FrameFiles files;
  files.frame = f;
  files.compression = job_.compression;
  files.sidecar_path = p.sidecar;
  files.sidecar = frame_info(f, p, fr.angle, fr.lights);
  files.sidecar_rig = fr.rig;
  files.sidecar_display = job_.display;
  files.has_meta = true;  // the EXR header attributes (docs/OUTPUTS.md)
  files.background = job_.background;
  files.quilt_png_opaque = job_.quilt_preview_opaque && job_.background.transparent();
  files.meta.frame = f, files.meta.time = double(f) / spec_.fps, files.meta.fps = spec_.fps;
  files.meta.sidecar = base_name(p.sidecar), files.meta.rig = fr.rig;
  files.meta.center_view = center_view_, files.meta.quilt = quilt_;
  if (products_.encoded) {
    files.encoded_path = p.encoded;
    files.display_w = job_.display.width, files.display_h = job_.display.height;
    files.display = writer.spare_buffer();
    files.sub_alpha = writer.spare_buffer();
    if (renderer_->has_geometry()) {
      pipeline.read_display(files.display);
      pipeline.read_sub_alpha(files.sub_alpha);
    } else {
      files.display.assign(size_t(job_.display.width) * job_.display.height * 4, 0);
      files.sub_alpha.assign(size_t(job_.display.width) * job_.display.height * 3, 0);
    }
  }
  files.encoded_png = p.encoded_png;
  if (view_transform_) files.view_transform = view_transform_.get();
  if (need_volume_) {
    files.views_path = p.views;
    files.quilt_path = p.quilt;
    files.quilt_png = p.quilt_png;
    files.center_png = p.center_png;
    files.quilt = quilt_;
    files.center_view = center_view_;
    files.view_w = rig.view_w, files.view_h = rig.view_h, files.views = rig.views;
    // pixels of a view are non-square: the view spans the display's aspect A
    files.pixel_aspect = float(rig.aspect * rig.view_h / rig.view_w);
    files.volume = writer.spare_buffer();
    if (renderer_->has_geometry()) pipeline.read_volume(files.volume);
    else files.volume.assign(size_t(rig.views) * rig.view_w * rig.view_h * 4, 0);
    if (products_.depth) {
      files.near = fr.rig.near_eff, files.far = fr.rig.far;
      files.depth_empty = products_.depth_empty;
      if (renderer_->has_geometry()) pipeline.read_depth(files.depth);
      else files.depth.assign(size_t(rig.views) * rig.view_w * rig.view_h, std::numeric_limits<float>::infinity());
    }
  }
  if (job_.background.environment) files.background.layers = backdrop_layers(fr.rig, pipeline);
  if (!files.encoded_png.empty() && view_transform_->mixes_channels()) shown_display(files, pipeline);
  return files;
}

// --background environment: the frame's backdrop (output/backdrop.h), made again only when the rig
// moved. Its encoded image comes from the pipeline's encoder, after the frame's own was read back.
std::shared_ptr<const BackdropLayers> SequenceRun::backdrop_layers(const Rig& rig, Pipeline& pipeline) const {
  if (backdrop_ && same_backdrop_rig(rig, backdrop_rig_)) return backdrop_;
  const BackdropParallax p = backdrop_parallax(rig, job_.background.depth);
  if (p.clamped && !backdrop_warned_ && job_.background.depth.kind != BackdropDepth::Kind::Focal) {
    warn("--background-depth " + to_string(job_.background.depth) + ": the backdrop is drawn at " +
         (p.fraction == 0.0 ? std::string("the focal plane (it is nearer)")
                            : std::string("its largest depth with at most 1 view pixel of disparity between "
                                          "neighbouring views, where the panel shows it without doubling")));
    backdrop_warned_ = true;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto ms_since = [](auto t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  };
  auto layers = std::make_shared<BackdropLayers>();
  layers->volume = render_backdrop(rig, *backdrop_environment_, p.fraction);
  const double drawn_ms = ms_since(t0);
  if (products_.encoded) {
    pipeline.encode_volume(layers->volume);
    pipeline.read_display(layers->display);
  }
  if (job_.verbose)
    std::fprintf(stderr,
                 "pmr: backdrop: parallax %.4g (%.3g view px between neighbours), drawn in %.0f ms, encoded in "
                 "%.0f ms\n",
                 p.fraction, p.step_px, drawn_ms, ms_since(t0) - drawn_ms);
  if (!need_volume_) layers->volume = {};
  backdrop_rig_ = rig;
  backdrop_ = layers;
  return backdrop_;
}

// The panel PNG through a transform that mixes channels: every view transformed first (over the
// background), then encoded by the pipeline's own encoder, so each subpixel takes its channel of its
// view's transformed colour. Without geometry every subpixel shows the transformed background.
void SequenceRun::shown_display(FrameFiles& files, Pipeline& pipeline) const {
  if (!renderer_->has_geometry()) {
    const std::vector<uint16_t> empty(files.display.size(), 0);
    files.display_shown = shown_colours(empty.data(), empty.size() / 4, files.background, *view_transform_);
    return;
  }
  const std::vector<uint16_t> shown =
      shown_colours(files.volume.data(), files.volume.size() / 4, files.background, *view_transform_);
  pipeline.encode_volume(shown);
  pipeline.read_display(files.display_shown);
}

void SequenceRun::print_frame_stages(long f, const FrameRenderer::Frame& fr, const Pipeline& pipeline,
                                     Progress& progress) const {
  // the fused path and --sampling subpixel write the display image from the fine raster's tiles
  const bool subpixel = pc_.sampling == Sampling::Subpixel, tiled_encode = pipeline.fused() || subpixel;
  const char* encode_label = subpixel ? " + subpixel samples" : " + encode (fused)";
  char line[360];
  std::snprintf(
      line, sizeof line,
      "pmr: frame %ld: pose %.2f ms, upload %.2f ms; stage times (ms): shadow maps %.2f, vertex %.2f, setup %.2f, "
      "tile raster %.2f, fine raster%s %.2f, %s %.2f; %u MTAs, %llu tile-queue entries, %d queue regrowth(s)",
      f, fr.pose_ms, fr.upload_ms, fr.times.shadow, fr.times.vertex, fr.times.setup, fr.times.bin,
      tiled_encode ? encode_label : "", fr.times.fine, tiled_encode ? "straddling alpha" : "encode", fr.times.encode,
      fr.times.mtas, (unsigned long long)fr.times.bin_entries, fr.times.retries);
  progress.message(line);
}

// Waits for the writer to write every frame submitted, and closes the progress display.
void SequenceRun::finish_writing(FrameWriter& writer, Progress& progress) {
  try {
    writer.finish();
  } catch (...) {
    progress.close();
    progress_ = nullptr;
    throw;
  }
  progress.close();
  progress_ = nullptr;
}

int SequenceRun::render_frames() {
  ClRuntime runtime;
  pc_.fuse_encode = !need_volume_;      // the volume is only kept when a product needs it
  pc_.debug_outputs = products_.depth;  // per-voxel depth
  Pipeline pipeline(runtime, pc_);
  renderer_->attach(pipeline, products_.encoded ? &job_.display : nullptr);  // builds every kernel the frames use
  if (job_.verbose) {
    std::string variants;
    for (const std::string& v : pipeline.kernel_variants()) variants += (variants.empty() ? "" : ", ") + v;
    std::fprintf(stderr, "pmr: device %s; kernels built in %.2f s (%zu work-group functions: %s)\n",
                 runtime.device_name().c_str(), pipeline.kernel_build_seconds(), pipeline.kernel_variants().size(),
                 variants.c_str());
    if (const size_t glass = pipeline.transmission_bytes())
      std::fprintf(stderr,
                   "pmr: glass: a transmission source of %zu MiB (each view's opaque image with its mips); every "
                   "frame draws an opaque pass first\n",
                   glass >> 20);
  }

  install_interrupt_handlers();
  const long total = long(plan_.todo.size());
  Progress progress(total, job_.quiet);
  FrameWriter writer(2, [&progress](long frame) { progress.frame_written(frame); });
  progress_ = &progress;
  const auto t_loop = std::chrono::steady_clock::now();
  const double cpu0 = process_cpu_seconds();
  for (long f : plan_.todo) {
    if (interrupt_signal()) break;
    frame_in_flight_ = f;
    FrameRenderer::Frame fr;
    try {
      fr = renderer_->render(f);
    } catch (...) {  // a frame that cannot render (a camera turned away): the frames before it are written
      finish_writing(writer, progress);
      throw;
    }
    if (interrupt_signal()) break;  // the frame in flight is abandoned
    render_s_ += fr.times.wall / 1000.0;
    pose_s_ += fr.pose_ms / 1000.0;
    upload_s_ += fr.upload_ms / 1000.0;
    if (!fr.visible)
      progress.message("pmr: warning: frame " + std::to_string(f) +
                       ": nothing visible, written as a transparent image");
    if (fr.near_clipped > 0 && !near_warned_) {  // once a run: the next frames say the same
      near_warned_ = true;
      progress.message("pmr: warning: frame " + std::to_string(f) + ": the near plane, moved from " +
                       std::to_string(fr.rig.near) + " to " + std::to_string(fr.rig.near_eff) +
                       " to keep the views' disparity in range, cuts " + std::to_string(fr.near_clipped) +
                       " triangle(s) nearer than it: narrow --cone, widen --yfov or move the camera back");
    }
    if (fr.times.blend_beyond > 0)
      progress.message("pmr: note: frame " + std::to_string(f) + ": " + std::to_string(fr.times.blend_beyond) +
                       " samples had more than 8 alphaMode BLEND fragments; those behind the nearest 8 were "
                       "composited as one layer");
    if (job_.verbose) print_frame_stages(f, fr, pipeline, progress);
    progress.frame_rendered(f, fr.times.wall);
    writer.submit(frame_files(f, fr, pipeline, writer));
    ++rendered_;
  }
  finish_writing(writer, progress);
  loop_s_ = seconds_since(t_loop);
  loop_cpu_s_ = process_cpu_seconds() - cpu0;
  const long written = writer.frames_written();
  if (const int sig = interrupt_signal(); sig && written < total) {
    const long dropped = rendered_ - written;  // rendered, not yet written when the signal came
    std::fprintf(stderr,
                 "pmr: interrupted by %s: %ld of %ld frame(s) written (%ld already complete%s); nothing partial "
                 "was left: rerun with --resume to finish\n",
                 interrupt_signal_name(sig), written, total, plan_.kept,
                 dropped > 0 ? (", " + std::to_string(dropped) + " rendered but not written").c_str() : "");
    return 128 + sig;
  }
  print_summary(writer);
  return 0;
}

void SequenceRun::print_summary(const FrameWriter& writer) const {
  if (job_.quiet) return;
  const double n = double(std::max(1L, rendered_));
  // the process's CPU in the frame loop, less the writer's: the renderer's (its OpenCL threads included).
  // zip and zip-fast compress on threads the writer starts and counts; the other compressions on
  // OpenEXR's own pool, which cannot be told apart from the renderer's threads.
  const double writer_cpu = writer.cpu_seconds();
  const bool ours = job_.compression == ExrCompression::Zip || job_.compression == ExrCompression::ZipFast;
  std::fprintf(stderr,
               "pmr: %ld frame(s) in %.2f s (%.2f s/frame; %ld skipped): render %.0f ms/frame (+ pose %.1f, upload "
               "%.1f), write %.0f "
               "ms/frame on the writer thread (%s, %.1f MB/frame); CPU per frame: renderer%s %.0f ms, writer %.0f ms; "
               "total %.2f s\n",
               rendered_, loop_s_, loop_s_ / n, plan_.kept, 1000.0 * render_s_ / n, 1000.0 * pose_s_ / n,
               1000.0 * upload_s_ / n, 1000.0 * writer.write_seconds() / n, to_string(job_.compression),
               double(writer.bytes_written()) / n / 1e6, ours ? "" : " and OpenEXR's compressing threads",
               1000.0 * std::max(0.0, loop_cpu_s_ - writer_cpu) / n, 1000.0 * writer_cpu / n, seconds_since(t0_));
  if (rendered_ == 1) {
    const FramePaths p = paths(plan_.todo[0]);
    for (const std::string& path : p.images()) std::fprintf(stderr, "pmr: wrote %s\n", path.c_str());
    std::fprintf(stderr, "pmr: wrote %s\n", p.sidecar.c_str());
  }
}

}  // namespace

int run_sequence(const SequenceJob& job) { return SequenceRun(job).run(); }

}  // namespace pmr
