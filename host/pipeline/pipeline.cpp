#include "pipeline/pipeline.h"

#include "pipeline/material_tables.h"
#include "pipeline/tile_tables.h"
#include "shading/environment.h"
#include "shading/lights.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>

#include "pmr/error.h"

namespace pmr {

namespace {

enum Stage { kVertex, kSetup, kBin, kFine, kEncode, kStages };

// Private memory one fused work-item may use for its visibility state and colours (20 bytes per
// voxel of a screen tile over all views); larger configurations use the unfused path.
constexpr size_t kFusedPrivateBudget = size_t(256) << 10;

// Work-group sizes, explicit for every launch (see ClRuntime::launch): the per-item stages (vertex,
// setup, tile raster) run groups of 64 work-items, several per core and wide enough for 16-lane vector
// code; the fine raster runs one work-item per tile in groups of 8, which keeps the two cores balanced.
constexpr size_t kItemGroup = 64;
constexpr size_t kFineGroup = 8;

// Fine raster vector width (PMR_VW): the smallest of 4, 8, 16 lanes that holds a tile row (wider rows
// take several vectors).
int fine_lanes(int tile_x) { return tile_x <= 4 ? 4 : (tile_x <= 8 ? 8 : 16); }

// RAII for the profiling events of one frame, each tagged with its stage.
struct Events {
  std::vector<std::pair<Stage, cl_event>> all;
  cl_event add(Stage s, cl_event e) {
    all.push_back({s, e});
    return e;
  }
  // Adds up the device time per stage (after the queue has finished).
  void collect(StageTimes& t) const {
    double ms[kStages] = {};
    for (const auto& se : all) ms[se.first] += event_ms(se.second);
    t.vertex = ms[kVertex], t.setup = ms[kSetup], t.bin = ms[kBin], t.fine = ms[kFine], t.encode = ms[kEncode];
    if (!all.empty()) t.device_total = event_span_ms(all.front().second, all.back().second);
  }
  ~Events() {
    for (const auto& se : all) clReleaseEvent(se.second);
  }
};

std::vector<float> srgb_lut() {
  std::vector<float> lut(256);
  for (int c = 0; c < 256; ++c) {
    const double v = c / 255.0;
    lut[c] = float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
  }
  return lut;
}

template <typename T>
size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

}  // namespace

struct Pipeline::Impl {
  const ClRuntime& rt;
  cl_program program = nullptr;
  ClKernel k_vertex, k_vertex_select, k_setup, k_bin_count, k_bin_fill, k_fine, k_encode, k_encode_bilinear, k_encode_blend;

  // scene
  uint32_t num_vertices = 0, num_triangles = 0;
  ClBuffer positions, attrs, tris, materials, textures, texels, lut;
  ClBuffer eyes, split_sum;  // each view's camera position (per frame); the pbr split-sum table
  ClBuffer texcoords, tangents;  // the TEXCOORD sets the material maps sample; world tangents (pbr)
  bool has_tangents = false;
  ClBuffer env, env_data;    // pbr: the environment image's header and tables (level_count 0: none)
  std::vector<SceneLight> scene_lights;  // the scene's lights (set_scene), for render(const Rig&)
  ClBuffer lights;                       // the frame's light table (PmrLight), uploaded every frame
  // frame
  PmrParams params{};
  PmrEncodeParams encode_params{};
  bool encode = false;
  ClBuffer params_buf, encode_buf, vertices, pmr_vertices, mtas, mta_counter;
  uint32_t mta_capacity = 0;
  bool mta_capacity_fixed = false;
  ClBuffer tile_counts, tile_offsets, tile_queue;
  size_t tile_queue_capacity = 0;
  ClBuffer volume, display, sub_alpha, encode_columns, encode_rows;
  ClBuffer dbg_key, dbg_depth, dbg_count;
  // fused raster + encode (cl/fine_encode.cl), built per view count
  cl_program fused_program = nullptr;
  int fused_views = 0;
  ClKernel k_fine_encode, k_straddle_alpha;
  bool fused = false;
  ClBuffer column_start, column_soa, row_start, straddle_slot, straddle_columns, straddle_cov;
  uint32_t straddle_slots = 0;
  // --sampling subpixel (cl/fine_subpixel.cl), built per view count; shares the straddle buffers
  cl_program subpixel_program = nullptr;
  int subpixel_views = 0;
  ClKernel k_fine_subpixel, k_subpixel_straddle;
  bool subpixel = false, keep_volume = true;
  bool subpixel_debug = false;  // debug outputs per display subpixel (when no view volume is rendered)
  ClBuffer chunks, sample_x, sample_y, column_a, column_b;
  uint32_t num_chunks = 0;
  size_t debug_entries = 1;
  uint32_t last_mtas = 0;
  uint64_t num_tiles = 0;
  // Kernel builds: OpenCL program builds plus the work-group functions compiled by the warm-up frame
  // (Pipeline::build_kernels), and the (kernel, local size) pairs that frame launched.
  double build_seconds = 0.0;
  bool warming = false;
  std::vector<std::string> variants;

  explicit Impl(const ClRuntime& r) : rt(r) {}
  uint64_t tile_queue_limit = UINT64_MAX;  // PipelineConfig::tile_queue_limit

  // Every stage launches through these: the real grid, or while warming one work-group of the same
  // local size on a frame in which every count is zero (the kernels return at once).
  cl_event launch(const ClKernel& k, size_t items, size_t local) {
    return warming ? warm(k, local, 1) : rt.launch(k, items, local);
  }
  cl_event launch_2d(const ClKernel& k, size_t gx, size_t gy, size_t lx, size_t ly) {
    return warming ? warm(k, lx, ly) : rt.launch_2d(k, gx, gy, lx, ly);
  }
  cl_event warm(const ClKernel& k, size_t lx, size_t ly) {
    const std::string v = k.name() + " " + std::to_string(lx) + "x" + std::to_string(ly);
    if (std::find(variants.begin(), variants.end(), v) == variants.end()) variants.push_back(v);
    return rt.launch_one_group(k, lx, ly);
  }
  cl_program build(const std::vector<std::string>& files, const std::string& options) {
    const auto t0 = std::chrono::steady_clock::now();
    cl_program p = rt.build_program(files, options);
    build_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return p;
  }

