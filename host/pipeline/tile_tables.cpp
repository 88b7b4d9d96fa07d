#include "pipeline/tile_tables.h"

#include <algorithm>

namespace pmr {

TileOwnership tile_ownership(const PmrEncodeParams& E, const std::vector<PmrEncodeColumn>& columns,
                             const std::vector<PmrEncodeRow>& rows, int tile_x) {
  TileOwnership t;
  const int subpixels = 3 * E.display_w;
  t.column_start.resize(size_t(E.view_w) + 1);
  t.row_start.resize(size_t(E.view_h) + 1);
  for (int px = 0, s = 0; px <= E.view_w; ++px) {
    while (s < subpixels && columns[size_t(s)].px < px) ++s;
    t.column_start[size_t(px)] = s;
  }
  for (int py = 0, i = 0; py <= E.view_h; ++py) {
    while (i < int(rows.size()) && rows[size_t(i)].py < py) ++i;
    t.row_start[size_t(py)] = i;
  }
  for (int j = 0; j < E.display_w; ++j)
    if (columns[size_t(3 * j)].px / tile_x != columns[size_t(3 * j + 2)].px / tile_x) t.straddling.push_back(j);
  return t;
}

std::vector<int32_t> subpixel_sample_columns(const PmrEncodeParams& E) {
  std::vector<int32_t> x(size_t(3) * E.display_w);
  for (int s = 0; s < 3 * E.display_w; ++s)
    x[size_t(s)] = int32_t((int64_t(2 * s + 1) * E.view_w * PMR_X_ONE) / (int64_t(6) * E.display_w));
  return x;
}

std::vector<int32_t> subpixel_sample_rows(const PmrEncodeParams& E) {
  std::vector<int32_t> y(size_t(E.display_h));
  for (int i = 0; i < E.display_h; ++i)
    y[size_t(i)] = int32_t((int64_t(2 * i + 1) * E.view_h * PMR_Y_ONE) / (int64_t(2) * E.display_h));
  return y;
}

int subpixel_chunk_capacity(int views, int samples) {
  // samples * area + (lanes - 1) * min(views, area) <= slots
  const int area = (kSubpixelSlots - (PMR_SUBPIXEL_LANES - 1) * views) / samples;
  return area >= views ? area : kSubpixelSlots / (samples + PMR_SUBPIXEL_LANES - 1);
}

std::vector<PmrSampleChunk> subpixel_chunks(const TileOwnership& own, int tile_x, int tile_y, int capacity) {
  std::vector<PmrSampleChunk> chunks;
  const int W = int(own.column_start.size()) - 1, H = int(own.row_start.size()) - 1;
  const int tiles_x = (W + tile_x - 1) / tile_x, tiles_y = (H + tile_y - 1) / tile_y;
  for (int ty = 0; ty < tiles_y; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int s_lo = own.column_start[size_t(tx * tile_x)],
                s_hi = own.column_start[size_t(std::min(W, (tx + 1) * tile_x))];
      const int i_lo = own.row_start[size_t(ty * tile_y)], i_hi = own.row_start[size_t(std::min(H, (ty + 1) * tile_y))];
      if (s_lo >= s_hi || i_lo >= i_hi) continue;
      for (int s0 = s_lo; s0 < s_hi;) {
        // pieces of whole display pixels (a cut inside a pixel only at the tile's own edges)
        const int s1 = std::min(s_hi, std::max(s0 + 1, (s0 + capacity) / 3 * 3));
        const int rows_per_chunk = std::max(1, capacity / (s1 - s0));
        for (int i0 = i_lo; i0 < i_hi; i0 += rows_per_chunk) {
          PmrSampleChunk c{};
          c.tile = ty * tiles_x + tx;
          c.s0 = s0, c.s1 = s1;
          c.i0 = i0, c.i1 = std::min(i_hi, i0 + rows_per_chunk);
          chunks.push_back(c);
        }
        s0 = s1;
      }
    }
  return chunks;
}

}  // namespace pmr
