#include "pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>

#include "pipeline/encode_stage.h"
#include "pipeline/fine_stage.h"
#include "pipeline/geometry_stage.h"
#include "pipeline/launcher.h"
#include "pipeline/scene_buffers.h"
#include "pipeline/shadow_stage.h"
#include "pmr/error.h"
#include "pmr/limits.h"
#include "shading/lights.h"

namespace pmr {

namespace {

// Private memory one fused work-item may use for its visibility state and colours (per voxel of a
// screen tile over all views: depth, key and winning MTA, and the half RGBA colour); larger
// configurations use the unfused path.
constexpr size_t kFusedPrivateBudget = size_t(256) << 10;
// per voxel: depth, key and winner per sample (and the winner's sample coverage when there are several),
// then the shaded colour
constexpr size_t kFusedBytesPerSample = 3 * sizeof(uint32_t), kFusedBytesPerVoxel = 4 * sizeof(uint16_t);
size_t fused_bytes_per_voxel(int samples) {
  return (kFusedBytesPerSample + (samples > 1 ? sizeof(uint32_t) : 0)) * size_t(samples) + kFusedBytesPerVoxel;
}

// Fine raster vector width (PMR_VW): the smallest of 4, 8, 16 lanes that holds a tile row (wider rows
// take several vectors).
int fine_lanes(int tile_x) { return tile_x <= 4 ? 4 : (tile_x <= 8 ? 8 : 16); }

// The 3D tile of the method: PMR's as configured; the single-view baselines use 2D tiles, the
// configured one if its V is 1, else 8x8x1.
void method_tile(const PipelineConfig& config, size_t max_group, int* tile) {
  tile[0] = config.tile_x, tile[1] = config.tile_y, tile[2] = config.tile_v;
  if (config.method != Method::Pmr && config.tile_v != 1) tile[0] = 8, tile[1] = 8, tile[2] = 1;
  const int tx = tile[0], ty = tile[1], tv = tile[2];
  if (tx < 1 || ty < 1 || tv < 1 || tx > kMaxTileSide || ty > kMaxTileSide || tv > kMaxTileSide)
    throw Error("invalid --tile: each tile side must be 1.." + std::to_string(kMaxTileSide));
  if (size_t(tx) * ty * tv > max_group)
    throw Error("invalid --tile " + std::to_string(tx) + "x" + std::to_string(ty) + "x" + std::to_string(tv) + ": " +
                std::to_string(tx * ty * tv) + " voxels exceed the device's work-group limit of " +
                std::to_string(max_group));
}

// -w: PoCL's compiler would print "N warnings generated." on the user's terminal at every cold build.
// PMR_TRILINEAR: bilinear filtering's kernels carry no level-of-detail code (cl/texture.h).
std::string build_options(const int* tile, const PipelineConfig& config) {
  return "-cl-std=CL1.2 -w -cl-fp32-correctly-rounded-divide-sqrt -DPMR_TILE_X=" + std::to_string(tile[0]) +
         " -DPMR_TILE_Y=" + std::to_string(tile[1]) + " -DPMR_TILE_V=" + std::to_string(tile[2]) +
         " -DPMR_VW=" + std::to_string(fine_lanes(tile[0])) + " -DPMR_SAMPLES=" + std::to_string(config.samples) +
         " -DPMR_TRILINEAR=" + (config.texture_filter == TextureFilter::Trilinear ? "1" : "0");
}

}  // namespace

struct Pipeline::Impl {
  Impl(const ClRuntime& rt, const PipelineConfig& config, const int* tile_in)
      : tile{tile_in[0], tile_in[1], tile_in[2]},
        launcher(rt),
        options(build_options(tile, config)),
        program(launcher.build({"vertex.cl", "setup.cl", "bin.cl", "fine.cl", "encode.cl", "straddle_alpha.cl",
                                "source_mips.cl", "shadow.cl"},
                               options)),
        scene(rt, config),
        geometry(launcher, program, config.tile_queue_limit),
        encode(launcher, program),
        fine(launcher, program, options, tile),
        transmission(launcher, program),
        shadows(launcher, program, config.shadow_sizes) {}

