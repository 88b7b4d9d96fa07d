/* Stage 3, tile raster: one work-item per MTA bins it into the 3D tiles (PMR_TILE_X x PMR_TILE_Y
 * pixels x PMR_TILE_V views) it may cover. Per view slab it takes the MTA's exact bounding box over
 * those views, then tests every tile of the box with the 8-corner test: the edge functions are
 * multilinear in (x, y, view), so their maximum over a box of samples (pixel_sample_box) is at one of
 * its 8 corners, and a tile is
 * rejected exactly when some edge fails at all 8 (found with two evaluations,
 * see edge_may_pass).
 *
 * The queues are built in two passes that enumerate identically: bin_count counts entries per tile,
 * the host turns the counts into offsets (exclusive scan) and sizes the queue, and bin_fill writes each
 * entry at offset + (count - 1) while decrementing the count, which leaves the counts at zero for the
 * next frame. Entry order within a tile is arbitrary; fine raster's result does not depend on it. */
#include "common.h"

/* Max over the 8 corners of sign * E_ab - bias (>= 0 means the tile may hold a covered voxel); i0 and
 * i1 are the view coordinates of the slab's end views (E is multilinear in the view coordinate, which
 * grows with the view index), f_lo that of the MTA's first view.
 * sign * E is linear in X with the coefficient sign * dy, the same at every corner, and for a fixed
 * view linear in Y with the coefficient -sign * dx(i): so the maximum over the box is at X1 or X0 by
 * the sign of the first, and per end view at Y1 or Y0 by the sign of the second. Two evaluations
 * instead of eight, the same answer. */
inline bool edge_may_pass(const PmrMta* m, int a, int b, long X0, long X1, long Y0, long Y1, long i0, long i1,
                          long f_lo) {
  const long bias = mta_edge_bias(m, a, b, f_lo);
  const long s = m->sign;
  const long X = s * (long)(m->y[b] - m->y[a]) >= 0 ? X1 : X0;
  const long dx0 = (long)m->x0[b] + i0 * m->dx[b] - (long)m->x0[a] - i0 * m->dx[a];
  const long dx1 = (long)m->x0[b] + i1 * m->dx[b] - (long)m->x0[a] - i1 * m->dx[a];
  const long best =
      max(s * mta_edge(m, a, b, X, -s * dx0 >= 0 ? Y1 : Y0, i0), s * mta_edge(m, a, b, X, -s * dx1 >= 0 ? Y1 : Y0, i1));
  return best >= bias;
}

/* The MTA's x extent in the view with view coordinate i reaches the sample range [X0, X1]. */
inline bool in_view(const PmrMta* m, long i, long X0, long X1) {
  long lo, hi;
  mta_x_extent(m, i, &lo, &hi);
  return hi >= X0 && lo <= X1;
}

/* The x extents [lo, hi] of views i0 .. i0 + count - 1 relative to `base`, one lane each (lanes past
 * count repeat the last view), when count <= 16 and they fit 32 bits (view_x_lanes). */
inline bool view_extent_lanes(global const PmrParams* P, const PmrMta* m, int i0, int count, long base, int16* lo,
                              int16* hi) {
  int16 x[3];
  if (count > 16 || !view_x_lanes(P, m, i0, count, base, x)) return false;
  *lo = min(x[0], min(x[1], x[2]));
  *hi = max(x[0], max(x[1], x[2]));
  return true;
}

/* Some lane's extent [lo, hi] (view_extent_lanes) reaches the range [a, b] (relative to the same base):
 * in_view for 16 views at once. Clamping a and b to 32 bits keeps every outcome, the extents being
 * below 2^30 in magnitude. */
inline bool lanes_in_view(int16 lo, int16 hi, long a, long b) {
  const int ai = (int)clamp(a, (long)INT_MIN, (long)INT_MAX), bi = (int)clamp(b, (long)INT_MIN, (long)INT_MAX);
  return any((hi >= (int16)(ai)) & (lo <= (int16)(bi)));
}

/* Where a pixel's samples lie: in [X + lo_x, X + hi_x] x [Y + lo_y, Y + hi_y], (X, Y) its corner. Around
 * its center, or with --sampling subpixel around any point of the pixel (PmrParams.sample_area), the
 * box of the S sample offsets. */
inline void pixel_sample_box(global const PmrParams* P, long* lo_x, long* hi_x, long* lo_y, long* hi_y) {
  const bool whole = P->sample_area == PMR_SAMPLES_PIXEL;
  int ox0 = 0, ox1 = 0, oy0 = 0, oy1 = 0;
  for (uint s = 0; s < P->samples; ++s) {
    ox0 = min(ox0, P->sample_x[s]), ox1 = max(ox1, P->sample_x[s]);
    oy0 = min(oy0, P->sample_y[s]), oy1 = max(oy1, P->sample_y[s]);
  }
  *lo_x = (whole ? 0 : PMR_HALF_X) + ox0, *hi_x = (whole ? PMR_X_ONE - 1 : PMR_HALF_X) + ox1;
  *lo_y = (whole ? 0 : PMR_HALF_Y) + oy0, *hi_y = (whole ? PMR_Y_ONE - 1 : PMR_HALF_Y) + oy1;
}

