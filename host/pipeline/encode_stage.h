// Stage 5, the display encoding (DESIGN section 5): the display image, each subpixel's own alpha, the
// encoder's tables and the encoder kernels. The paths that write the display from screen tiles (fused
// raster + encode, --sampling subpixel) write into the same image and leave the alpha of the display
// pixels that straddle tiles to straddle_alpha().
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/launcher.h"
#include "pipeline/tile_tables.h"
#include "pmr/rig.h"

namespace pmr {

class EncodeStage {
 public:
  // `program`: the main program (encode.cl, straddle_alpha.cl).
  EncodeStage(Launcher& launcher, const ClProgram& program);
  // The display's parameters and tables for views of w x h, and its images.
  void configure(const Display& display, int views, int w, int h);
  bool configured() const { return configured_; }
  // Which screen tile owns which display subpixels (tiles tile_x view pixels wide), with the straddling
  // columns uploaded for straddle_alpha().
  TileOwnership own_by_tiles(int tile_x);

  // Encodes the view volume into the display image (nearest, bilinear or blended, as the display asks).
  void encode(const ClBuffer& volume, FrameEvents& ev);
  // The straddling display pixels' alpha, after the tile paths (nothing when there are none).
  void straddle_alpha(FrameEvents& ev);

  const PmrEncodeParams& params() const { return params_; }
  const std::vector<PmrEncodeColumn>& columns() const { return columns_; }
  const std::vector<PmrEncodeRow>& rows() const { return rows_; }
  const ClBuffer& params_buffer() const { return params_buf_; }
  const ClBuffer& rows_buffer() const { return rows_buf_; }
  const ClBuffer& display() const { return display_; }
  const ClBuffer& sub_alpha() const { return sub_alpha_; }
  // Bytes of the display image (half RGBA), 0 without a display.
  size_t display_bytes() const;

  void read_display(std::vector<uint16_t>& out) const;
  void read_sub_alpha(std::vector<uint16_t>& out) const;
  size_t device_bytes() const;

 private:
  Launcher& launcher_;
  const ClRuntime& rt_;
  ClKernel nearest_, bilinear_, blend_, straddle_;
  bool configured_ = false;
  PmrEncodeParams params_{};
  std::vector<PmrEncodeColumn> columns_;
  std::vector<PmrEncodeRow> rows_;
  ClBuffer params_buf_, columns_buf_, rows_buf_, display_, sub_alpha_;
  ClBuffer straddle_columns_;
  uint32_t straddle_slots_ = 0;
};

// The smallest buffer of an encoder or fine-raster table: a table may be empty (no straddling
// columns), and OpenCL has no empty buffers.
constexpr size_t kMinTableBytes = 16;

}  // namespace pmr
