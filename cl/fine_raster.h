#ifndef PMR_CL_FINE_RASTER_H
#define PMR_CL_FINE_RASTER_H
/* The pixel-center fine raster, shared by the stage kernels that write the view volume (fine.cl) and
 * that write the display image directly (fine_encode.cl); fine_core.h holds what it shares with the
 * subpixel raster too.
 *
 * A work-item walks a tile's queue once. Per MTA and view it sets up the exact edge functions at
 * the tile's first pixel center in 64-bit integers, and per tile row it turns each edge into a 32-bit
 * threshold on the lane index, so that coverage of a whole row of pixels is a few 32-bit vector
 * compares (explicit OpenCL vectors of PMR_VW lanes: PoCL does not vectorize a work-item loop around
 * a queue loop, but it does compile vector types to SIMD). Depth is a plane per (MTA, view) (see
 * depth_plane in common.h), one float multiply-add per voxel. The closest fragment per voxel is kept in
 * private memory, so the volume needs no depth buffer and no clear. Visibility is a total order on
 * (depth, key), so the result does not depend on queue order, tile size or thread count. Only the
 * winners are shaded (except for alphaMode MASK, whose alpha decides visibility).
 *
 * Why the thresholds are exact. For edge e, the inside test at pixel lx of a row chunk is
 *   F + s dy 2^16 lx >= bias     (F = sign * E at the chunk's first pixel center, 2^-24 px^2 units)
 * and since s dy 2^16 lx is a multiple of 2^8 this is equivalent to
 *   G lx >= T,   G = s dy 2^8,   T = ceil((bias - F) / 2^8).
 * When |G| (PMR_VW - 1) < 2^31 - 1 ("narrow" edges: up to ~2000 px tall at 16 lanes), G lx fits in
 * 32 bits and T can be clamped to 32 bits without changing the outcome; taller edges use an exact
 * 64-bit division per row instead. */
#include "fine_core.h"

#define PMR_CAT_(a, b) a##b
#define PMR_CAT(a, b) PMR_CAT_(a, b)
#define VW PMR_VW
typedef PMR_CAT(int, PMR_VW) vint;
typedef PMR_CAT(uint, PMR_VW) vuint;
typedef PMR_CAT(float, PMR_VW) vfloat;
#define vload_vint PMR_CAT(vload, PMR_VW)
#define vstore_vint PMR_CAT(vstore, PMR_VW)
#define convert_vfloat PMR_CAT(convert_float, PMR_VW)
#define as_vint PMR_CAT(as_int, PMR_VW)

/* A tile row is FINE_CHUNKS vectors; the private visibility state is FINE_ROWS vectors per array. */
#define FINE_CHUNKS ((PMR_TILE_X + VW - 1) / VW)
#define FINE_ROWS (PMR_TILE_Y * PMR_TILE_V * FINE_CHUNKS)

/* Queue entries between an MTA's prefetch and its use. */
#define FINE_PREFETCH 4

/* Lanes of a row chunk inside one edge: G lx >= T (see the head of this file). */
inline vint edge_lanes(long F, long bias, long G, vint ramp, bool narrow, vint lane) {
  const long T = (bias - F + 255) >> 8; /* ceil((bias - F) / 2^8) */
  if (narrow) return ramp >= (vint)((int)clamp(T, (long)INT_MIN, (long)INT_MAX));
  if (G > 0) return lane >= (vint)((int)clamp(floor_div_l(T + G - 1, G), 0L, (long)VW));
  if (G < 0) return lane <= (vint)((int)clamp(floor_div_l(-T, -G), -1L, (long)VW));
  return (vint)(T <= 0 ? -1 : 0);
}

/* An MTA's three edges over a tile's rows: the fill-rule bias, the threshold slope G with its lane ramp
 * (see the head of this file), and the edge function at pixel center (X0, Yfirst) of view i_lo (row),
 * its step per row (step_y) and per row chunk (step_c). Every per-view quantity is linear in the view
 * coordinate f (x_k(f) = x0_k + f dx_k): at view i, row and step_y are those at view i_lo plus
 * (f_i - f_lo) exact integer increments drow and dstep_y. */
typedef struct {
  long bias[3], G[3];
  bool narrow[3];
  vint ramp[3];
  long row[3], drow[3], step_y[3], dstep_y[3], step_c[3];
} RowEdges;