  // Each stage enqueues its kernel(s) for the parameters P (written to params_buf here).
  void vertex_stage(const PmrParams& P, Events& ev);
  void select_view_stage(const PmrParams& P, int coord, Events& ev);
  void setup_stage(PmrParams& P, Events& ev, StageTimes& t);
  void bin_stage(Events& ev, StageTimes& t);
  void fine_stage(Events& ev);
  void wait_reporting(const Events& ev, const StageTimes& t, std::chrono::steady_clock::time_point start,
                      double interval, const std::function<void(double, uint64_t)>& report);
  void encode_stage(Events& ev);
  void fused_stage(const PmrParams& P, Events& ev);
  void subpixel_stage(Events& ev);
  void straddle_alpha_stage(ClKernel& k, Events& ev);
  void configure_fused(const std::string& options, int views, int tile_x, const std::vector<PmrEncodeColumn>& columns,
                       const std::vector<PmrEncodeRow>& rows);
  void configure_subpixel(const std::string& options, int views, const int* tile,
                          const std::vector<PmrEncodeColumn>& columns, const std::vector<PmrEncodeRow>& rows);
  void upload_straddles(const TileOwnership& own);
  void upload_frame(const FrameDescription& frame);
  void upload_table(ClBuffer& b, const std::vector<int32_t>& v, const char* name) {
    b = rt.buffer(std::max<size_t>(bytes_of(v), 16), name, CL_MEM_READ_ONLY);
    rt.write(b, v.data(), bytes_of(v));
  }
  ~Impl() {
    if (program) clReleaseProgram(program);
    if (fused_program) clReleaseProgram(fused_program);
    if (subpixel_program) clReleaseProgram(subpixel_program);
  }
};

Method parse_method(const std::string& name) {
  if (name == "pmr") return Method::Pmr;
  if (name == "multipass") return Method::Multipass;
  if (name == "duplicate") return Method::Duplicate;
  throw Error("unknown method '" + name + "' (expected pmr, multipass or duplicate)");
}

const char* to_string(Method m) {
  switch (m) {
    case Method::Multipass: return "multipass";
    case Method::Duplicate: return "duplicate";
    default: return "pmr";
  }
}

Sampling parse_sampling(const std::string& name) {
  if (name == "view") return Sampling::View;
  if (name == "subpixel") return Sampling::Subpixel;
  throw Error("unknown sampling '" + name + "' (expected view or subpixel)");
}

const char* to_string(Sampling s) { return s == Sampling::Subpixel ? "subpixel" : "view"; }

Shading parse_shading(const std::string& name) {
  if (name == "lambert") return Shading::Lambert;
  if (name == "pbr") return Shading::Pbr;
  throw Error("unknown shading '" + name + "' (expected lambert or pbr)");
}

const char* to_string(Shading s) { return s == Shading::Pbr ? "pbr" : "lambert"; }

void check_subpixel_sampling(Method method, const Display& display) {
  if (method != Method::Pmr) throw Error("--sampling subpixel renders with --method pmr");
  if (display.bilinear || display.blend_views)
    throw Error("--sampling subpixel computes every subpixel at its own sample: --bilinear and --blend-views "
                "apply to --sampling view only");
}

namespace {

// The environment image's tables, uploaded once per pipeline (the Environment is prefiltered once per
// process and shared); without one, an empty header (level_count 0) selects the uniform default.
void upload_environment(Pipeline::Impl& m, const PipelineConfig& config) {
  const Environment* e = config.environment.get();
  if (e && config.shading != Shading::Pbr) throw Error("an environment image needs --shading pbr");
  if (e && e->tables().header.intensity != float(config.environment_intensity))
    throw Error("internal error: the environment's intensity differs from the configuration's");
  const PmrEnvironment none{};
  const std::vector<float> no_data(4, 0.0f);
  const PmrEnvironment& header = e ? e->tables().header : none;
  const std::vector<float>& data = e ? e->tables().data : no_data;
  if (bytes_of(data) > m.rt.max_alloc_bytes())
    throw Error("the environment's tables need " + std::to_string(bytes_of(data) >> 20) + " MiB, more than the device "
                "can allocate at once (" + std::to_string(m.rt.max_alloc_bytes() >> 20) + " MiB): use a smaller image");
  m.env = m.rt.buffer(sizeof header, "environment header", CL_MEM_READ_ONLY);
  m.rt.write(m.env, &header, sizeof header);
  m.env_data = m.rt.buffer(bytes_of(data), "environment tables", CL_MEM_READ_ONLY);
  m.rt.write(m.env_data, data.data(), bytes_of(data));
}

}  // namespace

Pipeline::Pipeline(const ClRuntime& runtime, const PipelineConfig& config)
    : impl_(new Impl(runtime)), config_(config) {
  impl_->tile_queue_limit = config.tile_queue_limit;
  tile_[0] = config.tile_x, tile_[1] = config.tile_y, tile_[2] = config.tile_v;
  if (config.method != Method::Pmr && config.tile_v != 1) tile_[0] = 8, tile_[1] = 8, tile_[2] = 1;
  const int tx = tile_[0], ty = tile_[1], tv = tile_[2];
  if (tx < 1 || ty < 1 || tv < 1 || tx > 64 || ty > 64 || tv > 64)
    throw Error("invalid --tile: each tile side must be 1..64");
  if (size_t(tx) * ty * tv > runtime.max_work_group_size())
    throw Error("invalid --tile " + std::to_string(tx) + "x" + std::to_string(ty) + "x" + std::to_string(tv) +
                ": " + std::to_string(tx * ty * tv) + " voxels exceed the device's work-group limit of " +
                std::to_string(runtime.max_work_group_size()));
  // -w: PoCL's compiler would print "N warnings generated." on the user's terminal at every cold build
  const std::string options = "-cl-std=CL1.2 -w -cl-fp32-correctly-rounded-divide-sqrt -DPMR_TILE_X=" +
                              std::to_string(tx) + " -DPMR_TILE_Y=" + std::to_string(ty) +
                              " -DPMR_TILE_V=" + std::to_string(tv) + " -DPMR_VW=" + std::to_string(fine_lanes(tx));
  Impl& m = *impl_;
  build_options_ = options;
  m.program = m.build({"vertex.cl", "setup.cl", "bin.cl", "fine.cl", "encode.cl"}, options);
  m.k_vertex = ClKernel(m.program, "vertex_transform");
  m.k_vertex_select = ClKernel(m.program, "vertex_select_view");
  m.k_setup = ClKernel(m.program, "setup_triangles");
  m.k_bin_count = ClKernel(m.program, "bin_count");
  m.k_bin_fill = ClKernel(m.program, "bin_fill");
  m.k_fine = ClKernel(m.program, "fine_raster");
  m.k_encode = ClKernel(m.program, "encode_nearest");
  m.k_encode_bilinear = ClKernel(m.program, "encode_bilinear");
  m.k_encode_blend = ClKernel(m.program, "encode_blend");
  m.params_buf = runtime.buffer(sizeof(PmrParams), "frame parameters", CL_MEM_READ_ONLY);
  m.encode_buf = runtime.buffer(sizeof(PmrEncodeParams), "encoder parameters", CL_MEM_READ_ONLY);
  m.mta_counter = runtime.buffer(sizeof(uint32_t), "MTA counter");
  const auto lut = srgb_lut();
  m.lut = runtime.buffer(bytes_of(lut), "sRGB table", CL_MEM_READ_ONLY);
  runtime.write(m.lut, lut.data(), bytes_of(lut));
  // the split-sum table (pbr only: computing it costs about 0.5 s of CPU once per process)
  static_assert(kEnvSplitSumSize == PMR_SPLIT_SUM_N, "the kernels' split-sum table size");
  const std::vector<float> none(2, 0.0f);
  const std::vector<float>& table = config.shading == Shading::Pbr ? split_sum_table() : none;
  m.split_sum = runtime.buffer(bytes_of(table), "split-sum table", CL_MEM_READ_ONLY);
  runtime.write(m.split_sum, table.data(), bytes_of(table));
  upload_environment(m, config);
}

Pipeline::~Pipeline() = default;

void Pipeline::set_scene(const Scene& scene) {
  Impl& m = *impl_;
  const ClRuntime& rt = m.rt;
  if (scene.triangles.size() >= PMR_MAX_TRIANGLES)
    throw Error("the scene has " + std::to_string(scene.triangles.size()) + " triangles; at most " +
                std::to_string(PMR_MAX_TRIANGLES - 1) + " are supported");
  m.num_vertices = uint32_t(scene.positions.size());
  m.num_triangles = uint32_t(scene.triangles.size());
  const MaterialTables tables = make_material_tables(scene);
  m.has_tangents = scene.tangents.size() == scene.positions.size() && !scene.positions.empty();
  const std::vector<glm::vec4> no_tangents(1, glm::vec4(0.0f));
  const std::vector<glm::vec4>& tangents = m.has_tangents ? scene.tangents : no_tangents;
  m.scene_lights = scene.lights;

  m.positions = rt.buffer(bytes_of(scene.positions), "vertex positions", CL_MEM_READ_ONLY);
  rt.write(m.positions, scene.positions.data(), bytes_of(scene.positions));
  m.attrs = rt.buffer(bytes_of(scene.attributes), "vertex attributes", CL_MEM_READ_ONLY);
  rt.write(m.attrs, scene.attributes.data(), bytes_of(scene.attributes));
  m.tris = rt.buffer(bytes_of(scene.triangles), "triangles", CL_MEM_READ_ONLY);
  rt.write(m.tris, scene.triangles.data(), bytes_of(scene.triangles));
  m.materials = rt.buffer(bytes_of(tables.materials), "materials", CL_MEM_READ_ONLY);
  rt.write(m.materials, tables.materials.data(), bytes_of(tables.materials));
  m.textures = rt.buffer(std::max<size_t>(bytes_of(tables.textures), 16), "texture table", CL_MEM_READ_ONLY);
  rt.write(m.textures, tables.textures.data(), bytes_of(tables.textures));
  m.texels = rt.buffer(std::max<size_t>(tables.texels.size(), 16), "texels", CL_MEM_READ_ONLY);
  rt.write(m.texels, tables.texels.data(), tables.texels.size());
  m.texcoords = rt.buffer(bytes_of(tables.texcoords), "texture coordinates", CL_MEM_READ_ONLY);
  rt.write(m.texcoords, tables.texcoords.data(), bytes_of(tables.texcoords));
  m.tangents = rt.buffer(bytes_of(tangents), "tangents", CL_MEM_READ_ONLY);
  rt.write(m.tangents, tangents.data(), bytes_of(tangents));
  m.vertices = rt.buffer(size_t(m.num_vertices) * sizeof(PmrVertex), "transformed vertices");
  if (config_.method == Method::Multipass && config_.multipass_snapped)
    m.pmr_vertices = rt.buffer(size_t(m.num_vertices) * sizeof(PmrVertex), "PMR vertices");
  if (!m.mta_capacity_fixed || m.mta_capacity == 0) {
    // Most triangles become one MTA; clipping and double-sided orientation splits add a few.
    m.mta_capacity = std::max<uint32_t>(1024, m.num_triangles + m.num_triangles / 4);
    m.mtas = ClBuffer();
  }
}

void Pipeline::update_geometry(const Scene& posed) {
  Impl& m = *impl_;
  if (posed.positions.size() != m.num_vertices || posed.triangles.size() != m.num_triangles ||
      posed.attributes.size() != posed.positions.size())
    throw Error("update_geometry: the posed scene does not match the scene given to set_scene");
  if (posed.triangles.empty()) return;
  m.rt.write(m.positions, posed.positions.data(), bytes_of(posed.positions));
  m.rt.write(m.attrs, posed.attributes.data(), bytes_of(posed.attributes));
  m.rt.write(m.tris, posed.triangles.data(), bytes_of(posed.triangles));
  if (m.has_tangents && posed.tangents.size() == posed.positions.size())
    m.rt.write(m.tangents, posed.tangents.data(), bytes_of(posed.tangents));
}

FrameDescription describe_frame(const Rig& rig, const std::vector<SceneLight>& scene_lights,
                                const PipelineConfig& config) {
  FrameDescription f;
  f.rig = rig;
  if (config.shading == Shading::Pbr) f.lights = resolve_lights(scene_lights, rig, !config.environment);
  return f;
}

size_t Pipeline::volume_bytes() const {
  const PmrParams& p = impl_->params;
  return size_t(p.views) * p.view_w * p.view_h * 4 * sizeof(uint16_t);
}

size_t Pipeline::display_bytes() const {
  return impl_->encode ? size_t(impl_->encode_params.display_w) * impl_->encode_params.display_h * 4 * sizeof(uint16_t) : 0;
}

void Pipeline::configure(const Rig& rig, const Display* display) {
  Impl& m = *impl_;
  const ClRuntime& rt = m.rt;
  m.params = make_params(rig);
  tiles_x_ = (rig.view_w + tile_[0] - 1) / tile_[0];
  tiles_y_ = (rig.view_h + tile_[1] - 1) / tile_[1];
  // multipass rasterizes one view per pass, so its tile grid is one view deep
  const int pass_views = config_.method == Method::Multipass ? 1 : rig.views;
  tiles_v_ = (pass_views + tile_[2] - 1) / tile_[2];
  m.num_tiles = uint64_t(tiles_x_) * tiles_y_ * tiles_v_;
  if (m.num_tiles >= (uint64_t(1) << 32)) throw Error("too many tiles; use larger --tile");
  m.encode = display != nullptr;
  m.subpixel = config_.sampling == Sampling::Subpixel;
  if (m.subpixel) {
    if (!display) throw Error("--sampling subpixel samples a display's subpixels: it needs a display");
    check_subpixel_sampling(config_.method, *display);
  }
  const int lanes = fine_lanes(tile_[0]);
  const size_t fused_private = size_t(tile_[0] + lanes - 1) / lanes * lanes * tile_[1] * rig.views * 20;
  m.fused = !m.subpixel && config_.fuse_encode && display && !display->bilinear && !display->blend_views &&
            display->cell_rows <= 1 && config_.method == Method::Pmr && !config_.debug_outputs &&
            fused_private <= kFusedPrivateBudget;
  m.keep_volume = !m.fused && !(m.subpixel && config_.fuse_encode);
  m.subpixel_debug = m.subpixel && !m.keep_volume && config_.debug_outputs;
  if (display) {
    m.encode_params = make_encode_params(*display, rig.views, rig.view_w, rig.view_h);
    std::vector<PmrEncodeColumn> columns;
    std::vector<PmrEncodeRow> rows;
    make_encode_tables(*display, m.encode_params, columns, rows);
    if (m.fused) m.configure_fused(build_options_, rig.views, tile_[0], columns, rows);
    if (m.subpixel) m.configure_subpixel(build_options_, rig.views, tile_, columns, rows);
    m.encode_columns = rt.buffer(bytes_of(columns), "encoder columns", CL_MEM_READ_ONLY);
    rt.write(m.encode_columns, columns.data(), bytes_of(columns));
    m.encode_rows = rt.buffer(bytes_of(rows), "encoder rows", CL_MEM_READ_ONLY);
    rt.write(m.encode_rows, rows.data(), bytes_of(rows));
  }

  const size_t vol = m.keep_volume ? volume_bytes() : 0;
  const size_t disp = display_bytes() + display_bytes() / 4 * 3;  // RGBA and the subpixels' alpha
  const size_t voxels = size_t(rig.views) * rig.view_w * rig.view_h;
  m.debug_entries = !config_.debug_outputs ? 1 : m.keep_volume ? voxels : size_t(3) * display->width * display->height;
  const size_t dbg = config_.debug_outputs ? m.debug_entries * 12 : 0;
  if (vol + disp + dbg > rt.global_mem_bytes())
    throw Error("the view volume (" + std::to_string(vol >> 20) + " MiB) and display image (" +
                std::to_string(disp >> 20) + " MiB) do not fit in the device's memory (" +
                std::to_string(rt.global_mem_bytes() >> 20) + " MiB)");
  m.volume = rt.buffer(std::max<size_t>(vol, 16), "view volume");
  m.display = rt.buffer(std::max<size_t>(display_bytes(), 16), "display image");
  m.sub_alpha = rt.buffer(std::max<size_t>(display_bytes() / 4 * 3, 16), "display subpixel alpha");
  m.tile_counts = rt.buffer(size_t(m.num_tiles + 1) * sizeof(uint32_t), "tile counters");
  rt.fill_zero(m.tile_counts);
  m.tile_offsets = rt.buffer(size_t(m.num_tiles + 1) * sizeof(uint32_t), "tile offsets");
  m.dbg_key = rt.buffer(m.debug_entries * 4, "debug keys");
  m.dbg_depth = rt.buffer(m.debug_entries * 4, "debug depth");
  m.dbg_count = rt.buffer(m.debug_entries * 4, "debug counts");
  if (m.subpixel_debug) rt.fill_zero(m.dbg_count);  // the subpixel kernel keeps no counts
  if (m.tile_queue_capacity == 0) {
    m.tile_queue_capacity = std::max<size_t>(4096, size_t(m.mta_capacity) * 8);
    m.tile_queue = rt.buffer(m.tile_queue_capacity * sizeof(uint32_t), "tile queues");
  }
  rt.finish();
  build_kernels(rig);
}

// PoCL compiles a kernel's work-group function when a launch first needs it (and caches it on disk):
// seconds per function on a cold cache. One frame with nothing in it, each launch a single work-group
// of its real local size, compiles every function the configuration will use before the first frame.
void Pipeline::build_kernels(const Rig& rig) {
  Impl& m = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  m.warming = true;
  m.variants.clear();
  try {
    render(rig);
  } catch (...) {
    m.warming = false;
    throw;
  }
  m.warming = false;
  m.build_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double Pipeline::kernel_build_seconds() const { return impl_->build_seconds; }
const std::vector<std::string>& Pipeline::kernel_variants() const { return impl_->variants; }

void Pipeline::set_mta_capacity(uint32_t capacity) {
  impl_->mta_capacity = std::max<uint32_t>(1, capacity);
  impl_->mta_capacity_fixed = true;
  impl_->mtas = ClBuffer();
}

void Pipeline::Impl::vertex_stage(const PmrParams& P, Events& ev) {
  rt.write(params_buf, &P, sizeof P);
  k_vertex.args(params_buf, positions, vertices);
  ev.add(kVertex, launch(k_vertex, num_vertices, kItemGroup));
}

void Pipeline::Impl::select_view_stage(const PmrParams& P, int coord, Events& ev) {
  rt.write(params_buf, &P, sizeof P);
  k_vertex_select.args(params_buf, pmr_vertices, coord, vertices);
  ev.add(kVertex, launch(k_vertex_select, num_vertices, kItemGroup));
}

// Primitive setup, redone with a larger MTA queue until everything fits (never drops work).
void Pipeline::Impl::setup_stage(PmrParams& P, Events& ev, StageTimes& t) {
  for (;;) {
    if (!mtas.get()) mtas = rt.buffer(size_t(mta_capacity) * sizeof(PmrMta), "MTA queue");
    P.mta_capacity = mta_capacity;
    rt.write(params_buf, &P, sizeof P);
    const uint32_t zero = 0;
    rt.write(mta_counter, &zero, sizeof zero);
    k_setup.args(params_buf, tris, vertices, materials, mtas, mta_counter);
    ev.add(kSetup, launch(k_setup, num_triangles, kItemGroup));
    rt.read(mta_counter, &last_mtas, sizeof last_mtas);
    if (last_mtas <= mta_capacity) break;
    const uint64_t grown = uint64_t(last_mtas) + last_mtas / 4 + 64;
    if (grown * sizeof(PmrMta) > rt.max_alloc_bytes())
      throw Error("the scene produces " + std::to_string(last_mtas) + " multi-view triangles, more than the device can hold");
    mta_capacity = uint32_t(std::min<uint64_t>(grown, 0xffffffffu));
    mtas = ClBuffer();
    ++t.retries;
  }
  t.mtas += last_mtas;
}

// Tile raster: count entries per tile, exclusive scan on the host (sizes the queue), fill.
void Pipeline::Impl::bin_stage(Events& ev, StageTimes& t) {
  k_bin_count.args(params_buf, mtas, last_mtas, tile_counts);
  ev.add(kBin, launch(k_bin_count, last_mtas, kItemGroup));
  std::vector<uint32_t> counts(num_tiles + 1);
  rt.read(tile_counts, counts.data(), size_t(num_tiles) * 4);
  uint64_t total = 0;
  for (uint64_t i = 0; i < num_tiles; ++i) {
    const uint32_t c = counts[i];
    counts[i] = uint32_t(total);
    total += c;
    if (total >= 0xffffffffull) throw Error("the tile queues would exceed 4 G entries; use larger --tile or fewer views");
  }
  if (t.bin_entries + total > tile_queue_limit)  // (multipass: every pass of the frame counts)
    throw Error("the frame's tile raster produces " + std::to_string(t.bin_entries + total) + " tile-queue entries, more than the "
                "tile-queue limit of " + std::to_string(tile_queue_limit) + " (raise it with --limit tile-queue=N)");
  counts[num_tiles] = uint32_t(total);
  rt.write(tile_offsets, counts.data(), bytes_of(counts));
  if (total > tile_queue_capacity) {
    const size_t grown = size_t(total) + size_t(total) / 4;
    if (grown * 4 > rt.max_alloc_bytes())
      throw Error("the tile queues need " + std::to_string((total * 4) >> 20) + " MiB, more than the device can hold; use larger --tile");
    tile_queue = ClBuffer();
    tile_queue = rt.buffer(grown * 4, "tile queues");
    tile_queue_capacity = grown;
  }
  t.bin_entries += total;
  k_bin_fill.args(params_buf, mtas, last_mtas, tile_counts, tile_offsets, tile_queue);
  ev.add(kBin, launch(k_bin_fill, last_mtas, kItemGroup));
}

// Waits for the frame's last command, calling `report` every `interval` seconds once the frame has
// run that long. The event's completion callback wakes the wait, so a fast frame waits no longer than
// finish() would.
void Pipeline::Impl::wait_reporting(const Events& ev, const StageTimes& t, std::chrono::steady_clock::time_point start,
                                    double interval, const std::function<void(double, uint64_t)>& report) {
  const auto step = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(interval));
  if (ev.all.empty()) return;
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
  if (clSetEventCallback(ev.all.back().second, CL_COMPLETE, complete, &d) != CL_SUCCESS) return;  // finish() waits
  clFlush(rt.queue());
  std::unique_lock<std::mutex> lock(d.mutex);
  auto next = start + step;
  while (!d.changed.wait_until(lock, next, [&] { return d.done; })) {
    report(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), t.bin_entries);
    next += step;
  }
}

