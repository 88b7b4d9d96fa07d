#include "pipeline/transmission_stage.h"

#include <algorithm>

namespace pmr {

namespace {

// Levels down to 1 x 1 in S (each level's first texel for `views` slices, and their count); returns the
// texels of all levels (4 halves each).
uint64_t source_levels(int w, int h, int views, PmrSource& S) {
  S = PmrSource{};
  uint64_t offset = 0;
  for (unsigned k = 0; k < PMR_SOURCE_MAX_LEVELS; ++k) {
    const uint64_t lw = uint64_t(std::max(1, w >> k)), lh = uint64_t(std::max(1, h >> k));
    S.level_offset[k] = offset;
    S.levels = k + 1;
    offset += lw * lh * uint64_t(views);
    if (lw == 1 && lh == 1) break;
  }
  return offset;
}

}  // namespace

TransmissionStage::TransmissionStage(Launcher& launcher, const ClProgram& program)
    : launcher_(launcher), rt_(launcher.runtime()), mip_(program, "source_mip") {
  configure(false, 1, 1, 1, 1);
}

size_t TransmissionStage::bytes_for(int views, int w, int h) {
  PmrSource S;
  return size_t(source_levels(w, h, views, S) * 8);
}

void TransmissionStage::configure(bool needed, int views, int view_w, int view_h, uint64_t num_tiles) {
  PmrSource full{}, opaque{};
  const uint64_t texels = needed ? source_levels(view_w, view_h, views, full) : 0;
  levels_ = full.levels;
  opaque.opaque_only = 1;
  w_ = view_w, h_ = view_h;
  data_ = ClBuffer(), tiles_ = ClBuffer();  // freed first: the budget must not hold the old and the new
  data_ = rt_.buffer(needed ? size_t(texels * 8) : 16, "transmission source");
  tiles_ = rt_.buffer(needed ? size_t(num_tiles) * 4 : 16, "transmission source tiles");
  opaque_info_ = rt_.buffer(sizeof(PmrSource), "transmission source (opaque pass)", CL_MEM_READ_ONLY);
  full_info_ = rt_.buffer(sizeof(PmrSource), "transmission source", CL_MEM_READ_ONLY);
  rt_.write(opaque_info_, &opaque, sizeof opaque);
  rt_.write(full_info_, &full, sizeof full);
}

void TransmissionStage::mip(int slice0, int slices, FrameEvents& ev) {
  for (unsigned k = 1; k < levels_; ++k) {
    const int h = std::max(1, h_ >> k);
    mip_.args(data_, full_info_, cl_uint(k), cl_uint(slice0), cl_uint(slices), cl_int(w_), cl_int(h_));
    ev.add(kFine, launcher_.launch(mip_, size_t(slices) * size_t(h), 64));
  }
}

size_t TransmissionStage::device_bytes() const {
  return data_.size() + opaque_info_.size() + full_info_.size() + tiles_.size();
}

}  // namespace pmr
