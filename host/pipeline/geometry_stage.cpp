#include "pipeline/geometry_stage.h"

#include <algorithm>

#include "pipeline/pipeline.h"
#include "pmr/error.h"

namespace pmr {

namespace {

// The per-item stages run groups of 64 work-items: several per core and wide enough for 16-lane code.
constexpr size_t kItemGroup = 64;

}  // namespace

GeometryStage::GeometryStage(Launcher& launcher, const ClProgram& program, uint64_t tile_queue_limit)
    : launcher_(launcher),
      rt_(launcher.runtime()),
      vertex_(program, "vertex_transform"),
      select_view_(program, "vertex_select_view"),
      setup_(program, "setup_triangles"),
      bin_count_(program, "bin_count"),
      bin_fill_(program, "bin_fill"),
      tile_queue_limit_(tile_queue_limit) {
  params_ = rt_.buffer(sizeof(PmrParams), "frame parameters", CL_MEM_READ_ONLY);
  mta_counter_ = rt_.buffer(sizeof(uint32_t), "MTA counter");
}

void GeometryStage::set_scene(const SceneBuffers& scene, bool snapped_copy) {
  num_vertices_ = scene.num_vertices();
  vertices_ = rt_.buffer(std::max<size_t>(size_t(num_vertices_) * sizeof(PmrVertex), 1), "transformed vertices");
  snapped_ = snapped_copy ? rt_.buffer(std::max<size_t>(size_t(num_vertices_) * sizeof(PmrVertex), 1), "PMR vertices")
                          : ClBuffer();
  if (!mta_capacity_fixed_ || mta_capacity_ == 0) {
    // Most triangles become one MTA; clipping and double-sided orientation splits add a few.
    mta_capacity_ = std::max<uint32_t>(1024, scene.num_triangles() + scene.num_triangles() / 4);
    mtas_ = ClBuffer();
  }
}

void GeometryStage::configure(uint64_t num_tiles) {
  num_tiles_ = num_tiles;
  tile_counts_ = rt_.buffer(size_t(num_tiles + 1) * sizeof(uint32_t), "tile counters");
  rt_.fill_zero(tile_counts_);
  tile_offsets_ = rt_.buffer(size_t(num_tiles + 1) * sizeof(uint32_t), "tile offsets");
  if (tile_queue_capacity_ == 0) {
    tile_queue_capacity_ = std::max<size_t>(4096, size_t(mta_capacity_) * 8);
    tile_queue_ = rt_.buffer(tile_queue_capacity_ * sizeof(uint32_t), "tile queues");
  }
}

void GeometryStage::set_mta_capacity(uint32_t capacity) {
  mta_capacity_ = std::max<uint32_t>(1, capacity);
  mta_capacity_fixed_ = true;
  mtas_ = ClBuffer();
}

void GeometryStage::transform(const PmrParams& P, const SceneBuffers& scene, FrameEvents& ev) {
  rt_.write(params_, &P, sizeof P);
  vertex_.args(params_, scene.positions(), vertices_);
  ev.add(kVertex, launcher_.launch(vertex_, num_vertices_, kItemGroup));
}

void GeometryStage::swap_snapped() { std::swap(vertices_, snapped_); }

void GeometryStage::select_view(const PmrParams& P, int coord, FrameEvents& ev) {
  rt_.write(params_, &P, sizeof P);
  select_view_.args(params_, snapped_, coord, vertices_);
  ev.add(kVertex, launcher_.launch(select_view_, num_vertices_, kItemGroup));
}

void GeometryStage::setup_and_bin(PmrParams& P, const SceneBuffers& scene, FrameEvents& ev, StageTimes& t) {
  setup(P, scene, ev, t);
  bin(ev, t);
}

// Primitive setup, redone with a larger MTA queue until everything fits (never drops work).
void GeometryStage::setup(PmrParams& P, const SceneBuffers& scene, FrameEvents& ev, StageTimes& t) {
  for (;;) {
    if (!mtas_.get()) mtas_ = rt_.buffer(size_t(mta_capacity_) * sizeof(PmrMta), "MTA queue");
    P.mta_capacity = mta_capacity_;
    rt_.write(params_, &P, sizeof P);
    const uint32_t zero = 0;
    rt_.write(mta_counter_, &zero, sizeof zero);
    setup_.args(params_, scene.triangles(), vertices_, scene.materials(), mtas_, mta_counter_);
    ev.add(kSetup, launcher_.launch(setup_, scene.num_triangles(), kItemGroup));
    rt_.read(mta_counter_, &last_mtas_, sizeof last_mtas_);
    if (last_mtas_ <= mta_capacity_) break;
    const uint64_t grown = uint64_t(last_mtas_) + last_mtas_ / 4 + 64;
    if (grown * sizeof(PmrMta) > rt_.max_alloc_bytes())
      throw Error("the scene produces " + std::to_string(last_mtas_) +
                  " multi-view triangles, more than the device can hold");
    mta_capacity_ = uint32_t(std::min<uint64_t>(grown, 0xffffffffu));
    mtas_ = ClBuffer();
    ++t.retries;
  }
  t.mtas += last_mtas_;
}

// Tile raster: count entries per tile, exclusive scan on the host (sizes the queue), fill.
void GeometryStage::bin(FrameEvents& ev, StageTimes& t) {
  bin_count_.args(params_, mtas_, last_mtas_, tile_counts_);
  ev.add(kBin, launcher_.launch(bin_count_, last_mtas_, kItemGroup));
  const uint32_t total = scan_tile_counts(t);
  if (total > tile_queue_capacity_) {
    const size_t grown = size_t(total) + size_t(total) / 4;
    if (grown * 4 > rt_.max_alloc_bytes())
      throw Error("the tile queues need " + std::to_string((uint64_t(total) * 4) >> 20) +
                  " MiB, more than the device can hold; use larger --tile");
    tile_queue_ = ClBuffer();
    tile_queue_ = rt_.buffer(grown * 4, "tile queues");
    tile_queue_capacity_ = grown;
  }
  t.bin_entries += total;
  bin_fill_.args(params_, mtas_, last_mtas_, tile_counts_, tile_offsets_, tile_queue_);
  ev.add(kBin, launcher_.launch(bin_fill_, last_mtas_, kItemGroup));
}

// The tile counts' exclusive scan into the tile offsets, within the limits; returns the total.
uint32_t GeometryStage::scan_tile_counts(StageTimes& t) {
  std::vector<uint32_t> counts(num_tiles_ + 1);
  rt_.read(tile_counts_, counts.data(), size_t(num_tiles_) * 4);
  uint64_t total = 0;
  for (uint64_t i = 0; i < num_tiles_; ++i) {
    const uint32_t c = counts[i];
    counts[i] = uint32_t(total);
    total += c;
    if (total >= 0xffffffffull)
      throw Error("the tile queues would exceed 4 G entries; use larger --tile or fewer views");
  }
  if (t.bin_entries + total > tile_queue_limit_)  // (multipass: every pass of the frame counts)
    throw Error("the frame's tile raster produces " + std::to_string(t.bin_entries + total) +
                " tile-queue entries, more than the "
                "tile-queue limit of " +
                std::to_string(tile_queue_limit_) + " (raise it with --limit tile-queue=N)");
  counts[num_tiles_] = uint32_t(total);
  rt_.write(tile_offsets_, counts);
  return uint32_t(total);
}

std::vector<PmrMta> GeometryStage::read_mtas() const {
  std::vector<PmrMta> out(last_mtas_);
  rt_.read(mtas_, out.data(), out.size() * sizeof(PmrMta));
  return out;
}

void GeometryStage::read_tile_queues(std::vector<uint32_t>& offsets, std::vector<uint32_t>& queue) const {
  offsets.resize(num_tiles_ + 1);
  rt_.read(tile_offsets_, offsets.data(), offsets.size() * 4);
  queue.resize(offsets.back());
  rt_.read(tile_queue_, queue.data(), queue.size() * 4);
}

PmrParams GeometryStage::read_params() const {
  PmrParams P;
  rt_.read(params_, &P, sizeof P);
  return P;
}

std::vector<PmrVertex> GeometryStage::read_vertices() const {
  std::vector<PmrVertex> out(num_vertices_);
  rt_.read(vertices_, out.data(), out.size() * sizeof(PmrVertex));
  return out;
}

size_t GeometryStage::device_bytes() const {
  size_t total = 0;
  for (const ClBuffer* b :
       {&params_, &vertices_, &snapped_, &mtas_, &mta_counter_, &tile_counts_, &tile_offsets_, &tile_queue_})
    total += b->size();
  return total;
}

}  // namespace pmr