PMR_HOT void row_edges(const PmrMta* m, long f_first, long f_lo, long X0, long Yfirst, vint lane, RowEdges* R) {
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  for (int e = 0; e < 3; ++e) {
    const int a = ea[e], b = eb[e];
    R->bias[e] = mta_edge_bias(m, a, b, f_first);
    R->G[e] = (long)m->sign * (long)(m->y[b] - m->y[a]) * PMR_Y_ONE;
    R->narrow[e] = (R->G[e] < 0 ? -R->G[e] : R->G[e]) * (VW - 1) < (long)INT_MAX;
    R->ramp[e] = R->narrow[e] ? (vint)((int)R->G[e]) * lane : (vint)(0);
    const long xa = (long)m->x0[a] + f_lo * m->dx[a], xb = (long)m->x0[b] + f_lo * m->dx[b];
    const long dy = (long)(m->y[b] - m->y[a]), ddx = (long)m->dx[b] - (long)m->dx[a];
    R->row[e] = m->sign * (dy * (X0 - xa) - (xb - xa) * (Yfirst - (long)m->y[a]));
    R->drow[e] = -m->sign * (dy * (long)m->dx[a] + ddx * (Yfirst - (long)m->y[a]));
    R->step_y[e] = -m->sign * (xb - xa) * PMR_Y_ONE;
    R->dstep_y[e] = -m->sign * ddx * PMR_Y_ONE;
    R->step_c[e] = m->sign * dy * ((long)PMR_X_ONE * VW);
  }
}

/* Rasterizes the queue entries [q0, q1) of the 3D tile at (x0, y0, v0) (nx x ny x nv voxels inside
 * the raster) into the visibility state: per voxel the closest (depth, key) and the winning MTA, and,
 * if `covered` is not null, the number of MTAs covering it. State row r = ((view - vbase) *
 * PMR_TILE_Y + ly) * FINE_CHUNKS + chunk holds VW lanes. */
inline void fine_raster_queue(global const PmrMta* mtas, global const uint* tile_queue, uint q0, uint q1,
                              const ShadeInputs* in, global const PmrTriangle* tris,
                              global const PmrMaterial* materials, int x0, int y0, int v0, int nx, int ny, int nv,
                              int vbase, vfloat* best_depth, vuint* best_key, vuint* best_mta, vint* covered) {
  const long X0 = (long)x0 * PMR_X_ONE + PMR_HALF_X, Y0 = (long)y0 * PMR_Y_ONE + PMR_HALF_Y;
  const vint lane = vload_vint(0, lane_index);
  vint in_tile[FINE_CHUNKS]; /* lanes inside the raster (edge tiles are narrower) */
  for (int c = 0; c < FINE_CHUNKS; ++c) in_tile[c] = (lane + c * VW) < (vint)(nx);
  for (uint q = q0; q < q1; ++q) {
    /* The queue visits MTAs in no memory order and a 1M-triangle frame's MTAs (150 MB) do not stay in
     * cache: ask for an MTA a few entries ahead, so its cache misses overlap this entry's work. */
    if (q + FINE_PREFETCH < q1) {
      global const char* ahead = (global const char*)&mtas[tile_queue[q + FINE_PREFETCH]];
      __builtin_prefetch(ahead);
      __builtin_prefetch(ahead + sizeof(PmrMta) - 1);
    }
    const uint id = tile_queue[q];
    const PmrMta m = mtas[id];
    const int i_lo = max(v0, m.view_lo), i_hi = min(v0 + nv - 1, m.view_hi);
    /* the tile rows whose centers lie within the MTA's y extent (the same in every view) */
    const long ylo = min(m.y[0], min(m.y[1], m.y[2])), yhi = max(m.y[0], max(m.y[1], m.y[2]));
    const int ly0 = (int)max(0L, -floor_div_l(Y0 - ylo, PMR_Y_ONE));
    const int ly1 = (int)min((long)ny - 1, floor_div_l(yhi - Y0, PMR_Y_ONE));
    if (ly0 > ly1 || i_lo > i_hi) continue;
    const float cutoff = (m.flags & PMR_MTA_MASK) ? materials[tris[m.tri].material].alpha_cutoff : 0.0f;
    const long f_lo = view_coord(in->P, i_lo);
    RowEdges R;
    row_edges(&m, view_coord(in->P, m.view_lo), f_lo, X0, Y0 + (long)ly0 * PMR_Y_ONE, lane, &R);
    for (int ib = i_lo; ib <= i_hi; ib += 16) {
      uint pass = view_pass_mask(in->P, &m, ib, min(i_hi - ib + 1, 16), X0, PMR_X_FRAC_BITS, nx - 1);
      while (pass != 0) { /* the passing views, lowest first */
        const int i = ib + (31 - (int)clz(pass & (0u - pass)));
        pass &= pass - 1u;
        const long fi = view_coord(in->P, i), di = fi - f_lo;
        long row[3] = {R.row[0] + di * R.drow[0], R.row[1] + di * R.drow[1], R.row[2] + di * R.drow[2]};
        const long step_y[3] = {R.step_y[0] + di * R.dstep_y[0], R.step_y[1] + di * R.dstep_y[1],
                                R.step_y[2] + di * R.dstep_y[2]};
        DepthPlane dp;
        bool have_plane = false; /* set up on the first covered voxel: tiny MTAs often cover none */
        for (int ly = ly0; ly <= ly1; ++ly) {
          float zrow = 0.0f;
          bool have_zrow = false;
          for (int c = 0; c < FINE_CHUNKS; ++c) {
            vint hit = in_tile[c];
            hit &= edge_lanes(row[0] + c * R.step_c[0], R.bias[0], R.G[0], R.ramp[0], R.narrow[0], lane);
            hit &= edge_lanes(row[1] + c * R.step_c[1], R.bias[1], R.G[1], R.ramp[1], R.narrow[1], lane);
            hit &= edge_lanes(row[2] + c * R.step_c[2], R.bias[2], R.G[2], R.ramp[2], R.narrow[2], lane);
            if (!any(hit)) continue;
            if (!have_plane) dp = depth_plane(&m, fi), have_plane = true;
            if (!have_zrow) zrow = (float)(dp.zr + dp.gy * (double)(y0 + ly - dp.qr)), have_zrow = true;
            const vfloat z = (vfloat)(zrow) + (vfloat)(dp.gx) * convert_vfloat(lane + (x0 + c * VW - dp.pr));
            const int r = ((i - vbase) * PMR_TILE_Y + ly) * FINE_CHUNKS + c;
            if (covered) covered[r] -= hit;
            vint win = hit & ((z < best_depth[r]) | ((z == best_depth[r]) & ((vuint)(m.key) < best_key[r])));
            if ((m.flags & PMR_MTA_MASK) && any(win)) {
              int w[VW];
              vstore_vint(win, 0, w);
              const SampleLanes S = row_samples(X0 + (long)c * VW * PMR_X_ONE, Y0 + (long)ly * PMR_Y_ONE);
              mask_alpha_lanes(in, &m, w, VW, &S, i, cutoff);
              win = vload_vint(0, w);
            }
            best_depth[r] = select(best_depth[r], z, win);
            best_key[r] = select(best_key[r], (vuint)(m.key), win);
            best_mta[r] = select(best_mta[r], (vuint)(id), win);
          }
          row[0] += step_y[0];
          row[1] += step_y[1];
          row[2] += step_y[2];
        }
      }
    }
  }
}

