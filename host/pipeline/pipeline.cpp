#include "pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "pmr/error.h"

namespace pmr {

namespace {

// RAII for the profiling events of one frame.
struct Events {
  std::vector<cl_event> all;
  cl_event add(cl_event e) {
    all.push_back(e);
    return e;
  }
  ~Events() {
    for (cl_event e : all) clReleaseEvent(e);
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
  ClKernel k_vertex, k_setup, k_bin_count, k_bin_fill, k_fine, k_encode;

  // scene
  uint32_t num_vertices = 0, num_triangles = 0;
  ClBuffer positions, attrs, tris, materials, textures, texels, lut;
  // frame
  PmrParams params{};
  PmrEncodeParams encode_params{};
  bool encode = false;
  ClBuffer params_buf, encode_buf, vertices, mtas, mta_counter;
  uint32_t mta_capacity = 0;
  bool mta_capacity_fixed = false;
  ClBuffer tile_counts, tile_offsets, tile_queue;
  size_t tile_queue_capacity = 0;
  ClBuffer volume, display;
  ClBuffer dbg_key, dbg_depth, dbg_count;
  uint32_t last_mtas = 0;
  uint64_t num_tiles = 0;

  explicit Impl(const ClRuntime& r) : rt(r) {}

  // Stage 5: interleaves the view volume into the display image.
  cl_event launch_encode(Events& ev) {
    rt.write(encode_buf, &encode_params, sizeof encode_params);
    k_encode.arg(0, encode_buf);
    k_encode.arg(1, volume);
    k_encode.arg(2, display);
    return ev.add(rt.launch(k_encode, size_t(encode_params.display_w) * encode_params.display_h, 0));
  }
  ~Impl() {
    if (program) clReleaseProgram(program);
  }
};

Pipeline::Pipeline(const ClRuntime& runtime, const PipelineConfig& config)
    : impl_(new Impl(runtime)), config_(config) {
  const int tx = config.tile_x, ty = config.tile_y, tv = config.tile_v;
  if (tx < 1 || ty < 1 || tv < 1 || tx > 64 || ty > 64 || tv > 64)
    throw Error("invalid --tile: each tile side must be 1..64");
  if (size_t(tx) * ty * tv > runtime.max_work_group_size())
    throw Error("invalid --tile " + std::to_string(tx) + "x" + std::to_string(ty) + "x" + std::to_string(tv) +
                ": " + std::to_string(tx * ty * tv) + " voxels exceed the device's work-group limit of " +
                std::to_string(runtime.max_work_group_size()));
  const std::string options = "-cl-std=CL1.2 -cl-fp32-correctly-rounded-divide-sqrt -DPMR_TILE_X=" +
                              std::to_string(tx) + " -DPMR_TILE_Y=" + std::to_string(ty) +
                              " -DPMR_TILE_V=" + std::to_string(tv);
  Impl& m = *impl_;
  m.program = runtime.build_program({"vertex.cl", "setup.cl", "bin.cl", "fine.cl", "encode.cl"}, options);
  m.k_vertex = ClKernel(m.program, "vertex_transform");
  m.k_setup = ClKernel(m.program, "setup_triangles");
  m.k_bin_count = ClKernel(m.program, "bin_count");
  m.k_bin_fill = ClKernel(m.program, "bin_fill");
  m.k_fine = ClKernel(m.program, "fine_raster");
  m.k_encode = ClKernel(m.program, "encode_display");
  m.params_buf = runtime.buffer(sizeof(PmrParams), "frame parameters", CL_MEM_READ_ONLY);
  m.encode_buf = runtime.buffer(sizeof(PmrEncodeParams), "encoder parameters", CL_MEM_READ_ONLY);
  m.mta_counter = runtime.buffer(sizeof(uint32_t), "MTA counter");
  const auto lut = srgb_lut();
  m.lut = runtime.buffer(bytes_of(lut), "sRGB table", CL_MEM_READ_ONLY);
  runtime.write(m.lut, lut.data(), bytes_of(lut));
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
  std::vector<PmrTexture> tex_table;
  size_t total_texels = 0;
  for (const auto& t : scene.textures) {
    PmrTexture d{};
    d.offset = uint32_t(total_texels);
    d.width = t.width;
    d.height = t.height;
    d.wrap_s = t.wrap_s;
    d.wrap_t = t.wrap_t;
    tex_table.push_back(d);
    total_texels += size_t(t.width) * t.height;
  }
  if (total_texels >= (size_t(1) << 32)) throw Error("the scene's textures are too large (over 4 G texels)");
  std::vector<uint8_t> texels(total_texels * 4);
  for (size_t i = 0; i < scene.textures.size(); ++i)
    std::copy(scene.textures[i].rgba.begin(), scene.textures[i].rgba.end(), texels.begin() + size_t(tex_table[i].offset) * 4);

  m.positions = rt.buffer(bytes_of(scene.positions), "vertex positions", CL_MEM_READ_ONLY);
  rt.write(m.positions, scene.positions.data(), bytes_of(scene.positions));
  m.attrs = rt.buffer(bytes_of(scene.attributes), "vertex attributes", CL_MEM_READ_ONLY);
  rt.write(m.attrs, scene.attributes.data(), bytes_of(scene.attributes));
  m.tris = rt.buffer(bytes_of(scene.triangles), "triangles", CL_MEM_READ_ONLY);
  rt.write(m.tris, scene.triangles.data(), bytes_of(scene.triangles));
  m.materials = rt.buffer(bytes_of(scene.materials), "materials", CL_MEM_READ_ONLY);
  rt.write(m.materials, scene.materials.data(), bytes_of(scene.materials));
  m.textures = rt.buffer(bytes_of(tex_table), "texture table", CL_MEM_READ_ONLY);
  rt.write(m.textures, tex_table.data(), bytes_of(tex_table));
  m.texels = rt.buffer(texels.size(), "texels", CL_MEM_READ_ONLY);
  rt.write(m.texels, texels.data(), texels.size());
  m.vertices = rt.buffer(size_t(m.num_vertices) * sizeof(PmrVertex), "transformed vertices");
  if (!m.mta_capacity_fixed || m.mta_capacity == 0) {
    // Most triangles become one MTA; clipping and double-sided orientation splits add a few.
    m.mta_capacity = std::max<uint32_t>(1024, m.num_triangles + m.num_triangles / 4);
    m.mtas = ClBuffer();
  }
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
  tiles_x_ = (rig.view_w + config_.tile_x - 1) / config_.tile_x;
  tiles_y_ = (rig.view_h + config_.tile_y - 1) / config_.tile_y;
  tiles_v_ = (rig.views + config_.tile_v - 1) / config_.tile_v;
  m.num_tiles = uint64_t(tiles_x_) * tiles_y_ * tiles_v_;
  if (m.num_tiles >= (uint64_t(1) << 32)) throw Error("too many tiles; use larger --tile");
  m.encode = display != nullptr;
  if (display) m.encode_params = make_encode_params(*display, rig.views, rig.view_w, rig.view_h);

  const size_t vol = volume_bytes();
  const size_t disp = display_bytes();
  const size_t dbg = config_.debug_outputs ? size_t(rig.views) * rig.view_w * rig.view_h * 12 : 0;
  if (vol + disp + dbg > rt.global_mem_bytes())
    throw Error("the view volume (" + std::to_string(vol >> 20) + " MiB) and display image (" +
                std::to_string(disp >> 20) + " MiB) do not fit in the device's memory (" +
                std::to_string(rt.global_mem_bytes() >> 20) + " MiB)");
  m.volume = rt.buffer(vol, "view volume");
  m.display = rt.buffer(std::max<size_t>(disp, 16), "display image");
  m.tile_counts = rt.buffer(size_t(m.num_tiles + 1) * sizeof(uint32_t), "tile counters");
  rt.fill_zero(m.tile_counts);
  m.tile_offsets = rt.buffer(size_t(m.num_tiles + 1) * sizeof(uint32_t), "tile offsets");
  const size_t voxels = size_t(rig.views) * rig.view_w * rig.view_h;
  const size_t dbg_n = config_.debug_outputs ? voxels : 1;
  m.dbg_key = rt.buffer(dbg_n * 4, "debug keys");
  m.dbg_depth = rt.buffer(dbg_n * 4, "debug depth");
  m.dbg_count = rt.buffer(dbg_n * 4, "debug counts");
  if (m.tile_queue_capacity == 0) {
    m.tile_queue_capacity = std::max<size_t>(4096, size_t(m.mta_capacity) * 8);
    m.tile_queue = rt.buffer(m.tile_queue_capacity * sizeof(uint32_t), "tile queues");
  }
  rt.finish();
}

void Pipeline::set_mta_capacity(uint32_t capacity) {
  impl_->mta_capacity = std::max<uint32_t>(1, capacity);
  impl_->mta_capacity_fixed = true;
  impl_->mtas = ClBuffer();
}

StageTimes Pipeline::render(const Rig& rig) {
  Impl& m = *impl_;
  const ClRuntime& rt = m.rt;
  const auto t_start = std::chrono::steady_clock::now();
  if (!m.volume.get()) throw Error("internal error: Pipeline::render before configure");
  StageTimes times;
  Events ev;

  PmrParams& P = m.params;
  const PmrParams fresh = make_params(rig);
  std::copy(fresh.view, fresh.view + 16, P.view);
  std::copy(fresh.light_world, fresh.light_world + 4, P.light_world);
  P.tiles_x = tiles_x_;
  P.tiles_y = tiles_y_;
  P.tiles_v = tiles_v_;
  P.num_vertices = m.num_vertices;
  P.num_triangles = m.num_triangles;
  P.debug_outputs = config_.debug_outputs ? 1u : 0u;

  // 1. vertex transform
  rt.write(m.params_buf, &P, sizeof P);
  m.k_vertex.arg(0, m.params_buf);
  m.k_vertex.arg(1, m.positions);
  m.k_vertex.arg(2, m.vertices);
  cl_event e_vertex = ev.add(rt.launch(m.k_vertex, m.num_vertices, 0));

  // 2. primitive setup, redone with a larger MTA queue until everything fits
  uint32_t produced = 0;
  cl_event e_setup = nullptr;
  for (;;) {
    if (!m.mtas.get()) m.mtas = rt.buffer(size_t(m.mta_capacity) * sizeof(PmrMta), "MTA queue");
    P.mta_capacity = m.mta_capacity;
    rt.write(m.params_buf, &P, sizeof P);
    const uint32_t zero = 0;
    rt.write(m.mta_counter, &zero, sizeof zero);
    m.k_setup.arg(0, m.params_buf);
    m.k_setup.arg(1, m.tris);
    m.k_setup.arg(2, m.vertices);
    m.k_setup.arg(3, m.materials);
    m.k_setup.arg(4, m.mtas);
    m.k_setup.arg(5, m.mta_counter);
    e_setup = ev.add(rt.launch(m.k_setup, m.num_triangles, 0));
    rt.read(m.mta_counter, &produced, sizeof produced);
    if (produced <= m.mta_capacity) break;
    const uint64_t grown = uint64_t(produced) + produced / 4 + 64;
    if (grown * sizeof(PmrMta) > rt.max_alloc_bytes())
      throw Error("the scene produces " + std::to_string(produced) + " multi-view triangles, more than the device can hold");
    m.mta_capacity = uint32_t(std::min<uint64_t>(grown, 0xffffffffu));
    m.mtas = ClBuffer();
    ++times.retries;
  }
  m.last_mtas = produced;
  times.mtas = produced;

  // 3. tile raster: count, scan on the host, fill
  m.k_bin_count.arg(0, m.params_buf);
  m.k_bin_count.arg(1, m.mtas);
  m.k_bin_count.arg(2, produced);
  m.k_bin_count.arg(3, m.tile_counts);
  cl_event e_bin0 = ev.add(rt.launch(m.k_bin_count, produced, 0));
  std::vector<uint32_t> counts(m.num_tiles + 1);
  rt.read(m.tile_counts, counts.data(), size_t(m.num_tiles) * 4);
  uint64_t total = 0;
  for (uint64_t t = 0; t < m.num_tiles; ++t) {
    const uint32_t c = counts[t];
    counts[t] = uint32_t(total);
    total += c;
    if (total >= 0xffffffffull)
      throw Error("the tile queues would exceed 4 G entries; use larger --tile or fewer views");
  }
  counts[m.num_tiles] = uint32_t(total);
  rt.write(m.tile_offsets, counts.data(), bytes_of(counts));
  if (total > m.tile_queue_capacity) {
    const size_t grown = size_t(total) + size_t(total) / 4;
    if (grown * 4 > rt.max_alloc_bytes())
      throw Error("the tile queues need " + std::to_string((total * 4) >> 20) + " MiB, more than the device can hold; use larger --tile");
    m.tile_queue = ClBuffer();
    m.tile_queue = rt.buffer(grown * 4, "tile queues");
    m.tile_queue_capacity = grown;
  }
  times.bin_entries = total;
  m.k_bin_fill.arg(0, m.params_buf);
  m.k_bin_fill.arg(1, m.mtas);
  m.k_bin_fill.arg(2, produced);
  m.k_bin_fill.arg(3, m.tile_counts);
  m.k_bin_fill.arg(4, m.tile_offsets);
  m.k_bin_fill.arg(5, m.tile_queue);
  cl_event e_bin1 = ev.add(rt.launch(m.k_bin_fill, produced, 0));

  // 4. fine raster
  const size_t group = size_t(config_.tile_x) * config_.tile_y * config_.tile_v;
  int a = 0;
  m.k_fine.arg(a++, m.params_buf);
  m.k_fine.arg(a++, m.mtas);
  m.k_fine.arg(a++, m.tile_offsets);
  m.k_fine.arg(a++, m.tile_queue);
  m.k_fine.arg(a++, m.tris);
  m.k_fine.arg(a++, m.attrs);
  m.k_fine.arg(a++, m.materials);
  m.k_fine.arg(a++, m.textures);
  m.k_fine.arg(a++, m.texels);
  m.k_fine.arg(a++, m.lut);
  m.k_fine.arg(a++, m.volume);
  m.k_fine.arg(a++, m.dbg_key);
  m.k_fine.arg(a++, m.dbg_depth);
  m.k_fine.arg(a++, m.dbg_count);
  cl_event e_fine = ev.add(rt.launch(m.k_fine, size_t(m.num_tiles) * group, group));

  // 5. pixel encoding
  cl_event e_last = e_fine;
  if (m.encode) e_last = m.launch_encode(ev);
  rt.finish();
  if (m.encode) times.encode = event_ms(e_last);
  times.vertex = event_ms(e_vertex);
  times.setup = event_ms(e_setup);
  times.bin = event_ms(e_bin0) + event_ms(e_bin1);
  times.fine = event_ms(e_fine);
  times.device_total = event_span_ms(e_vertex, e_last);
  times.wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_start).count();
  return times;
}

StageTimes Pipeline::encode_volume(const std::vector<uint16_t>& volume) {
  Impl& m = *impl_;
  if (!m.encode) throw Error("internal error: no display configured");
  if (volume.size() * 2 != volume_bytes()) throw Error("internal error: volume size mismatch");
  m.rt.write(m.volume, volume.data(), volume_bytes());
  Events ev;
  cl_event e = m.launch_encode(ev);
  m.rt.finish();
  StageTimes t;
  t.encode = event_ms(e);
  return t;
}

void Pipeline::read_volume(std::vector<uint16_t>& out) const {
  out.resize(volume_bytes() / 2);
  impl_->rt.read(impl_->volume, out.data(), volume_bytes());
}

void Pipeline::read_display(std::vector<uint16_t>& out) const {
  if (!impl_->encode) throw Error("internal error: no display configured");
  out.resize(display_bytes() / 2);
  impl_->rt.read(impl_->display, out.data(), display_bytes());
}

void Pipeline::read_debug(std::vector<uint32_t>& keys, std::vector<float>& depth, std::vector<uint32_t>& count) const {
  if (!config_.debug_outputs) throw Error("internal error: debug outputs are off");
  const size_t n = size_t(impl_->params.views) * impl_->params.view_w * impl_->params.view_h;
  keys.resize(n);
  depth.resize(n);
  count.resize(n);
  impl_->rt.read(impl_->dbg_key, keys.data(), n * 4);
  impl_->rt.read(impl_->dbg_depth, depth.data(), n * 4);
  impl_->rt.read(impl_->dbg_count, count.data(), n * 4);
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