void Pipeline::Impl::fine_stage(Events& ev) {
  k_fine.args(params_buf, mtas, tile_offsets, tile_queue, tris, attrs, materials, textures, texels, lut, positions, eyes, split_sum, texcoords, tangents, volume,
              dbg_key, dbg_depth, dbg_count, env, env_data, lights);
  ev.add(kFine, launch(k_fine, size_t(num_tiles), kFineGroup));
}

void Pipeline::Impl::encode_stage(Events& ev) {
  const PmrEncodeParams nothing{};  // warming: a display of 0 x 0
  rt.write(encode_buf, warming ? &nothing : &encode_params, sizeof encode_params);
  ClKernel& k = encode_params.blend ? k_encode_blend : encode_params.bilinear ? k_encode_bilinear : k_encode;
  k.args(encode_buf, encode_columns, encode_rows, volume, display, sub_alpha);
  const size_t runs = (size_t(encode_params.display_w) + PMR_ENCODE_RUN - 1) / PMR_ENCODE_RUN;
  ev.add(kEncode, launch_2d(k, runs, size_t(encode_params.display_h), 8, 1));
}

// Tables of the fused path: the first subpixel of every view column and the first display row of every
// view row (the encoder's maps are monotone), and the display columns whose three subpixels belong to
// different screen tiles, each with a slot in the coverage buffer their alpha is computed from.
void Pipeline::Impl::configure_fused(const std::string& options, int views, int tile_x,
                                     const std::vector<PmrEncodeColumn>& columns, const std::vector<PmrEncodeRow>& rows) {
  if (fused_views != views) {
    if (fused_program) clReleaseProgram(fused_program);
    fused_program = build({"fine_encode.cl", "straddle_alpha.cl"}, options + " -DPMR_FUSED_VIEWS=" + std::to_string(views));
    fused_views = views;
    k_fine_encode = ClKernel(fused_program, "fine_encode");
    k_straddle_alpha = ClKernel(fused_program, "encode_straddle_alpha");
  }
  const PmrEncodeParams& E = encode_params;
  const TileOwnership own = tile_ownership(E, columns, rows, tile_x);
  upload_table(column_start, own.column_start, "fused column starts");
  upload_table(row_start, own.row_start, "fused row starts");
  upload_straddles(own);
  // the fused kernel's column table, as planes for 8-pixel vector loads: [field (a_mod_n, b, px)][subpixel k][pixel j]
  const size_t W = size_t(E.display_w);
  std::vector<int32_t> soa(9 * W);
  for (size_t j = 0; j < W; ++j)
    for (size_t k = 0; k < 3; ++k) {
      const PmrEncodeColumn& c = columns[3 * j + k];
      soa[(0 + k) * W + j] = c.a_mod_n, soa[(3 + k) * W + j] = c.b, soa[(6 + k) * W + j] = c.px;
    }
  column_soa = rt.buffer(bytes_of(soa), "fused column planes", CL_MEM_READ_ONLY);
  rt.write(column_soa, soa.data(), bytes_of(soa));
}

