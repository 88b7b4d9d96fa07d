#ifndef PMR_CL_FINE_RASTER_H
#define PMR_CL_FINE_RASTER_H
/* The pixel-center fine raster, shared by the stage kernels that write the view volume (fine.cl) and
 * that write the display image directly (fine_encode.cl); fine_core.h holds what it shares with the
 * subpixel raster too.
 *
 * A work-item walks a tile's queue once, each entry in blocks of up to 16 views. A block whose views
 * each hold a few candidate pixels takes the small-triangle path (fine_small.h: lanes are views); the
 * others take the general path, described here. Per MTA and view it sets up the exact edge functions at
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
#include "fine_chunk.h"
#include "fine_shade.h"
#include "fine_small.h"

/* The general path over views [ib, ib + count) of queue entry (m, id): per view whose x extent holds a
 * sample column of the tile, its rows' chunks tested with the exact edge thresholds (R and OS, set up
 * at the entry's first view, view coordinate f_lo). */
inline void raster_block(const ShadeInputs* in, const PmrMta* m, uint id, const RowEdges* R, const SampleEdgeSteps* OS,
                         long f_lo, int ib, int count, int ly0, int ly1, float cutoff, const FineTile* T,
                         const FineState* st) {
  global const PmrParams* P = in->P;
  /* views whose x extent holds a sample column of the tile: its pixel centers, or with several samples
   * any x between the first pixel's leftmost and the last pixel's rightmost sample */
  uint pass = NS == 1
                  ? view_pass_mask(P, m, ib, count, T->X0, PMR_X_FRAC_BITS, T->nx - 1)
                  : view_pass_mask(P, m, ib, count, T->X0 + T->sx0, 0, (long)(T->nx - 1) * PMR_X_ONE + T->sx1 - T->sx0);
  while (pass != 0) { /* the passing views, lowest first */
    const int i = ib + (31 - (int)clz(pass & (0u - pass)));
    pass &= pass - 1u;
    const long fi = view_coord(P, i), di = fi - f_lo;
    long row[3] = {R->row[0] + di * R->drow[0], R->row[1] + di * R->drow[1], R->row[2] + di * R->drow[2]};
    const long step_y[3] = {R->step_y[0] + di * R->dstep_y[0], R->step_y[1] + di * R->dstep_y[1],
                            R->step_y[2] + di * R->dstep_y[2]};
    SampleEdges O;
    if (NS > 1) sample_edges_at(OS, di, &O);
    DepthPlane dp;
    bool have_plane = false; /* set up on the first covered voxel: tiny MTAs often cover none */
    for (int ly = ly0; ly <= ly1; ++ly) {
      float zrow[NS];
      bool have_zrow = false;
      for (int c = 0; c < FINE_CHUNKS; ++c) {
        const long F[3] = {row[0] + c * R->step_c[0], row[1] + c * R->step_c[1], row[2] + c * R->step_c[2]};
        vint hit[NS], any_hit = (vint)(0);
        for (int s = 0; s < NS; ++s) any_hit |= hit[s] = chunk_hits(R, F, NS > 1 ? &O : 0, s, T->in_tile[c], T->lane);
        if (!any(any_hit)) continue;
        if (!have_plane) dp = depth_plane(m, fi), have_plane = true;
        if (!have_zrow) depth_row(P, &dp, T->y0 + ly, zrow), have_zrow = true;
        const vint center = NS > 1 ? chunk_hits(R, F, 0, 0, T->in_tile[c], T->lane) : (vint)(0);
        const int r = ((i - T->vbase) * PMR_TILE_Y + ly) * FINE_CHUNKS + c;
        raster_chunk(in, m, id, hit, center, &dp, zrow, T->lane, T->X0 + (long)c * VW * PMR_X_ONE,
                     T->Y0 + (long)ly * PMR_Y_ONE, T->x0 + c * VW, i, r, cutoff, st);
      }
      row[0] += step_y[0];
      row[1] += step_y[1];
      row[2] += step_y[2];
    }
  }
}