  int tile[3];
  Launcher launcher;
  std::string options;
  ClProgram program;  // the main program: every stage's kernels but the per-view-count ones
  SceneBuffers scene;
  GeometryStage geometry;
  EncodeStage encode;
  FineStage fine;
  TransmissionStage transmission;
  ShadowStage shadows;
  FinePaths paths;
  int views = 0, view_w = 0, view_h = 0;  // as configured
  Rig rig;                                // ... the rig and display of the last configure()
  std::unique_ptr<Display> display;
  // PmrParams.lod_scale_x/y: view pixels per output pixel (subpixel sampling: a display pixel's)
  float lod_scale[2] = {1.0f, 1.0f};
  uint64_t num_tiles = 0;

  void render_multipass(const Rig& rig, const PmrParams& P, bool snapped, FrameEvents& ev, StageTimes& t);
  void render_fine(FrameEvents& ev, int screen_tiles);
  void configure_transmission() { transmission.configure(scene.transmissive(), views, view_w, view_h, num_tiles); }
};

Pipeline::Pipeline(const ClRuntime& runtime, const PipelineConfig& config) : config_(config) {
  int tile[3];
  method_tile(config, runtime.max_work_group_size(), tile);
  impl_.reset(new Impl(runtime, config, tile));
}

Pipeline::~Pipeline() = default;

void Pipeline::set_scene(const Scene& scene, const Scene* catcher) {
  Impl& m = *impl_;
  m.scene.set_scene(scene, catcher);
  if (m.views > 0 && m.paths.fused && m.scene.blended()) {  // BLEND needs the volume path: choose again
    const std::unique_ptr<Display> display = std::move(m.display);
    configure(Rig(m.rig), display.get());
  }
  if (m.views > 0) m.configure_transmission();
  m.geometry.set_scene(m.scene, config_.method == Method::Multipass && config_.multipass_snapped);
}

void Pipeline::update_geometry(const Scene& posed) { impl_->scene.update_geometry(posed); }

FrameDescription describe_frame(const Rig& rig, const std::vector<SceneLight>& scene_lights,
                                const PipelineConfig& config) {
  FrameDescription f;
  f.rig = rig;
  if (config.shading != Shading::Pbr) return f;
  f.lights = resolve_lights(scene_lights, rig, config.environment.get());
  if (config.shadows && config.environment_occlusion)
    f.occlusion = occlusion_directions(config.environment.get(), config.environment_intensity);
  return f;
}

size_t Pipeline::volume_bytes() const { return impl_->fine.volume_bytes(); }
size_t Pipeline::display_bytes() const { return impl_->encode.display_bytes(); }
size_t Pipeline::transmission_bytes() const {
  return impl_->transmission.active() ? impl_->transmission.source().size() : 0;
}

// Which forms of the fine raster a configuration renders (FinePaths).
FinePaths Pipeline::choose_paths(const Rig& rig, const Display* display) const {
  FinePaths p;
  p.subpixel = config_.sampling == Sampling::Subpixel;
  if (p.subpixel) {
    if (!display) throw Error("--sampling subpixel samples a display's subpixels: it needs a display");
    check_subpixel_sampling(config_.method, *display);
  }
  const int* tile = impl_->tile;
  const int lanes = fine_lanes(tile[0]);
  const size_t fused_private =
      size_t(tile[0] + lanes - 1) / lanes * lanes * tile[1] * rig.views * fused_bytes_per_voxel(config_.samples);
  // BLEND layers are composited by the volume form alone (cl/blend.h): its tiles are small
  p.fused = !p.subpixel && config_.fuse_encode && display && !display->bilinear && !display->blend_views &&
            display->cell_rows <= 1 && config_.method == Method::Pmr && !config_.debug_outputs &&
            fused_private <= kFusedPrivateBudget && !impl_->scene.blended();
  p.volume = !p.fused && !(p.subpixel && config_.fuse_encode);
  p.debug = config_.debug_outputs;
  p.samples = config_.samples;
  return p;
}

void Pipeline::configure(const Rig& rig, const Display* display) {
  Impl& m = *impl_;
  const int* tile = m.tile;
  tiles_x_ = (rig.view_w + tile[0] - 1) / tile[0];
  tiles_y_ = (rig.view_h + tile[1] - 1) / tile[1];
  // multipass rasterizes one view per pass, so its tile grid is one view deep
  const int pass_views = config_.method == Method::Multipass ? 1 : rig.views;
  tiles_v_ = (pass_views + tile[2] - 1) / tile[2];
  m.num_tiles = uint64_t(tiles_x_) * tiles_y_ * tiles_v_;
  if (m.num_tiles >= (uint64_t(1) << 32)) throw Error("too many tiles; use larger --tile");
  m.views = rig.views, m.view_w = rig.view_w, m.view_h = rig.view_h;
  m.rig = rig;
  m.display = display ? std::make_unique<Display>(*display) : nullptr;
  m.paths = choose_paths(rig, display);
  // A display pixel covers view_w / display_w view pixels across (and view_h / display_h down): the
  // texture footprint of a subpixel's sample is the display pixel's, not its view pixel's.
  m.lod_scale[0] = m.paths.subpixel ? float(double(rig.view_w) / display->width) : 1.0f;
  m.lod_scale[1] = m.paths.subpixel ? float(double(rig.view_h) / display->height) : 1.0f;
  if (display) m.encode.configure(*display, rig.views, rig.view_w, rig.view_h);
  m.fine.configure(m.paths, rig.views, rig.view_w, rig.view_h, display ? &m.encode : nullptr);
  m.geometry.configure(m.num_tiles);
  m.configure_transmission();
  m.launcher.runtime().finish();
  m.launcher.warm_up([&] { render_frame(describe_frame(rig, {}, config_), true); });
}

double Pipeline::kernel_build_seconds() const { return impl_->launcher.build_seconds(); }
const std::vector<std::string>& Pipeline::kernel_variants() const { return impl_->launcher.variants(); }

void Pipeline::read_shadow_maps(std::vector<PmrShadowMap>& maps, std::vector<float>& depth) const {
  maps = impl_->shadows.maps();
  depth = impl_->shadows.read_depth();
}

void Pipeline::set_mta_capacity(uint32_t capacity) { impl_->geometry.set_mta_capacity(capacity); }

StageTimes Pipeline::render(const Rig& rig) {
  return render(describe_frame(rig, impl_->scene.scene_lights(), config_));
}

StageTimes Pipeline::render(const FrameDescription& frame) { return render_frame(frame, false); }

// The kernels' parameters of one frame: everything the frame's rig gives (make_params), then what the
// configuration fixes for the run. An empty frame (the warm-up) has no vertices, triangles or tiles.
PmrParams Pipeline::frame_params(const FrameDescription& frame, bool empty) const {
  const Impl& m = *impl_;
  const Rig& rig = frame.rig;
  if (rig.views != m.views || rig.view_w != m.view_w || rig.view_h != m.view_h)
    throw InternalError("a frame's rig differs in size from the configured one");
  PmrParams P = make_params(rig);
  P.tiles_x = empty ? 0 : tiles_x_;
  P.tiles_y = empty ? 0 : tiles_y_;
  P.tiles_v = empty ? 0 : tiles_v_;
  P.num_vertices = empty ? 0 : m.scene.num_vertices();
  P.num_triangles = empty ? 0 : m.scene.num_triangles();
  P.debug_outputs = config_.debug_outputs ? 1u : 0u;
  P.setup_mode = config_.method == Method::Duplicate ? PMR_SETUP_DUPLICATE : PMR_SETUP_MTA;
  P.sample_area = m.paths.subpixel ? PMR_SAMPLES_PIXEL : PMR_SAMPLES_CENTER;
  if (m.paths.subpixel) {  // the pattern spans one display pixel's footprint in the view (DESIGN section 3b)
    const PmrEncodeParams& E = m.encode.params();
    set_sample_pattern(config_.samples, double(rig.view_w) / E.display_w, double(rig.view_h) / E.display_h, P);
  } else {
    set_sample_pattern(config_.samples, P);
  }
  P.shading = config_.shading == Shading::Pbr ? PMR_SHADING_PBR : PMR_SHADING_LAMBERT;
  P.exposure = float(std::exp2(config_.exposure_ev));
  P.texture_filter = config_.texture_filter == TextureFilter::Trilinear ? PMR_FILTER_TRILINEAR : PMR_FILTER_BILINEAR;
  P.lod_scale_x = m.lod_scale[0], P.lod_scale_y = m.lod_scale[1];
  P.env_radiance = float(0.2 * config_.environment_intensity);
  P.num_lights = uint32_t(frame.lights.size());
  return P;
}

StageTimes Pipeline::render_frame(const FrameDescription& frame, bool empty) {
  Impl& m = *impl_;
  const auto t_start = std::chrono::steady_clock::now();
  if (m.views == 0) throw InternalError("Pipeline::render before configure");
  StageTimes times;
  FrameEvents ev;
  PmrParams P = frame_params(frame, empty);
  m.shadows.place(config_.shadows && config_.shading == Shading::Pbr, frame.lights, frame.occlusion, m.scene);
  m.scene.upload_frame(frame, m.shadows.placement());
  P.env_occlusion = m.shadows.placement().occlusion.count > 0 ? 1u : 0u;
  P.clear_glass = config_.clear_glass && config_.shading == Shading::Pbr ? 1u : 0u;
  m.fine.begin_frame();
  if (config_.shadows && config_.shading == Shading::Pbr)
    m.shadows.render(m.scene, P, m.transmission.full_pass(), ev, empty);
  if (config_.method == Method::Multipass) {
    m.render_multipass(frame.rig, P, config_.multipass_snapped, ev, times);
  } else {
    m.geometry.transform(P, m.scene, ev);
    m.geometry.setup_and_bin(P, m.scene, ev, times);
    m.render_fine(ev, tiles_x_ * tiles_y_);
  }
  if (m.encode.configured() && m.paths.volume && !m.paths.subpixel) m.encode.encode(m.fine.volume(), ev);
  if (config_.slow_frame && !empty) wait_reporting(ev, times, t_start);
  m.launcher.runtime().finish();
  ev.collect(times);
  if (m.scene.blended()) times.blend_beyond = m.fine.blend_overflow();
  times.wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_start).count();
  return times;
}