// The straddling pixels' slots and coverage bytes (fused and subpixel paths).
void Pipeline::Impl::upload_straddles(const TileOwnership& own) {
  upload_table(straddle_slot, own.straddle_slot, "straddle slots");
  upload_table(straddle_columns, own.straddling, "straddle columns");
  straddle_slots = uint32_t(own.straddling.size());
  straddle_cov = rt.buffer(std::max<size_t>(size_t(straddle_slots) * encode_params.display_h * 3, 16), "straddle coverage");
}

// The subpixel program (per view count: its private per-view arrays) and the chunk list.
void Pipeline::Impl::configure_subpixel(const std::string& options, int views, const int* tile,
                                        const std::vector<PmrEncodeColumn>& columns,
                                        const std::vector<PmrEncodeRow>& rows) {
  const int capacity = subpixel_chunk_capacity(views);
  if (subpixel_views != views) {
    if (subpixel_program) clReleaseProgram(subpixel_program);
    subpixel_program = build({"fine_subpixel.cl", "straddle_alpha.cl"},
                                        options + " -DPMR_SUBPIXEL_VIEWS=" + std::to_string(views) +
                                            " -DPMR_SUBPIXEL_CAP=" + std::to_string(capacity) +
                                            " -DPMR_SUBPIXEL_SLOTS=" + std::to_string(kSubpixelSlots));
    subpixel_views = views;
    k_fine_subpixel = ClKernel(subpixel_program, "fine_subpixel");
    k_subpixel_straddle = ClKernel(subpixel_program, "encode_straddle_alpha");
  }
  const TileOwnership own = tile_ownership(encode_params, columns, rows, tile[0]);
  upload_straddles(own);
  // the column table's a_mod_n and b as planes, for 8-column vector loads (8 entries of slack at the end)
  std::vector<int32_t> a(columns.size() + 8), b(columns.size() + 8);
  for (size_t s = 0; s < columns.size(); ++s) a[s] = columns[s].a_mod_n, b[s] = columns[s].b;
  upload_table(column_a, a, "subpixel column views");
  upload_table(column_b, b, "subpixel column ranks");
  // the samples must lie in the view pixels the encoder tables name (tile ownership relies on it)
  const std::vector<int32_t> xs = subpixel_sample_columns(encode_params), ys = subpixel_sample_rows(encode_params);
  for (size_t s = 0; s < xs.size(); ++s)
    if (xs[s] >> PMR_X_FRAC_BITS != columns[s].px) throw Error("internal error: subpixel sample outside its column");
  for (size_t i = 0; i < ys.size(); ++i)
    if (ys[i] >> PMR_Y_FRAC_BITS != rows[i].py) throw Error("internal error: subpixel sample outside its row");
  upload_table(sample_x, xs, "subpixel sample columns");
  upload_table(sample_y, ys, "subpixel sample rows");
  const std::vector<PmrSampleChunk> list = subpixel_chunks(own, tile[0], tile[1], capacity);
  num_chunks = uint32_t(list.size());
  chunks = rt.buffer(std::max<size_t>(bytes_of(list), 16), "subpixel chunks", CL_MEM_READ_ONLY);
  rt.write(chunks, list.data(), bytes_of(list));
}

