#ifndef PMR_CL_FINE_SMALL_H
#define PMR_CL_FINE_SMALL_H

#include "fine_chunk.h"

/* The small-triangle path of the pixel-center fine raster (fine_raster.h's queue walk chooses it).
 *
 * Why. At a million triangles most MTAs cover one or two pixel centers in a view, or none: the general
 * path's unit of work, a row chunk of VW pixels in one view, is mostly empty lanes, and it is spent
 * once per view. Here the lanes are the views instead: for a block of up to 16 views of a queue entry,
 * each view's few candidate pixel columns are enumerated from its own x extent, and one 16-lane vector
 * test decides a (row, column, sample) for all 16 views at once.
 *
 * When. Every view of the block has at most FINE_SMALL_COLUMNS candidate columns (pixels whose samples
 * can meet the MTA's x extent there), and the edge functions relative to the block's vertices fit in
 * 32 bits: (H + Y_ONE) (W + 2 X_ONE) < 2^29 for the MTA's height H and its widest view W bounds every
 * term below 2^31 (see small_block). Else the block takes the general path.
 *
 * Exactness. The tests are the same integers as the general path's: sign E_e + (sample offset) >= bias,
 * E at pixel center (X0 + lx X_ONE, Y) of view i, written relative to the view's vertices:
 *   sign E_e = (sign dy) (lx X_ONE - xa_i) - (sign (Y - ya)) (xb_i - xa_i),   xa_i = x_a(f_i) - X0,
 * where xa_i comes from view_x_lanes' exact 32-bit vertex positions. Covered pixels go to raster_chunk
 * as row-chunk hit vectors, the one depth, mask, blend and winner update of every path; the results do
 * not depend on which path, or in which order, a voxel was tested. */

/* At most this many candidate pixel columns in every view of a block: 2, 4, 8, 16 and 32 measured on
 * three scenes (docs/PERFORMANCE.md); from 8 on the 32-bit bound decides and the times are equal. */
#define FINE_SMALL_COLUMNS 8
/* Column sets are 32-bit masks: the path serves tiles up to 32 pixels wide. */
#define FINE_SMALL (PMR_TILE_X <= 32)

/* A block of up to 16 views of one MTA, lane l being view ib + l: each vertex's x relative to the
 * tile's first pixel center X0 (16.16), and the lanes' first and last candidate columns (unclamped to
 * the tile; c0 > c1 where a view has none). */
typedef struct {
  int16 x[3];
  int16 c0, c1;
  int columns; /* the widest lane's candidate columns */
} SmallBlock;

inline int max_lanes16(int16 v) {
  const int8 a = max(v.lo, v.hi);
  const int4 b = max(a.lo, a.hi);
  const int2 c = max(b.lo, b.hi);
  return max(c.x, c.y);
}

/* Whether views [ib, ib + count) of MTA m (height H) take the small path, and its block if so. The
 * samples of a pixel lie within [sx0, sx1] of its center in x. */
inline bool small_block(global const PmrParams* P, const PmrMta* m, int ib, int count, long X0, int sx0, int sx1,
                        long H, SmallBlock* B) {
  if (!view_x_lanes(P, m, ib, count, X0, B->x)) return false;
  const int16 xmin = min(B->x[0], min(B->x[1], B->x[2])), xmax = max(B->x[0], max(B->x[1], B->x[2]));
  /* pixel lx's samples span [lx X_ONE + sx0, lx X_ONE + sx1]; arithmetic shifts floor */
  B->c0 = -(((int16)(sx1)-xmin) >> PMR_X_FRAC_BITS);
  B->c1 = (xmax - (int16)(sx0)) >> PMR_X_FRAC_BITS;
  /* lanes past `count` repeat the last view's extent (view_x_lanes), so they change no maximum */
  B->columns = max_lanes16(B->c1 - B->c0 + (int16)(1));
  const long W = (long)max_lanes16(xmax - xmin);
  return B->columns <= FINE_SMALL_COLUMNS && (H + PMR_Y_ONE) * (W + 2L * PMR_X_ONE) < (1L << 29);
}

/* The pixel columns of one tile row covered in each view of the block, lanes = views: bits[s] bit lx
 * where sample s of pixel lx is covered, center bit lx where its center is (NS > 1). E[e] and the
 * sample terms off[e][s] as in the head of this file; Y the row's pixel centers. */