/* Calls BIN_EMIT(tile) for every tile the MTA may cover. */
#define BIN_ENUMERATE(P, m)                                                                              \
  for (int tv = (m).view_lo / PMR_TILE_V; tv <= (m).view_hi / PMR_TILE_V; ++tv) {                        \
    const int i0 = max((m).view_lo, tv * PMR_TILE_V);                                                    \
    const int i1 = min((m).view_hi, tv * PMR_TILE_V + PMR_TILE_V - 1);                                   \
    const long f0 = view_coord((P), i0), f1 = view_coord((P), i1), f_lo = view_coord((P), (m).view_lo);  \
    /* x range over the slab: each vertex's x is linear in the view coordinate, so the extremes are at \
     * its end views; per view only when the views are more than a tile apart (in_view below) */ \
    long lo0, hi0, lo1, hi1;                                                                             \
    mta_x_extent(&(m), f0, &lo0, &hi0);                                                                  \
    mta_x_extent(&(m), f1, &lo1, &hi1);                                                                  \
    const long xlo = min(lo0, lo1), xhi = max(hi0, hi1);                                                 \
    const bool sheared = (xhi - xlo) - (hi0 - lo0) > (long)PMR_TILE_X * PMR_X_ONE;                       \
    int16 vlo, vhi; /* with `lanes`, the views' x extents from xlo, tested 16 at once */                 \
    const bool lanes = sheared && view_extent_lanes((P), &(m), i0, i1 - i0 + 1, xlo, &vlo, &vhi);        \
    const long ylo = min3l((m).y[0], (m).y[1], (m).y[2]), yhi = max3l((m).y[0], (m).y[1], (m).y[2]);     \
    /* the pixels whose samples (pixel_sample_box) meet the box */                                       \
    long slo_x, shi_x, slo_y, shi_y;                                                                     \
    pixel_sample_box((P), &slo_x, &shi_x, &slo_y, &shi_y);                                               \
    const int px0 = (int)max(0L, -floor_div_l(shi_x - xlo, PMR_X_ONE));                                  \
    const int px1 = (int)min((long)(P)->view_w - 1, floor_div_l(xhi - slo_x, PMR_X_ONE));                \
    const int py0 = (int)max(0L, -floor_div_l(shi_y - ylo, PMR_Y_ONE));                                  \
    const int py1 = (int)min((long)(P)->view_h - 1, floor_div_l(yhi - slo_y, PMR_Y_ONE));                \
    for (int ty = py0 / PMR_TILE_Y; py0 <= py1 && ty <= py1 / PMR_TILE_Y; ++ty) {                        \
      const long Y0 = (long)max(py0, ty * PMR_TILE_Y) * PMR_Y_ONE + slo_y;                               \
      const long Y1 = (long)min(py1, ty * PMR_TILE_Y + PMR_TILE_Y - 1) * PMR_Y_ONE + shi_y;              \
      for (int tx = px0 / PMR_TILE_X; px0 <= px1 && tx <= px1 / PMR_TILE_X; ++tx) {                      \
        const long X0 = (long)max(px0, tx * PMR_TILE_X) * PMR_X_ONE + slo_x;                             \
        const long X1 = (long)min(px1, tx * PMR_TILE_X + PMR_TILE_X - 1) * PMR_X_ONE + shi_x;            \
        bool in_some_view = !sheared || (lanes && lanes_in_view(vlo, vhi, X0 - xlo, X1 - xlo));          \
        for (int i = i0; i <= i1 && !in_some_view && !lanes; ++i)                                        \
          in_some_view = in_view(&(m), view_coord((P), i), X0, X1);                                      \
        if (in_some_view && edge_may_pass(&(m), 1, 2, X0, X1, Y0, Y1, f0, f1, f_lo) &&                   \
            edge_may_pass(&(m), 2, 0, X0, X1, Y0, Y1, f0, f1, f_lo) &&                                   \
            edge_may_pass(&(m), 0, 1, X0, X1, Y0, Y1, f0, f1, f_lo)) {                                   \
          BIN_EMIT(((uint)tv * (P)->tiles_y + (uint)ty) * (P)->tiles_x + (uint)tx);                      \
        }                                                                                                \
      }                                                                                                  \
    }                                                                                                    \
  }

kernel void bin_count(global const PmrParams* P, global const PmrMta* mtas, uint num_mtas,
                      volatile global uint* tile_counts) {
  const uint id = pmr_item_id();
  if (id >= num_mtas) return;
  const PmrMta m = mtas[id];
#define BIN_EMIT(tile) atomic_inc(&tile_counts[tile])
  BIN_ENUMERATE(P, m)
#undef BIN_EMIT
}

kernel void bin_fill(global const PmrParams* P, global const PmrMta* mtas, uint num_mtas,
                     volatile global uint* tile_counts, global const uint* tile_offsets, global uint* tile_queue) {
  const uint id = pmr_item_id();
  if (id >= num_mtas) return;
  const PmrMta m = mtas[id];
#define BIN_EMIT(tile) tile_queue[tile_offsets[tile] + atomic_dec(&tile_counts[tile]) - 1u] = id
  BIN_ENUMERATE(P, m)
#undef BIN_EMIT
}
