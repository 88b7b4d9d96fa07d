// The transmission source of --shading pbr (DESIGN section 4c step 2): in a frame whose scene has
// transmissive materials, an opaque pass (the volume fine raster without the transmissive MTAs) draws
// each view's opaque image into the source, mip() builds its mip chain, and the frame's own pass then
// reads it where a transmissive surface wins (cl/transmission.h). This stage owns the source, its two
// descriptions (the opaque pass's and the full pass's) and the mip kernel. Scenes without transmission
// get a source of no levels and allocate nothing else.
#pragma once
#include <cstddef>
#include <cstdint>

#include "pipeline/launcher.h"
#include "pmr/shared.h"

namespace pmr {

// What a shading kernel binds for the transmission source: the data, one of the two descriptions, and
// per 3D tile whether the opaque pass left glass out (where it did not, the full pass reuses its voxels).
struct SourceBinding {
  const ClBuffer* data;
  const ClBuffer* info;
  const ClBuffer* tiles;
};

class TransmissionStage {
 public:
  // `program`: the main program (source_mips.cl).
  TransmissionStage(Launcher& launcher, const ClProgram& program);
  // Allocates the source for `views` views of view_w x view_h and its flags for num_tiles 3D tiles when
  // `needed` (a transmissive material under pbr), else frees them.
  void configure(bool needed, int views, int view_w, int view_h, uint64_t num_tiles);
  bool active() const { return levels_ > 0; }
  // The opaque pass draws into source(); the full pass (and a scene without transmission) reads.
  SourceBinding opaque_pass() const { return {&data_, &opaque_info_, &tiles_}; }
  SourceBinding full_pass() const { return {&data_, &full_info_, &tiles_}; }
  const ClBuffer& source() const { return data_; }
  // The mip chain of view slices [slice0, slice0 + slices) from their level 0.
  void mip(int slice0, int slices, FrameEvents& ev);
  // Bytes the source takes for views x w x h with its mip chain (the memory budget's figure).
  static size_t bytes_for(int views, int w, int h);
  size_t device_bytes() const;

 private:
  Launcher& launcher_;
  const ClRuntime& rt_;
  ClKernel mip_;
  int w_ = 0, h_ = 0;
  unsigned levels_ = 0;
  ClBuffer data_, opaque_info_, full_info_, tiles_;
};

}  // namespace pmr