void Pipeline::Impl::straddle_alpha_stage(ClKernel& k, Events& ev) {
  if (straddle_slots == 0) return;
  k.args(encode_buf, straddle_columns, warming ? 0u : straddle_slots, straddle_cov, display);
  ev.add(kEncode, launch_2d(k, straddle_slots, size_t(encode_params.display_h), 1, 8));
}

void Pipeline::Impl::subpixel_stage(Events& ev) {
  rt.write(encode_buf, &encode_params, sizeof encode_params);
  k_fine_subpixel.args(params_buf, mtas, tile_offsets, tile_queue, tris, attrs, materials, textures, texels, lut, positions, eyes, split_sum, texcoords, tangents,
                       encode_buf, column_a, column_b, encode_rows, sample_x, sample_y, chunks, warming ? 0u : num_chunks,
                       straddle_slot, straddle_slots,
                       straddle_cov, display, sub_alpha, cl_uint(subpixel_debug), dbg_key, dbg_depth, env, env_data, lights);
  ev.add(kFine, launch(k_fine_subpixel, num_chunks, 1));
  straddle_alpha_stage(k_subpixel_straddle, ev);
}

void Pipeline::Impl::fused_stage(const PmrParams& P, Events& ev) {
  rt.write(encode_buf, &encode_params, sizeof encode_params);
  k_fine_encode.args(params_buf, mtas, tile_offsets, tile_queue, tris, attrs, materials, textures, texels, lut, positions, eyes, split_sum, texcoords, tangents,
                     encode_buf, column_soa, encode_rows, column_start, row_start, straddle_slot, straddle_slots,
                     straddle_cov, display, sub_alpha, env, env_data, lights);
  const size_t screen_tiles = size_t(P.tiles_x) * P.tiles_y;
  ev.add(kFine, launch(k_fine_encode, screen_tiles, 1));
  straddle_alpha_stage(k_straddle_alpha, ev);
}

