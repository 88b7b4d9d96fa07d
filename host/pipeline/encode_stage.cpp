#include "pipeline/encode_stage.h"

#include <algorithm>

#include "pmr/error.h"

namespace pmr {

EncodeStage::EncodeStage(Launcher& launcher, const ClProgram& program)
    : launcher_(launcher),
      rt_(launcher.runtime()),
      nearest_(program, "encode_nearest"),
      bilinear_(program, "encode_bilinear"),
      blend_(program, "encode_blend"),
      straddle_(program, "encode_straddle_alpha") {
  params_buf_ = rt_.buffer(sizeof(PmrEncodeParams), "encoder parameters", CL_MEM_READ_ONLY);
}

void EncodeStage::configure(const Display& display, int views, int w, int h) {
  params_ = make_encode_params(display, views, w, h);
  make_encode_tables(display, params_, columns_, rows_);
  rt_.write(params_buf_, &params_, sizeof params_);
  columns_buf_ = rt_.upload(columns_, "encoder columns");
  rows_buf_ = rt_.upload(rows_, "encoder rows");
  configured_ = true;
  display_ = rt_.buffer(std::max<size_t>(display_bytes(), 16), "display image");
  sub_alpha_ = rt_.buffer(std::max<size_t>(display_bytes() / 4 * 3, 16), "display subpixel alpha");
}

size_t EncodeStage::display_bytes() const {
  return configured_ ? size_t(params_.display_w) * params_.display_h * 4 * sizeof(uint16_t) : 0;
}

// The straddling columns (fused and subpixel paths).
TileOwnership EncodeStage::own_by_tiles(int tile_x) {
  TileOwnership own = tile_ownership(params_, columns_, rows_, tile_x);
  straddle_columns_ = rt_.upload(own.straddling, "straddle columns", kMinTableBytes);
  straddle_slots_ = uint32_t(own.straddling.size());
  return own;
}

void EncodeStage::encode(const ClBuffer& volume, FrameEvents& ev) {
  ClKernel& k = params_.blend ? blend_ : params_.bilinear ? bilinear_ : nearest_;
  k.args(params_buf_, columns_buf_, rows_buf_, volume, display_, sub_alpha_);
  const size_t runs = (size_t(params_.display_w) + PMR_ENCODE_RUN - 1) / PMR_ENCODE_RUN;
  ev.add(kEncode, launcher_.launch_2d(k, runs, size_t(params_.display_h), 8, 1));
}

void EncodeStage::straddle_alpha(FrameEvents& ev) {
  if (straddle_slots_ == 0) return;
  straddle_.args(params_buf_, straddle_columns_, straddle_slots_, sub_alpha_, display_);
  ev.add(kEncode, launcher_.launch_2d(straddle_, straddle_slots_, size_t(params_.display_h), 1, 8));
}

void EncodeStage::read_display(std::vector<uint16_t>& out) const {
  if (!configured_) throw InternalError("no display configured");
  out.resize(display_bytes() / 2);
  rt_.read(display_, out.data(), display_bytes());
}

void EncodeStage::read_sub_alpha(std::vector<uint16_t>& out) const {
  if (!configured_) throw InternalError("no display configured");
  out.resize(display_bytes() / 8 * 3);
  rt_.read(sub_alpha_, out.data(), display_bytes() / 4 * 3);
}

size_t EncodeStage::device_bytes() const {
  size_t total = 0;
  for (const ClBuffer* b : {&params_buf_, &columns_buf_, &rows_buf_, &display_, &sub_alpha_, &straddle_columns_})
    total += b->size();
  return total;
}

}  // namespace pmr
