// Size limits that more than one module checks (the command line, calibration files, the encoder, the
// pipeline), as C++ constants. Every limit is defined once, in pmr/shared.h, which host and kernels
// share, so that the checks, their messages and the kernels agree.
#pragma once

#include "pmr/shared.h"

namespace pmr {

constexpr int kMaxDisplaySide = PMR_MAX_DISPLAY_SIDE;
constexpr int kMaxTileSide = PMR_MAX_TILE_SIDE;

}  // namespace pmr