StageTimes Pipeline::render(const Rig& rig) { return render(describe_frame(rig, impl_->scene_lights, config_)); }

// The kernels' parameters of one frame: everything the frame's rig gives (make_params), then what the
// configuration fixes for the run.
PmrParams Pipeline::frame_params(const FrameDescription& frame) const {
  const Impl& m = *impl_;
  const Rig& rig = frame.rig;
  if (rig.views != m.params.views || rig.view_w != m.params.view_w || rig.view_h != m.params.view_h)
    throw Error("internal error: a frame's rig differs in size from the configured one");
  PmrParams P = make_params(rig);
  P.tiles_x = tiles_x_;
  P.tiles_y = tiles_y_;
  P.tiles_v = tiles_v_;
  P.num_vertices = m.num_vertices;
  P.num_triangles = m.num_triangles;
  P.debug_outputs = config_.debug_outputs ? 1u : 0u;
  P.setup_mode = config_.method == Method::Duplicate ? PMR_SETUP_DUPLICATE : PMR_SETUP_MTA;
  P.sample_area = m.subpixel ? PMR_SAMPLES_PIXEL : PMR_SAMPLES_CENTER;
  P.shading = config_.shading == Shading::Pbr ? PMR_SHADING_PBR : PMR_SHADING_LAMBERT;
  P.exposure = float(std::exp2(config_.exposure_ev));
  P.env_radiance = float(0.2 * config_.environment_intensity);
  P.num_lights = uint32_t(frame.lights.size());
  return P;
}

