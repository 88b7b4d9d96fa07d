// Size limits that more than one module checks (the command line, calibration files, the encoder, the
// pipeline), each defined once so that the checks and their messages agree. The kernels' own limits
// (views, view raster) are in pmr/shared.h.
#pragma once

namespace pmr {

// A display image's side in pixels: the encode kernels index its subpixels in 32 bits.
constexpr int kMaxDisplaySide = 16384;
// A side of the 3D tile (--tile XxYxV): the fine raster keeps a tile's x offsets in 16.16 below 2^22
// (fine_subpixel.cl).
constexpr int kMaxTileSide = 64;

}  // namespace pmr