// Stage 4 of a frame whose geometry is binned: with transmissive surfaces, first the transmission
// source (the opaque pass into its level 0 and the mip chain: DESIGN section 4c step 2), then the
// configuration's paths, which read it.
void Pipeline::Impl::render_fine(FrameEvents& ev, int screen_tiles) {
  if (transmission.active()) {
    fine.run_volume(scene, geometry, num_tiles, shadows.binding(), transmission.opaque_pass(), ev,
                    &transmission.source());
    transmission.mip(0, views, ev);
  }
  const SourceBinding source = transmission.full_pass();
  if (paths.fused) fine.run_fused(scene, geometry, size_t(screen_tiles), encode, shadows.binding(), source, ev);
  if (paths.volume) fine.run_volume(scene, geometry, num_tiles, shadows.binding(), source, ev);
  if (paths.subpixel) fine.run_subpixel(scene, geometry, encode, shadows.binding(), source, ev);
}

// The multipass baseline: one conventional pass per view with view i's own view matrix and off-axis
// projection, x_ndc = (D / a) x_view / w + s_i / a in camera i's view space. `snapped` (a test mode):
// every pass takes PMR's snapped positions of its view, from PMR's vertex records computed once.
void Pipeline::Impl::render_multipass(const Rig& rig, const PmrParams& P, bool snapped, FrameEvents& ev,
                                      StageTimes& t) {
  if (snapped) {
    geometry.transform(P, scene, ev);
    geometry.swap_snapped();
  }
  const double a = rig.aspect * rig.focal * std::tan(rig.yfov / 2.0);
  for (int i = 0; i < rig.views; ++i) {
    PmrParams Q = P;
    const glm::dmat4 V = rig.view_matrix(i);
    std::copy(&V[0][0], &V[0][0] + 16, Q.view);
    Q.views = 1;
    Q.disparity_k = 0.0;
    Q.ndc_offset_x = rig.camera_offset(i) / a;
    Q.view_base = uint32_t(i);
    std::fill(std::begin(Q.view_coord), std::end(Q.view_coord), 0);  // the pass's one view
    if (snapped) geometry.select_view(Q, rig.view_coord(i), ev);
    else geometry.transform(Q, scene, ev);
    geometry.setup_and_bin(Q, scene, ev, t);
    if (transmission.active()) {  // as a conventional renderer: the view's opaque pass, then its own
      fine.run_volume(scene, geometry, num_tiles, shadows.binding(), transmission.opaque_pass(), ev,
                      &transmission.source());
      transmission.mip(i, 1, ev);
    }
    fine.run_volume(scene, geometry, num_tiles, shadows.binding(), transmission.full_pass(), ev);
  }
  if (snapped) geometry.swap_snapped();
}