// The frame's light table and each view's camera position in world space (the view vector of pbr).
void Pipeline::Impl::upload_frame(const FrameDescription& frame) {
  std::vector<PmrLight> table;
  for (const SceneLight& l : frame.lights) table.push_back(device_light(l));
  table.resize(std::max<size_t>(table.size(), 1));  // no empty buffers
  if (lights.size() != bytes_of(table)) lights = rt.buffer(bytes_of(table), "lights", CL_MEM_READ_ONLY);
  rt.write(lights, table.data(), bytes_of(table));
  const Rig& rig = frame.rig;
  std::vector<glm::vec4> at(size_t(rig.views));
  for (int i = 0; i < rig.views; ++i) at[size_t(i)] = glm::vec4(glm::vec3(glm::inverse(rig.view_matrix(i))[3]), 1.0f);
  if (eyes.size() != bytes_of(at)) eyes = rt.buffer(bytes_of(at), "camera positions", CL_MEM_READ_ONLY);
  rt.write(eyes, at.data(), bytes_of(at));
}

StageTimes Pipeline::render(const FrameDescription& frame) {
  Impl& m = *impl_;
  const auto t_start = std::chrono::steady_clock::now();
  if (!m.volume.get()) throw Error("internal error: Pipeline::render before configure");
  const Rig& rig = frame.rig;
  StageTimes times;
  Events ev;
  PmrParams P = frame_params(frame);
  m.upload_frame(frame);
  if (m.warming) P.num_vertices = P.num_triangles = 0, P.tiles_x = P.tiles_y = P.tiles_v = 0;  // an empty frame

  if (config_.method != Method::Multipass) {
    m.vertex_stage(P, ev);
    m.setup_stage(P, ev, times);
    m.bin_stage(ev, times);
    if (m.fused) m.fused_stage(P, ev);
    if (m.keep_volume) m.fine_stage(ev);
    if (m.subpixel) m.subpixel_stage(ev);
  } else {
    if (config_.multipass_snapped) {  // test mode: PMR's vertex records, computed once
      m.vertex_stage(P, ev);
      std::swap(m.vertices, m.pmr_vertices);
    }
    // One conventional pass per view with view i's own view matrix and off-axis projection:
    // x_ndc = (D / a) x_view / w + s_i / a in camera i's view space.
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
      if (config_.multipass_snapped)
        m.select_view_stage(Q, rig.view_coord(i), ev);
      else
        m.vertex_stage(Q, ev);
      m.setup_stage(Q, ev, times);
      m.bin_stage(ev, times);
      m.fine_stage(ev);
    }
    if (config_.multipass_snapped) std::swap(m.vertices, m.pmr_vertices);
  }
  if (m.encode && !m.fused && !m.subpixel) m.encode_stage(ev);
  if (config_.slow_frame && !m.warming) m.wait_reporting(ev, times, t_start, config_.slow_frame_seconds, config_.slow_frame);
  m.rt.finish();
  ev.collect(times);
  times.wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_start).count();
  return times;
}

