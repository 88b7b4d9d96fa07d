// Tables of the paths that write the display image from screen tiles (the fused raster + encode, and
// --sampling subpixel): which screen tile owns which display subpixels, and how --sampling subpixel cuts
// a tile's subpixels into chunks of bounded size.
#pragma once
#include <cstdint>
#include <vector>

#include "pmr/shared.h"

namespace pmr {

// Ownership: display subpixel column s belongs to the screen tile holding its view column px(s), display
// row i to the one holding its view row py(i) (both maps are monotone).
struct TileOwnership {
  std::vector<int32_t> column_start;  // per view column px (and W): its first subpixel column
  std::vector<int32_t> row_start;     // per view row py (and H): its first display row
  std::vector<int32_t> straddling;    // display columns whose three subpixels lie in different tiles
};
// `columns` may hold several blocks (subpixel cells): px is the same in every block, the first is read.
TileOwnership tile_ownership(const PmrEncodeParams& E, const std::vector<PmrEncodeColumn>& columns,
                             const std::vector<PmrEncodeRow>& rows, int tile_x);

// --sampling subpixel: the sample of display subpixel column s = 3j + k and of display row i in the view
// raster, ((s + 1/2) / (3 W_d) W, (i + 1/2) / H_d H) (DESIGN section 5), truncated to the raster's fixed
// point (16.16 and 24.8): the truncation keeps each sample in the pixel the encoder tables name.
std::vector<int32_t> subpixel_sample_columns(const PmrEncodeParams& E);  // 3 W_d entries, 16.16
std::vector<int32_t> subpixel_sample_rows(const PmrEncodeParams& E);     // H_d entries, 24.8

// A chunk's samples (`samples` per subpixel) sorted by view, each view's run padded to whole vectors,
// must fit the kernel's PMR_SUBPIXEL_SLOTS private slots: the chunk capacity (in subpixels) leaves room
// for the padding.
// 8192 slots make a work-item's private arrays about 230 KB: fine for PoCL's CPU devices, which run the
// kernel with one work-item per work-group (measured best of 2048 to 16384 at paper-8k).
constexpr int kSubpixelSlots = 8192;
int subpixel_chunk_capacity(int views, int samples);
// Every display subpixel in exactly one chunk; a chunk lies in one screen tile, holds at most
// `capacity` subpixels and is cut from its neighbours in the same tile at display-pixel boundaries.
std::vector<PmrSampleChunk> subpixel_chunks(const TileOwnership& own, int tile_x, int tile_y, int capacity);

}  // namespace pmr