// Waits for the frame's last command, calling the configuration's slow_frame every slow_frame_seconds
// once the frame has run that long. The event's completion callback wakes the wait, so a fast frame
// waits no longer than finish() would.
void Pipeline::wait_reporting(const FrameEvents& ev, const StageTimes& t, std::chrono::steady_clock::time_point start) {
  const auto step = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(config_.slow_frame_seconds));
  if (!ev.last()) return;
  struct Done {
    std::mutex mutex;
    std::condition_variable changed;
    bool done = false;
  } d;
  auto complete = [](cl_event, cl_int, void* user) {
    auto* p = static_cast<Done*>(user);
    std::lock_guard<std::mutex> lock(p->mutex);
    p->done = true;
    p->changed.notify_all();
  };
  if (clSetEventCallback(ev.last(), CL_COMPLETE, complete, &d) != CL_SUCCESS) return;  // finish() waits
  clFlush(impl_->launcher.runtime().queue());
  std::unique_lock<std::mutex> lock(d.mutex);
  auto next = start + step;
  while (!d.changed.wait_until(lock, next, [&] { return d.done; })) {
    config_.slow_frame(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), t.bin_entries);
    next += step;
  }
}

StageTimes Pipeline::encode_volume(const std::vector<uint16_t>& volume) {
  Impl& m = *impl_;
  if (!m.encode.configured()) throw InternalError("no display configured");
  if (volume.size() * 2 != volume_bytes()) throw InternalError("volume size mismatch");
  // the paths that encode from screen tiles keep no view volume: the given one goes to a buffer of its own
  const ClRuntime& rt = m.launcher.runtime();
  ClBuffer scratch = m.paths.volume ? ClBuffer() : rt.buffer(volume_bytes(), "volume to encode");
  const ClBuffer& target = m.paths.volume ? m.fine.volume() : scratch;
  rt.write(target, volume.data(), volume_bytes());
  FrameEvents ev;
  m.encode.encode(target, ev);
  rt.finish();
  StageTimes t;
  ev.collect(t);
  return t;
}