/* The tile's first pixel (x0, y0), nx x ny pixels inside the raster, as a FineTile. */
inline FineTile fine_tile(global const PmrParams* P, int x0, int y0, int nx, int vbase) {
  FineTile T;
  T.X0 = (long)x0 * PMR_X_ONE + PMR_HALF_X, T.Y0 = (long)y0 * PMR_Y_ONE + PMR_HALF_Y;
  T.x0 = x0, T.y0 = y0, T.nx = nx, T.vbase = vbase;
  T.lane = vload_vint(0, lane_index);
  for (int c = 0; c < FINE_CHUNKS; ++c) T.in_tile[c] = (T.lane + c * VW) < (vint)(nx);
  T.sx0 = T.sx1 = T.sy0 = T.sy1 = 0;
  for (int s = 0; s < NS; ++s) {
    T.sx0 = min(T.sx0, P->sample_x[s]), T.sx1 = max(T.sx1, P->sample_x[s]);
    T.sy0 = min(T.sy0, P->sample_y[s]), T.sy1 = max(T.sy1, P->sample_y[s]);
  }
  return T;
}

/* Rasterizes the queue entries [q0, q1) of the 3D tile at (x0, y0, v0) (nx x ny x nv voxels inside
 * the raster) into the visibility state `st`, each pixel at its NS samples (P->sample_x/y), leaving out
 * the MTAs st->skip and st->need name. Each block of up to 16 views of an entry takes the small path
 * (fine_small.h) when its views' footprints are a few pixels, else the general one (raster_block). */
inline void fine_raster_queue(global const PmrMta* mtas, global const uint* tile_queue, uint q0, uint q1,
                              const ShadeInputs* in, global const PmrTriangle* tris,
                              global const PmrMaterial* materials, int x0, int y0, int v0, int nx, int ny, int nv,
                              int vbase, const FineState* st) {
  global const PmrParams* P = in->P;
  const FineTile T = fine_tile(P, x0, y0, nx, vbase);
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
    if (m.flags & st->skip) {
      if (st->glass && (m.flags & PMR_MTA_TRANSMISSIVE)) *st->glass = 1u;
      if (st->blend && (m.flags & PMR_MTA_BLEND)) *st->blend = 1u;
      continue;
    }
    if ((m.flags & st->need) != st->need) continue;
    const int i_lo = max(v0, m.view_lo), i_hi = min(v0 + nv - 1, m.view_hi);
    /* the tile rows with a sample within the MTA's y extent (the same in every view) */
    const long ylo = min(m.y[0], min(m.y[1], m.y[2])), yhi = max(m.y[0], max(m.y[1], m.y[2]));
    const int ly0 = (int)max(0L, -floor_div_l(T.Y0 + T.sy1 - ylo, PMR_Y_ONE));
    const int ly1 = (int)min((long)ny - 1, floor_div_l(yhi - T.Y0 - T.sy0, PMR_Y_ONE));
    if (ly0 > ly1 || i_lo > i_hi) continue;
    const float cutoff = (m.flags & PMR_MTA_MASK) ? materials[tris[m.tri].material].alpha_cutoff : 0.0f;
    const long f_lo = view_coord(P, i_lo);
    RowEdges R;
    SampleEdgeSteps OS;
    bool have_edges = false; /* the general path's setup, on its first block */
    for (int ib = i_lo; ib <= i_hi; ib += 16) {
      const int count = min(i_hi - ib + 1, 16);
      SmallBlock B;
      if (FINE_SMALL && small_block(P, &m, ib, count, T.X0, T.sx0, T.sx1, yhi - ylo, &B)) {
        raster_small_block(in, &m, id, &B, ib, count, ly0, ly1, cutoff, &T, st);
        continue;
      }
      if (!have_edges) {
        row_edges(&m, view_coord(P, m.view_lo), f_lo, T.X0, T.Y0 + (long)ly0 * PMR_Y_ONE, T.lane, &R);
        if (NS > 1) sample_edge_steps(P, &m, f_lo, &OS);
        have_edges = true;
      }
      raster_block(in, &m, id, &R, &OS, f_lo, ib, count, ly0, ly1, cutoff, &T, st);
    }
  }
}

#endif