StageTimes Pipeline::encode_volume(const std::vector<uint16_t>& volume) {
  Impl& m = *impl_;
  if (!m.encode || m.fused || m.subpixel) throw Error("internal error: no display configured, or a path without an encoder");
  if (volume.size() * 2 != volume_bytes()) throw Error("internal error: volume size mismatch");
  m.rt.write(m.volume, volume.data(), volume_bytes());
  Events ev;
  m.encode_stage(ev);
  m.rt.finish();
  StageTimes t;
  ev.collect(t);
  return t;
}

bool Pipeline::fused() const { return impl_->fused; }
bool Pipeline::has_volume() const { return impl_->keep_volume; }

void Pipeline::read_volume(std::vector<uint16_t>& out) const {
  if (!impl_->keep_volume) throw Error("internal error: this configuration keeps no view volume");
  out.resize(volume_bytes() / 2);
  impl_->rt.read(impl_->volume, out.data(), volume_bytes());
}

void Pipeline::read_display(std::vector<uint16_t>& out) const {
  if (!impl_->encode) throw Error("internal error: no display configured");
  out.resize(display_bytes() / 2);
  impl_->rt.read(impl_->display, out.data(), display_bytes());
}

void Pipeline::read_sub_alpha(std::vector<uint16_t>& out) const {
  if (!impl_->encode) throw Error("internal error: no display configured");
  out.resize(display_bytes() / 8 * 3);
  impl_->rt.read(impl_->sub_alpha, out.data(), display_bytes() / 4 * 3);
}

void Pipeline::read_debug(std::vector<uint32_t>& keys, std::vector<float>& depth, std::vector<uint32_t>& count) const {
  if (!config_.debug_outputs) throw Error("internal error: debug outputs are off");
  const size_t n = impl_->debug_entries;
  keys.resize(n);
  depth.resize(n);
  count.resize(n);
  impl_->rt.read(impl_->dbg_key, keys.data(), n * 4);
  impl_->rt.read(impl_->dbg_depth, depth.data(), n * 4);
  impl_->rt.read(impl_->dbg_count, count.data(), n * 4);
}

size_t Pipeline::device_bytes() const {
  const Impl& m = *impl_;
  size_t total = 0;
  for (const ClBuffer* b : {&m.positions, &m.attrs, &m.tris, &m.materials, &m.textures, &m.texels, &m.lut, &m.params_buf,
                            &m.encode_buf, &m.vertices, &m.pmr_vertices, &m.mtas, &m.mta_counter, &m.tile_counts,
                            &m.tile_offsets, &m.tile_queue, &m.volume, &m.display, &m.sub_alpha, &m.encode_columns, &m.encode_rows, &m.dbg_key, &m.dbg_depth, &m.dbg_count,
                            &m.column_start, &m.column_soa, &m.row_start, &m.straddle_slot, &m.straddle_columns, &m.straddle_cov,
                            &m.chunks, &m.sample_x, &m.sample_y, &m.column_a, &m.column_b, &m.eyes, &m.split_sum, &m.env, &m.env_data,
                            &m.lights})
    total += b->get() ? b->size() : 0;
  return total;
}

std::vector<PmrMta> Pipeline::read_mtas() const {
  std::vector<PmrMta> out(impl_->last_mtas);
  impl_->rt.read(impl_->mtas, out.data(), bytes_of(out));
  return out;
}

void Pipeline::read_tile_queues(std::vector<uint32_t>& offsets, std::vector<uint32_t>& queue) const {
  offsets.resize(impl_->num_tiles + 1);
  impl_->rt.read(impl_->tile_offsets, offsets.data(), bytes_of(offsets));
  queue.resize(offsets.back());
  impl_->rt.read(impl_->tile_queue, queue.data(), bytes_of(queue));
}

std::vector<PmrVertex> Pipeline::read_vertices() const {
  std::vector<PmrVertex> out(impl_->num_vertices);
  impl_->rt.read(impl_->vertices, out.data(), bytes_of(out));
  return out;
}

}  // namespace pmr