bool Pipeline::fused() const { return impl_->paths.fused; }
bool Pipeline::has_volume() const { return impl_->paths.volume; }

void Pipeline::read_volume(std::vector<uint16_t>& out) const { impl_->fine.read_volume(out); }
void Pipeline::read_display(std::vector<uint16_t>& out) const { impl_->encode.read_display(out); }
void Pipeline::read_sub_alpha(std::vector<uint16_t>& out) const { impl_->encode.read_sub_alpha(out); }
void Pipeline::read_debug(std::vector<uint32_t>& keys, std::vector<float>& depth, std::vector<uint32_t>& count) const {
  impl_->fine.read_debug(keys, depth, count);
}

void Pipeline::read_depth(std::vector<float>& depth) const {
  std::vector<uint32_t> keys, count;
  std::vector<float> samples;
  impl_->fine.read_debug(keys, samples, count);
  const size_t S = size_t(config_.samples);
  depth.assign(samples.size() / S, std::numeric_limits<float>::infinity());
  for (size_t k = 0; k < samples.size(); ++k) depth[k / S] = std::min(depth[k / S], samples[k]);
}

size_t Pipeline::device_bytes() const {
  const Impl& m = *impl_;
  return m.scene.device_bytes() + m.geometry.device_bytes() + m.encode.device_bytes() + m.fine.device_bytes() +
         m.transmission.device_bytes();
}

std::vector<PmrMta> Pipeline::read_mtas() const { return impl_->geometry.read_mtas(); }
void Pipeline::read_tile_queues(std::vector<uint32_t>& offsets, std::vector<uint32_t>& queue) const {
  impl_->geometry.read_tile_queues(offsets, queue);
}
std::vector<PmrVertex> Pipeline::read_vertices() const { return impl_->geometry.read_vertices(); }
PmrParams Pipeline::read_params() const { return impl_->geometry.read_params(); }

}  // namespace pmr