/* The winners of a row chunk shaded, as half RGBA bits: lane l is voxel (px0 + l, py) of view `view`,
 * won by MTA mta[l] where `won`, and out[l] gets its lit colour with alpha 1, or zero (background). SW
 * lanes at a time (lanes_gather, shade_lanes). */
inline void fine_shade_chunk(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light, vuint mta,
                             vint won, int px0, int py, int view, ushort4* out) {
  for (int l = 0; l < VW; ++l) out[l] = (ushort4)(0);
  if (!any(won)) return; /* background */
  int ids[VW + SW], w[VW + SW];
  vstore_vint(as_vint(mta), 0, ids);
  vstore_vint(won, 0, w);
  for (int l = VW; l < VW + SW; ++l) ids[l] = w[l] = 0;
  const long Y = (long)py * PMR_Y_ONE + PMR_HALF_Y;
  for (int h = 0; h < VW; h += SW) {
    const sint block_won = vload_s(0, w + h) != 0;
    if (!any(block_won)) continue;
    const SampleLanes S = row_samples((long)(px0 + h) * PMR_X_ONE + PMR_HALF_X, Y);
    LaneWinners L;
    lanes_gather(in, mtas, cache, block_won, vload_s(0, ids + h), &S, view, &L);
    float c[3][SW];
    s3_store(shade_lanes(in, &L, light, view), c[0], c[1], c[2]);
    for (int l = 0; l < SW && h + l < VW; ++l)
      if (w[h + l]) vstore_half4((float4)(c[0][l], c[1][l], c[2][l], 1.0f), h + l, (half*)out);
  }
}

/* Initial visibility state: nothing drawn. */
inline void fine_clear_state(int rows, vfloat* best_depth, vuint* best_key, vuint* best_mta) {
  for (int r = 0; r < rows; ++r) {
    best_depth[r] = (vfloat)(INFINITY);
    best_key[r] = (vuint)(PMR_NO_KEY);
    best_mta[r] = (vuint)(0);
  }
}

#endif
