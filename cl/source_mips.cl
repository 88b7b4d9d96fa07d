/* The transmission source's mip chain (DESIGN section 4c step 2; PmrSource in include/pmr/shared.h):
 * level k of each view from level k - 1 by a 2x2 box mean of premultiplied RGBA, so that rough glass
 * reads a blurred image whose edges are weighted by coverage. One work-item per row of a view's level. */
#include "common.h"

kernel void source_mip(global half* src, global const PmrSource* S, uint level, uint slice0, uint slices, int W,
                       int H) {
  const uint item = pmr_item_id();
  const int w = max(1, W >> level), h = max(1, H >> level);
  const int pw = max(1, W >> (level - 1u)), ph = max(1, H >> (level - 1u));
  if (item >= slices * (uint)h) return;
  const int y = (int)(item % (uint)h);
  const size_t slice = (size_t)slice0 + (size_t)(item / (uint)h);
  const int y0 = min(2 * y, ph - 1), y1 = min(2 * y + 1, ph - 1);
  global const half* prev = src + 4 * (size_t)S->level_offset[level - 1u];
  const size_t row0 = (slice * (size_t)ph + (size_t)y0) * (size_t)pw,
               row1 = (slice * (size_t)ph + (size_t)y1) * (size_t)pw;
  const size_t out = (size_t)S->level_offset[level] + (slice * (size_t)h + (size_t)y) * (size_t)w;
  for (int x = 0; x < w; ++x) {
    const size_t x0 = (size_t)min(2 * x, pw - 1), x1 = (size_t)min(2 * x + 1, pw - 1);
    const float4 sum = vload_half4(row0 + x0, prev) + vload_half4(row0 + x1, prev) + vload_half4(row1 + x0, prev) +
                       vload_half4(row1 + x1, prev);
    vstore_half4(0.25f * sum, out + (size_t)x, src);
  }
}