inline void small_row(const PmrMta* m, const SmallBlock* B, const int16* dxab, const int* sdy, const int* bias,
                      const int16 (*off)[NS], long Y, int nx, int count, int16* bits, int16* center) {
  const int ea[3] = {1, 2, 0};
  int sya[3]; /* sign (Y - ya): |Y - ya| <= H + Y_ONE / 2 */
  for (int e = 0; e < 3; ++e) sya[e] = m->sign * (int)(Y - (long)m->y[ea[e]]);
  for (int s = 0; s < NS; ++s) bits[s] = (int16)(0);
  *center = (int16)(0);
  const int16 view_ok = vload16(0, lane_index) < (int16)(count);
  for (int k = 0; k < B->columns; ++k) {
    const int16 ck = B->c0 + (int16)(k), lx = min(ck, B->c1); /* clamped: every lane's terms stay bounded */
    const int16 valid = view_ok & (ck <= B->c1) & (lx >= (int16)(0)) & (lx < (int16)(nx));
    if (!any(valid)) continue;
    int16 E[3];
    for (int e = 0; e < 3; ++e)
      E[e] = (int16)(sdy[e]) * ((lx << PMR_X_FRAC_BITS) - B->x[ea[e]]) - (int16)(sya[e]) * dxab[e];
    const int16 col = select((int16)(0), (int16)(1) << lx, valid);
    for (int s = 0; s < NS; ++s) {
      const int16 o0 = NS > 1 ? off[0][s] : (int16)(0), o1 = NS > 1 ? off[1][s] : (int16)(0);
      const int16 o2 = NS > 1 ? off[2][s] : (int16)(0);
      const int16 in =
          (E[0] + o0 >= (int16)(bias[0])) & (E[1] + o1 >= (int16)(bias[1])) & (E[2] + o2 >= (int16)(bias[2]));
      bits[s] |= select((int16)(0), col, in);
    }
    if (NS > 1)
      *center |=
          select((int16)(0), col, (E[0] >= (int16)(bias[0])) & (E[1] >= (int16)(bias[1])) & (E[2] >= (int16)(bias[2])));
  }
}

/* A lane's column bits of one row chunk as a vector of lanes (-1 where set). */
inline vint chunk_lanes(uint bits, int c, vint lane) {
  return (((vint)((int)(bits >> (c * VW))) >> lane) & (vint)(1)) != (vint)(0);
}

/* The small path over views [ib, ib + count) of queue entry (m, id) (small_block B): every covered
 * (view, row chunk) goes to raster_chunk, with the view's depth plane set up once. */
inline void raster_small_block(const ShadeInputs* in, const PmrMta* m, uint id, const SmallBlock* B, int ib, int count,
                               int ly0, int ly1, float cutoff, const FineTile* T, const FineState* st) {
  global const PmrParams* P = in->P;
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  const long f_first = view_coord(P, m->view_lo);
  int16 dxab[3], off[3][NS];
  int sdy[3], bias[3];
  for (int e = 0; e < 3; ++e) {
    const int a = ea[e], b = eb[e];
    dxab[e] = B->x[b] - B->x[a];
    sdy[e] = m->sign * (m->y[b] - m->y[a]);
    bias[e] = (int)mta_edge_bias(m, a, b, f_first);
    for (int s = 0; s < NS && NS > 1; ++s)
      off[e][s] = (int16)(sdy[e] * P->sample_x[s]) - (int16)(m->sign * P->sample_y[s]) * dxab[e];
  }
  DepthPlane dp[16];
  uint have_plane = 0u;
  for (int ly = ly0; ly <= ly1; ++ly) {
    const long Y = T->Y0 + (long)ly * PMR_Y_ONE;
    int16 bits[NS], center, any_bits = (int16)(0);
    small_row(m, B, dxab, sdy, bias, off, Y, T->nx, count, bits, &center);
    for (int s = 0; s < NS; ++s) any_bits |= bits[s];
    uint views = mask_bits16(any_bits != (int16)(0));
    if (views == 0u) continue;
    uint vb[NS][16], cb[16];
    for (int s = 0; s < NS; ++s) vstore16(as_uint16(bits[s]), 0, vb[s]);
    vstore16(as_uint16(center), 0, cb);
    while (views != 0u) {
      const int l = 31 - (int)clz(views & (0u - views));
      views &= views - 1u;
      const int i = ib + l;
      if (!(have_plane & (1u << l))) dp[l] = depth_plane(m, view_coord(P, i)), have_plane |= 1u << l;
      float zrow[NS];
      depth_row(P, &dp[l], T->y0 + ly, zrow);
      for (int c = 0; c < FINE_CHUNKS; ++c) {
        vint hit[NS], any_hit = (vint)(0);
        for (int s = 0; s < NS; ++s) any_hit |= hit[s] = chunk_lanes(vb[s][l], c, T->lane);
        if (!any(any_hit)) continue;
        const int r = ((i - T->vbase) * PMR_TILE_Y + ly) * FINE_CHUNKS + c;
        raster_chunk(in, m, id, hit, chunk_lanes(cb[l], c, T->lane), &dp[l], zrow, T->lane,
                     T->X0 + (long)c * VW * PMR_X_ONE, Y, T->x0 + c * VW, i, r, cutoff, st);
      }
    }
  }
}

#endif
