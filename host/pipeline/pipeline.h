// The PMR pipeline on an OpenCL device: vertex transform -> primitive setup -> tile raster (bin) ->
// fine raster -> pixel encoding. The pipeline only sequences its stages, each of which owns its buffers
// and kernels (docs/ARCHITECTURE.md): the scene's buffers (scene_buffers.h), vertex + setup + tile raster
// with their queues (geometry_stage.h), the fine raster's forms (fine_stage.h) and the display encoding
// (encode_stage.h). Buffers are allocated once per configuration and reused across frames; a frame is
// described once (FrameDescription) and rendered whole.
#pragma once
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/frame_description.h"
#include "pipeline/pipeline_config.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "pmr/shared.h"
#include "runtime/cl_runtime.h"

namespace pmr {

class FrameEvents;
struct FinePaths;

struct StageTimes {  // milliseconds
  double vertex = 0, setup = 0, bin = 0, fine = 0, encode = 0;
  double shadow = 0;          // the frame's shadow maps (DESIGN section 4d)
  double device_total = 0;    // first kernel start to last kernel end (includes host work in between)
  double wall = 0;            // host wall-clock time of render()
  int retries = 0;            // frames redone because a queue was full
  uint32_t mtas = 0;          // MTAs produced by setup
  uint64_t bin_entries = 0;   // (tile, MTA) pairs produced by the tile raster
  uint32_t blend_beyond = 0;  // samples with more alphaMode BLEND fragments than the 8 composited exactly
};

class Pipeline {
 public:
  Pipeline(const ClRuntime& runtime, const PipelineConfig& config);
  ~Pipeline();

  // Uploads geometry, materials and textures, and with --ground shadow the catcher
  // (make_ground_catcher) after them. Call again to switch scenes.
  void set_scene(const Scene& scene, const Scene* catcher = nullptr);
  // Replaces positions, attributes and triangles (a posed frame of the scene given to set_scene: same
  // counts, same materials and textures). Only a copy: no buffer is reallocated.
  void update_geometry(const Scene& posed);
  // Allocates the per-configuration buffers (view volume, tile queues, display image). The display
  // may be null when only the view volume is needed.
  void configure(const Rig& rig, const Display* display);
  // Renders one frame whole: its rig (sizes as given to configure(); the cameras may move from frame to
  // frame) and its lights, uploaded once for the frame.
  StageTimes render(const FrameDescription& frame);
  // The same for a frame described by `rig` and the lights of the scene given to set_scene.
  StageTimes render(const Rig& rig);
  // Seconds spent building kernels: program builds and the work-group functions configure() compiles
  // ahead of the first frame (every launch has a fixed local size, so frames compile nothing).
  double kernel_build_seconds() const;
  // The (kernel, local size) pairs the configuration launches, e.g. "bin_count 64x1": one PoCL
  // work-group function each.
  const std::vector<std::string>& kernel_variants() const;

  const PipelineConfig& config() const { return config_; }
  // Bytes of device buffers currently allocated.
  size_t device_bytes() const;
  int tiles_x() const { return tiles_x_; }
  int tiles_y() const { return tiles_y_; }
  int tiles_v() const { return tiles_v_; }
  size_t volume_bytes() const;
  // Bytes of the transmission source (DESIGN 4c step 2), 0 for a scene without transmissive materials.
  size_t transmission_bytes() const;
  bool fused() const;       // the last configure() chose the fused raster + encode path
  bool has_volume() const;  // the last configure() renders the view volume (read_volume works)
  size_t display_bytes() const;

  // Read-back of the last frame. Volume: [view][y][x][RGBA] halves. Display: [y][x][RGBA] halves.
  void read_volume(std::vector<uint16_t>& out) const;
  void read_display(std::vector<uint16_t>& out) const;
  // Each display subpixel's own alpha: [y][x][k] halves, k = 0, 1, 2 (the EXR's AR, AG, AB).
  void read_sub_alpha(std::vector<uint16_t>& out) const;
  // Requires debug_outputs: per voxel the winning key (PMR_NO_KEY if empty), depth and coverage count
  // (with --sampling subpixel and no view volume: per display subpixel, and no count).
  // With S samples per pixel, per (voxel or subpixel, sample): [voxel][sample].
  void read_debug(std::vector<uint32_t>& keys, std::vector<float>& depth, std::vector<uint32_t>& count) const;
  // Requires debug_outputs: per voxel the window depth of its nearest covered sample, +infinity where
  // none (the Z channel: DESIGN section 3b; not averaged).
  void read_depth(std::vector<float>& depth) const;
  // The last frame's shadow maps (DESIGN section 4d) and their depths, texel (x, y) of map m at
  // m.offset + y m.size + x (+infinity: no caster); none with shadows off.
  void read_shadow_maps(std::vector<PmrShadowMap>& maps, std::vector<float>& depth) const;
  // The MTAs of the last frame, in queue order (arbitrary), and the tile queues (offsets has one entry
  // per tile plus one; queue[offsets[t] .. offsets[t+1]) are MTA indices).
  std::vector<PmrMta> read_mtas() const;
  void read_tile_queues(std::vector<uint32_t>& offsets, std::vector<uint32_t>& queue) const;
  // The last frame's parameters as the kernels saw them (view coordinates, tile grid).
  PmrParams read_params() const;
  // Vertex-stage output of the last frame.
  std::vector<PmrVertex> read_vertices() const;
  // Encodes a given view volume ([view][y][x][RGBA] halves) without rendering: the encoder alone, in
  // any path (those without a view volume encode it from a buffer of its own).
  StageTimes encode_volume(const std::vector<uint16_t>& volume);
  // The MTA queue capacity (for tests of the grow-and-redo path).
  void set_mta_capacity(uint32_t capacity);

  struct Impl;

 private:
  FinePaths choose_paths(const Rig& rig, const Display* display) const;
  PmrParams frame_params(const FrameDescription& frame, bool empty) const;
  StageTimes render_frame(const FrameDescription& frame, bool empty);
  void wait_reporting(const FrameEvents& ev, const StageTimes& t, std::chrono::steady_clock::time_point start);
  std::unique_ptr<Impl> impl_;
  PipelineConfig config_;
  int tiles_x_ = 0, tiles_y_ = 0, tiles_v_ = 0;
};

}  // namespace pmr
