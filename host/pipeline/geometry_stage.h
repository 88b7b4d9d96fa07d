// Stages 1-3 of a frame (or of a multipass pass): vertex transform, primitive setup into the MTA
// queue, and the tile raster into per-tile queues. It owns the frame parameters' buffer, the vertex
// records, the MTA queue and the tile queues, and grows the queues (redoing the stage) whenever a frame
// needs more, so no work is ever dropped.
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/launcher.h"
#include "pipeline/scene_buffers.h"
#include "pmr/shared.h"

namespace pmr {

struct StageTimes;

class GeometryStage {
 public:
  // `program`: the main program (vertex.cl, setup.cl, bin.cl). A frame whose tile raster produces more
  // than `tile_queue_limit` entries is refused (--limit tile-queue).
  GeometryStage(Launcher& launcher, const ClProgram& program, uint64_t tile_queue_limit);
  // Sizes the vertex records and the MTA queue for the scene; `snapped_copy`: keep a second set of
  // vertex records (the multipass baseline's test mode).
  void set_scene(const SceneBuffers& scene, bool snapped_copy);
  // The tile grid's size (tiles over x, y and view slabs).
  void configure(uint64_t num_tiles);
  // Fixes the MTA queue's capacity (tests of the grow-and-redo path).
  void set_mta_capacity(uint32_t capacity);

  // Writes the parameters P and transforms every vertex.
  void transform(const PmrParams& P, const SceneBuffers& scene, FrameEvents& ev);
  // The multipass test mode: view `coord`'s snapped positions taken from the kept PMR vertex records.
  void swap_snapped();  // after transform(): the records become the kept copy, and back after the passes
  void select_view(const PmrParams& P, int coord, FrameEvents& ev);
  // Setup (redone with a larger MTA queue until the frame fits) and the tile raster.
  void setup_and_bin(PmrParams& P, const SceneBuffers& scene, FrameEvents& ev, StageTimes& t);

  const ClBuffer& params() const { return params_; }
  PmrParams read_params() const;  // the last frame's
  const ClBuffer& mtas() const { return mtas_; }
  const ClBuffer& tile_offsets() const { return tile_offsets_; }
  const ClBuffer& tile_queue() const { return tile_queue_; }
  uint32_t last_mtas() const { return last_mtas_; }

  std::vector<PmrMta> read_mtas() const;
  void read_tile_queues(std::vector<uint32_t>& offsets, std::vector<uint32_t>& queue) const;
  std::vector<PmrVertex> read_vertices() const;
  size_t device_bytes() const;

 private:
  void setup(PmrParams& P, const SceneBuffers& scene, FrameEvents& ev, StageTimes& t);
  void bin(FrameEvents& ev, StageTimes& t);
  uint32_t scan_tile_counts(StageTimes& t);

  Launcher& launcher_;
  const ClRuntime& rt_;
  ClKernel vertex_, select_view_, setup_, bin_count_, bin_fill_;
  uint64_t tile_queue_limit_;
  uint32_t num_vertices_ = 0;
  uint64_t num_tiles_ = 0;
  ClBuffer params_, vertices_, snapped_, mtas_, mta_counter_;
  uint32_t mta_capacity_ = 0, last_mtas_ = 0;
  bool mta_capacity_fixed_ = false;
  ClBuffer tile_counts_, tile_offsets_, tile_queue_;
  size_t tile_queue_capacity_ = 0;
};

}  // namespace pmr
