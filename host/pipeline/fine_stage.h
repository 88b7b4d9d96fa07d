// Stage 4, the fine raster, in the three forms a configuration chooses from (all over one core,
// cl/fine_raster.h, and one shading module, cl/shade.h):
//   volume    3D tiles into the view volume [view][y][x] (cl/fine.cl), encoded afterwards by stage 5;
//   fused     screen tiles over every view, straight into the display image (cl/fine_encode.cl);
//   subpixel  every display subpixel at its own sample, straight into the display (cl/fine_subpixel.cl).
// It owns the view volume, the debug outputs and each form's tables and program.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/encode_stage.h"
#include "pipeline/geometry_stage.h"
#include "pipeline/launcher.h"
#include "pipeline/scene_buffers.h"

namespace pmr {

// The forms a configuration renders (Pipeline::configure chooses).
struct FinePaths {
  bool volume = true;     // the view volume (fine.cl)
  bool fused = false;     // fused raster + encode
  bool subpixel = false;  // --sampling subpixel
  bool debug = false;     // debug outputs: per voxel and sample of the volume, or per display subpixel
  int samples = 1;        // samples per pixel
};

class FineStage {
 public:
  // `program`: the main program (fine.cl); `options`: its build options, which the per-view-count
  // programs of the fused and subpixel forms extend; `tile`: the 3D tile.
  FineStage(Launcher& launcher, const ClProgram& program, const std::string& options, const int* tile);
  // Allocates the volume and debug buffers and builds the chosen forms' programs and tables.
  void configure(const FinePaths& paths, int views, int view_w, int view_h, EncodeStage* encode);

  // The view volume's 3D tiles (num_tiles of them: the volume form and the multipass passes), into the
  // view volume, or into `out` (the transmission source's opaque pass).
  void run_volume(const SceneBuffers& scene, const GeometryStage& geometry, uint64_t num_tiles,
                  const ShadowBinding& shadows, const SourceBinding& source, FrameEvents& ev, const ClBuffer* out = nullptr);
  // The fused form: one work-item per screen tile.
  void run_fused(const SceneBuffers& scene, const GeometryStage& geometry, size_t screen_tiles, EncodeStage& encode,
                 const ShadowBinding& shadows, const SourceBinding& source, FrameEvents& ev);
  void run_subpixel(const SceneBuffers& scene, const GeometryStage& geometry, EncodeStage& encode,
                    const ShadowBinding& shadows, const SourceBinding& source, FrameEvents& ev);

  const ClBuffer& volume() const { return volume_; }
  size_t volume_bytes() const { return volume_bytes_; }
  void read_volume(std::vector<uint16_t>& out) const;
  void read_debug(std::vector<uint32_t>& keys, std::vector<float>& depth, std::vector<uint32_t>& count) const;
  // The count of samples with more BLEND fragments than the exact layers (cl/blend.h): zeroed by
  // begin_frame, read once the frame is done.
  void begin_frame() const { rt_.fill_zero(blend_overflow_); }
  uint32_t blend_overflow() const;
  size_t device_bytes() const;

 private:
  void configure_fused(int views, EncodeStage& encode);
  void configure_subpixel(int views, EncodeStage& encode);

  Launcher& launcher_;
  const ClRuntime& rt_;
  std::string options_;
  int tile_[3];
  ClKernel fine_;
  FinePaths paths_;
  size_t volume_bytes_ = 0, debug_entries_ = 1;
  ClBuffer volume_, dbg_key_, dbg_depth_, dbg_count_, blend_overflow_;
  // fused raster + encode, built per view count
  ClProgram fused_program_;
  int fused_views_ = 0;
  ClKernel fine_encode_;
  ClBuffer column_start_, column_soa_, row_start_;
  // --sampling subpixel, built per view count
  ClProgram subpixel_program_;
  int subpixel_views_ = 0;
  ClKernel fine_subpixel_;
  ClBuffer chunks_, sample_x_, sample_y_, column_a_, column_b_;
  uint32_t num_chunks_ = 0;
};

}  // namespace pmr
