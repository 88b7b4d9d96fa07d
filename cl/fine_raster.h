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
#define vload_vfloat PMR_CAT(vload, PMR_VW)
#define vstore_vfloat PMR_CAT(vstore, PMR_VW)
#define convert_vint PMR_CAT(convert_int, PMR_VW)
#define as_vuint PMR_CAT(as_uint, PMR_VW)

#define NS PMR_SAMPLES

/* A tile row is FINE_CHUNKS vectors; the private visibility state is FINE_ROWS vectors per array and
 * sample. */
#define FINE_CHUNKS ((PMR_TILE_X + VW - 1) / VW)
#define FINE_ROWS (PMR_TILE_Y * PMR_TILE_V * FINE_CHUNKS)
#define FINE_SLOT(r, s) ((r)*NS + (s))

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

/* An MTA's per-sample terms in a view: each edge's change from the pixel center to sample s,
 * sign (dy sample_x[s] - dx_ab(f) sample_y[s]) (exact), so that sample s of any pixel is tested as its
 * center plus this constant. */
typedef struct {
  long off[3][NS];
} SampleEdges;

/* The same terms as an affine function of the view coordinate: dx_ab(f) = dx_ab(f_lo) + (f - f_lo) ddx_ab,
 * so at view f a term is base - (f - f_lo) sign ddx_ab sample_y[s]. Set up once per queue entry; a view
 * then costs one multiply per term instead of three (64-bit multiplies, the 4-sample raster's hottest
 * instructions when MTAs are a pixel or two). Exact integers: the same values as the direct formula. */
typedef struct {
  long base[3][NS], step[3][NS];
} SampleEdgeSteps;

PMR_HOT void sample_edge_steps(global const PmrParams* P, const PmrMta* m, long f_lo, SampleEdgeSteps* S) {
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  for (int e = 0; e < 3; ++e) {
    const int a = ea[e], b = eb[e];
    const long dy = (long)(m->y[b] - m->y[a]);
    const long dx = (long)m->x0[b] + f_lo * m->dx[b] - (long)m->x0[a] - f_lo * m->dx[a];
    const long ddx = (long)m->dx[b] - (long)m->dx[a];
    for (int s = 0; s < NS; ++s) {
      S->base[e][s] = m->sign * (dy * P->sample_x[s] - dx * P->sample_y[s]);
      S->step[e][s] = -m->sign * ddx * P->sample_y[s];
    }
  }
}

inline void sample_edges_at(const SampleEdgeSteps* S, long di, SampleEdges* O) {
  for (int e = 0; e < 3; ++e)
    for (int s = 0; s < NS; ++s) O->off[e][s] = S->base[e][s] + di * S->step[e][s];
}

/* Sample s's x offset from the pixel center in pixels. One sample is the center itself: known at compile
 * time, so the single-sample raster neither loads nor adds the offsets. */
inline float sample_dx(global const PmrParams* P, int s) {
  return NS > 1 ? (float)P->sample_x[s] / (float)PMR_X_ONE : 0.0f;
}

/* Lanes of a row chunk whose sample at edge offset `s` (SampleEdges, or none for the pixel centers)
 * passes all three edges. F: the edge functions at the chunk's first pixel center. */
inline vint chunk_hits(const RowEdges* R, const long* F, const SampleEdges* O, int s, vint in_tile, vint lane) {
  vint hit = in_tile;
  for (int e = 0; e < 3; ++e)
    hit &= edge_lanes(F[e] + (O ? O->off[e][s] : 0L), R->bias[e], R->G[e], R->ramp[e], R->narrow[e], lane);
  return hit;
}

/* A pixel's coverage by one MTA, with several samples: bit s its sample s, FINE_CENTER its center (what
 * its shading point depends on: shading_point). */
#define FINE_CENTER (1u << 31)
#define FINE_SAMPLE_BITS ((1u << NS) - 1u)

inline vuint cover_bits(const vint* hit, vint center) {
  vuint bits = select((vuint)(0u), (vuint)(FINE_CENTER), center);
  for (int s = 0; s < NS; ++s) bits |= select((vuint)(0u), (vuint)(1u << s), hit[s]);
  return bits;
}

/* alphaMode MASK for the lanes of a row chunk (first pixel center (X, Y)) that would win some sample:
 * alpha is tested once per pixel at its shading point (shading_point), and a lane that fails leaves every
 * sample (DESIGN section 3b). cover: what the MTA covers of each pixel (cover_bits). */
inline void mask_chunk(const ShadeInputs* in, const PmrMta* m, vuint cover, long X, long Y, int view, float cutoff,
                       vint* win) {
  vint any_win = (vint)(0);
  for (int s = 0; s < NS; ++s) any_win |= win[s];
  if (!any(any_win)) return;
  int w[VW], sx[VW], sy[VW];
  vstore_vint(any_win, 0, w);
  if (NS == 1) {
    const SampleLanes S = row_samples(X, Y);
    mask_alpha_lanes(in, m, w, VW, &S, view, cutoff);
  } else {
    uint bits[VW];
    vstore_vint(as_vint(cover), 0, (int*)bits);
    for (int l = 0; l < VW; ++l) {
      sx[l] = sy[l] = 0;
      if (w[l]) shading_point(in->P, (bits[l] & FINE_CENTER) != 0u, bits[l] & FINE_SAMPLE_BITS, sx + l, sy + l);
      sx[l] += l * PMR_X_ONE;
    }
    const SampleLanes S = offset_samples(X, Y, sx, sy);
    mask_alpha_lanes(in, m, w, VW, &S, view, cutoff);
  }
  const vint pass = vload_vint(0, w) != (vint)(0);
  for (int s = 0; s < NS; ++s) win[s] &= pass;
}

/* The visibility state of a tile's queue walk: per (voxel, sample) the closest (depth, key), the winning
 * MTA, with several samples which of the pixel's samples that MTA covers (bits: its shading point,
 * shading_point, without testing them again), and, if `covered` is not null, the number of MTAs
 * covering it. Slot FINE_SLOT(r, s) holds the VW lanes of sample s of state row
 * r = ((view - vbase) * PMR_TILE_Y + ly) * FINE_CHUNKS + chunk. */
typedef struct {
  vfloat* depth;
  vuint* key;
  vuint* mta;
  vuint* cover; /* NS > 1 */
  vint* covered;
  uint skip;   /* MTAs with one of these flags are left out of the walk (PMR_MTA_*) */
  uint need;   /* ... and those without all of these */
  uint* glass; /* if not null: set to 1 when a transmissive MTA is left out */
  uint* blend; /* if not null: set to 1 when a BLEND MTA is left out */
  /* a walk for a BLEND layer (blend.h), else null: only fragments after (after_depth, after_key) in the
   * (depth, key) order and at or in front of `limit` (the opaque depth) compete; `found` is set to 1 when
   * one wins somewhere; with `rest`, every such fragment is accumulated there instead of competing */
  const vfloat* after_depth;
  const vuint* after_key;
  const vfloat* limit;
  uint* found;
  struct BlendRest* rest;
} FineState;

/* A state for a walk of every MTA but those with flags `skip`, over the arrays given (fine_clear_state
 * clears them). */
inline FineState fine_state(vfloat* depth, vuint* key, vuint* mta, vuint* cover, vint* covered, uint skip) {
  const FineState st = {depth, key, mta, cover, covered, skip, 0u, 0, 0, 0, 0, 0, 0, 0};
  return st;
}

/* The lanes of a row chunk where fragment (z, key) lies behind (after_depth, after_key) and not behind
 * `limit`: a BLEND layer walk's candidates (every lane when the walk is not one). */
inline vint layer_lanes(const FineState* st, int k, vfloat z, uint key) {
  if (!st->after_depth) return (vint)(-1);
  const vfloat ad = st->after_depth[k];
  return ((z > ad) | ((z == ad) & ((vuint)(key) > st->after_key[k]))) & (z <= st->limit[k]);
}

/* alphaMode BLEND beyond a sample's PMR_BLEND_LAYERS nearest fragments (blend.h): the rest form one
 * layer directly behind them (DESIGN section 4c step 3), from per-sample sums of a c, a and -ln(1 - a)
 * in fixed point, so that their bytes do not depend on the order in which the fragments arrive. Arrays
 * of the state's slots (FINE_SLOT). */
typedef PMR_CAT(long, PMR_VW) vlong;
#define convert_vlong PMR_CAT(convert_long, PMR_VW)
#define convert_vlong_rte PMR_CAT(PMR_CAT(convert_long, PMR_VW), _rte)
struct BlendRest {
  vlong* ca[3];
  vlong* a;
  vlong* ln;
};

/* SW winners of a row chunk shaded at the pixel centers (px0 + h + l, py), l < SW, where `act`, as
 * colours c[3][SW]. */
inline void shade_center_lanes(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light,
                               sint act, sint ids, int px0, int py, int view, float c[4][SW]) {
  const SampleLanes S = row_samples((long)px0 * PMR_X_ONE + PMR_HALF_X, (long)py * PMR_Y_ONE + PMR_HALF_Y);
  shade_sample_lanes(in, mtas, cache, light, act, ids, &S, view, c);
}

/* The same at each lane's shading point for its winner (shading_point): the pixel center where the
 * winner covers it (all of them: the row form above), else the centroid of its covered samples
 * (cover[l], cover_bits). */
inline void shade_point_lanes(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light, sint act,
                              sint ids, const uint* cover, int px0, int py, int view, float c[4][SW]) {
  const long X = (long)px0 * PMR_X_ONE + PMR_HALF_X, Y = (long)py * PMR_Y_ONE + PMR_HALF_Y;
  int on[SW], sx[SW], sy[SW];
  vstore_s(act, 0, on);
  bool centers = true;
  for (int l = 0; l < SW; ++l) {
    sx[l] = l * PMR_X_ONE, sy[l] = 0;
    if (!on[l] || (cover[l] & FINE_CENTER)) continue;
    int ox, oy;
    shading_point(in->P, false, cover[l] & FINE_SAMPLE_BITS, &ox, &oy);
    sx[l] += ox, sy[l] += oy;
    centers = false;
  }
  if (centers) {
    shade_center_lanes(in, mtas, cache, light, act, ids, px0, py, view, c);
    return;
  }
  const SampleLanes S = offset_samples(X, Y, sx, sy);
  shade_sample_lanes(in, mtas, cache, light, act, ids, &S, view, c);
}

/* The lanes of a row chunk (pixels (px0 + l, py), state row r) where MTA m (queue entry id) won
 * sample s (win[s]) of a walk for the rest: m shaded once per pixel at its shading point (cover: bits,
 * cover_bits) and added to the sums of those samples. */
inline void blend_rest_chunk(const ShadeInputs* in, const PmrMta* m, uint id, vuint bits, const vint* win, int px0,
                             int py, int view, int r, struct BlendRest* rest) {
  global const PmrParams* P = in->P;
  vint any_win = (vint)(0);
  for (int s = 0; s < NS; ++s) any_win |= win[s];
  int w[VW + SW]; /* (SW lanes are read at a time: VW may be less) */
  uint cover[VW + SW];
  float c[4][VW];
  vstore_vint(any_win, 0, w);
  vstore_vint(as_vint(bits), 0, (int*)cover);
  for (int l = VW; l < VW + SW; ++l) w[l] = 0, cover[l] = 0u;
  MtaCache one; /* the shading's MTA cache, holding m */
  one.id = id, one.m = *m;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  for (int h = 0; h < VW; h += SW) {
    const sint act = vload_s(0, w + h) != 0, ids = (sint)((int)id);
    float cs[4][SW];
    if (NS == 1) shade_center_lanes(in, 0, &one, light, act, ids, px0 + h, py, view, cs);
    else shade_point_lanes(in, 0, &one, light, act, ids, cover + h, px0 + h, py, view, cs);
    for (int k = 0; k < 4; ++k)
      for (int l = 0; l < SW && h + l < VW; ++l) c[k][h + l] = cs[k][l];
  }
  const vfloat a = vload_vfloat(0, c[3]);
  vlong add[5];
  add[3] = convert_vlong_rte(a * REST_ALPHA_ONE);
  add[4] = convert_vlong_rte(REST_LN(a) * REST_ALPHA_ONE);
  for (int k = 0; k < 3; ++k) add[k] = convert_vlong_rte(vload_vfloat(0, c[k]) * a * REST_COLOUR_ONE);
  for (int s = 0; s < NS; ++s) {
    const int k = FINE_SLOT(r, s);
    const vlong on = convert_vlong(win[s]);
    for (int j = 0; j < 3; ++j) rest->ca[j][k] += select((vlong)(0), add[j], on);
    rest->a[k] += select((vlong)(0), add[3], on);
    rest->ln[k] += select((vlong)(0), add[4], on);
  }
}

/* MTA m (queue entry id) in view i over the tile's row chunk (ly, c): every sample's coverage (hit[s];
 * center: the pixel centers', read with several samples), depth (the one formula of DepthPlane, whose
 * row term zrow[s] the caller keeps per row, depth_row) and (depth, key) test. */
PMR_HOT void raster_chunk(const ShadeInputs* in, const PmrMta* m, uint id, const vint* hit, vint center,
                          const DepthPlane* dp, const float* zrow, vint lane, long X, long Y, int px0, int view, int r,
                          float cutoff, const FineState* st) {
  vint win[NS];
  vfloat z[NS];
  const vfloat column = convert_vfloat(lane + (px0 - dp->pr));
  for (int s = 0; s < NS; ++s) {
    const int k = FINE_SLOT(r, s);
    z[s] = (vfloat)(zrow[s]) + (vfloat)(dp->gx) * (column + (vfloat)(sample_dx(in->P, s)));
    if (st->covered) st->covered[k] -= hit[s];
    win[s] = PMR_WITH_BLEND ? hit[s] & layer_lanes(st, k, z[s], m->key) : hit[s];
    if (!PMR_WITH_BLEND || !st->rest)
      win[s] &= (z[s] < st->depth[k]) | ((z[s] == st->depth[k]) & ((vuint)(m->key) < st->key[k]));
  }
  const vuint bits = NS > 1 ? cover_bits(hit, center) : (vuint)(0u);
  if (m->flags & PMR_MTA_MASK) mask_chunk(in, m, bits, X, Y, view, cutoff, win);
  if (PMR_WITH_BLEND && (st->found || st->rest)) {
    vint any_win = (vint)(0);
    for (int s = 0; s < NS; ++s) any_win |= win[s];
    if (!any(any_win)) return;
    if (st->found) *st->found = 1u;
    if (st->rest) {
      blend_rest_chunk(in, m, id, bits, win, px0, (int)((Y - PMR_HALF_Y) >> PMR_Y_FRAC_BITS), view, r, st->rest);
      return;
    }
  }
  for (int s = 0; s < NS; ++s) {
    const int k = FINE_SLOT(r, s);
    st->depth[k] = select(st->depth[k], z[s], win[s]);
    st->key[k] = select(st->key[k], (vuint)(m->key), win[s]);
    st->mta[k] = select(st->mta[k], (vuint)(id), win[s]);
    if (NS > 1) st->cover[k] = select(st->cover[k], bits, win[s]);
  }
}

/* The depth plane's row term at each sample of pixel row py (raster_chunk's zrow). */
inline void depth_row(global const PmrParams* P, const DepthPlane* dp, int py, float* zrow) {
  const long rows = (long)(py - dp->qr) * PMR_Y_ONE;
  for (int s = 0; s < NS; ++s)
    zrow[s] = (float)(dp->zr + dp->gy * ((double)(rows + (NS > 1 ? P->sample_y[s] : 0)) / (double)PMR_Y_ONE));
}

/* The tile a queue walk rasterizes, as its raster paths see it: its first pixel (x0, y0) and pixel
 * center (X0, Y0), the columns inside the raster (nx; in_tile per chunk), the first view of its state
 * (vbase), and the samples' extent around a pixel center (sx0..sx1, sy0..sy1). */
typedef struct {
  long X0, Y0;
  int x0, y0, nx, vbase;
  int sx0, sx1, sy0, sy1;
  vint lane;
  vint in_tile[FINE_CHUNKS];
} FineTile;

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

/* Shading jobs of a row chunk beyond its pixels' first winners (pixel `lane`, winner `ids` first met at
 * sample `sample`, shading point (sx, sy) from the chunk's first pixel center, its share `weight` of the
 * pixel), packed SW to a batch: edge pixels are few, and shading them lane by lane in the pixels' own
 * positions would run a whole vector for each. */
typedef struct {
  int n;
  int lane[SW], sample[SW], ids[SW], sx[SW], sy[SW];
  float weight[SW];
} ShadeBatch;

/* A pixel's sum (premultiplied RGBA, acc[k][p]) gains a winner's colour c[0..2] with opacity c[3] and
 * share `weight` (of the samples, times their transmittance for a BLEND layer); its opacity goes to
 * alpha_of[sample][p] when that is kept (a BLEND layer). */
PMR_HOT void shade_add(float acc[4][VW], float* alpha_of, int p, int sample, float weight, const float* c) {
  const float wa = weight * c[3];
  for (int k = 0; k < 3; ++k) acc[k][p] += wa * c[k];
  acc[3][p] += wa;
  if (alpha_of) alpha_of[sample * VW + p] = c[3];
}

/* Shades the batch's jobs and adds them into acc (shade_add); empties it. */
inline void shade_batch(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light, long X, long Y,
                        int view, ShadeBatch* B, float acc[4][VW], float* alpha_of) {
  if (B->n == 0) return;
  float c[4][SW];
  shade_packed_lanes(in, mtas, cache, light, X, Y, view, B->n, B->ids, B->sx, B->sy, c);
  for (int l = 0; l < B->n; ++l) {
    const float cl[4] = {c[0][l], c[1][l], c[2][l], c[3][l]};
    shade_add(acc, alpha_of, B->lane[l], B->sample[l], B->weight[l], cl);
  }
  B->n = 0;
}

/* The lanes w of a row chunk whose winners (ids, covering `bits`, first met at sample 0, shares `weight`)
 * are shaded in pixel order, each lane its own pixel (the row forms of shade_center_lanes and
 * shade_point_lanes), into acc. One sample and no layers (`assign`): the winner's colour as shaded. */
inline void shade_pixel_lanes(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light,
                              const int* ids, const int* w, const float* weight, const uint* bits, int px0, int py,
                              int view, bool assign, float acc[4][VW], float* alpha_of) {
  for (int h = 0; h < VW; h += SW) {
    const sint act = vload_s(0, w + h) != 0;
    if (!any(act)) continue;
    float c[4][SW];
    if (NS == 1) shade_center_lanes(in, mtas, cache, light, act, vload_s(0, ids + h), px0 + h, py, view, c);
    else shade_point_lanes(in, mtas, cache, light, act, vload_s(0, ids + h), bits + h, px0 + h, py, view, c);
    for (int l = 0; l < SW && h + l < VW; ++l) {
      if (!w[h + l]) continue;
      if (assign) {
        for (int k = 0; k < 3; ++k) acc[k][h + l] = c[k][l];
        acc[3][h + l] += 1.0f;
        continue;
      }
      const float cl[4] = {c[0][l], c[1][l], c[2][l], c[3][l]};
      shade_add(acc, alpha_of, h + l, 0, weight[h + l], cl);
    }
  }
}

/* Lanes where sample s is the first of the pixel's samples won by its winner (won, mta), and in *count
 * the number of samples that winner won. */
inline vint first_winner(const vuint* mta, const vint* won, int s, vint* count) {
  vint first = won[s], n = (vint)(0);
  for (int t = 0; t < NS; ++t) {
    const vint same = won[t] & (mta[t] == mta[s]);
    if (t < s) first &= ~same;
    else n -= same;
  }
  *count = n;
  return first;
}

/* A BLEND layer's samples behind their winners: T[t] times 1 - the opacity of the winner of sample t,
 * shaded where it was first met (alpha_of[s], first_winner). */
inline void layer_transmittance(const vuint* mta, const vint* won, const float* alpha_of, vfloat* T) {
  for (int s = 0; s < NS; ++s) {
    vint count;
    const vint first = first_winner(mta, won, s, &count);
    const vfloat a = vload_vfloat(0, alpha_of + s * VW);
    for (int t = s; t < NS; ++t) T[t] = select(T[t], T[t] * (1.0f - a), first & won[t] & (mta[t] == mta[s]));
  }
}

/* The winners of a row chunk shaded and added into acc (premultiplied RGBA per pixel): lane l is pixel
 * (px0 + l, py) of view `view`, whose sample s was won by MTA mta[s][l] where won[s]. Each pixel shades
 * each distinct winner once, at its shading point, weighted by its share (its samples, or with T their
 * transmittances, over NS) times its opacity (1 but for a BLEND layer), so that alpha is the covered
 * fraction (DESIGN section 3b). T: the
 * samples' transmittance through the BLEND layers in front (null: none), which a BLEND layer then
 * multiplies by 1 - its opacity (blend.h); without T and with one sample a pixel is its winner's
 * colour at the pixel center, alpha 1, or unchanged (background). The winners first met at sample 0 are
 * shaded in pixel order, the others packed into batches; each pixel adds its winners in sample order. */
PMR_HOT void fine_shade_winners(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light,
                                const vuint* mta, const vuint* cover, const vint* won, vfloat* T, bool layer, int px0,
                                int py, int view, float acc[4][VW]) {
  float alpha_of[NS * VW];
  ShadeBatch B;
  B.n = 0;
  const long X = (long)px0 * PMR_X_ONE + PMR_HALF_X, Y = (long)py * PMR_Y_ONE + PMR_HALF_Y;
  for (int s = 0; s < NS; ++s) {
    vint count;
    const vint first = first_winner(mta, won, s, &count);
    if (!any(first)) continue;
    int ids[VW + SW], w[VW + SW], n[VW + SW];
    float weight[VW + SW]; /* the winner's share: its samples (times their transmittance T) over NS */
    uint bits[VW + SW];
    vstore_vint(as_vint(mta[s]), 0, ids);
    vstore_vint(first, 0, w);
    vstore_vint(count, 0, n);
    vstore_vint(as_vint(NS > 1 ? cover[s] : (vuint)(1u)), 0, (int*)bits);
    for (int l = VW; l < VW + SW; ++l) ids[l] = w[l] = n[l] = 0, bits[l] = 0u;
    if (T) {
      vfloat sum = (vfloat)(0.0f);
      for (int t = s; t < NS; ++t) sum += select((vfloat)(0.0f), T[t], won[t] & (mta[t] == mta[s]));
      vstore_vfloat(sum / (float)NS, 0, weight);
    } else {
      for (int l = 0; l < VW; ++l) weight[l] = (float)n[l] / (float)NS;
    }
    if (s == 0) {
      shade_pixel_lanes(in, mtas, cache, light, ids, w, weight, bits, px0, py, view, NS == 1 && !T, acc,
                        layer ? alpha_of : 0);
      continue;
    }
    for (int l = 0; l < VW; ++l) {
      if (!w[l]) continue;
      int ox, oy;
      shading_point(in->P, (bits[l] & FINE_CENTER) != 0u, bits[l] & FINE_SAMPLE_BITS, &ox, &oy);
      B.lane[B.n] = l, B.sample[B.n] = s, B.ids[B.n] = ids[l], B.sx[B.n] = l * PMR_X_ONE + ox, B.sy[B.n] = oy;
      B.weight[B.n] = weight[l];
      if (++B.n == SW) shade_batch(in, mtas, cache, light, X, Y, view, &B, acc, layer ? alpha_of : 0);
    }
  }
  shade_batch(in, mtas, cache, light, X, Y, view, &B, acc, layer ? alpha_of : 0);
  if (layer) layer_transmittance(mta, won, alpha_of, T);
}

/* The winners of a row chunk (fine_shade_winners) added behind what is in front of them, and resolved as
 * half RGBA bits: with BLEND, the layers' sums `front` (4 vectors, premultiplied RGBA) and the samples'
 * transmittances T (blend.h); else (null) nothing. */
inline void fine_shade_chunk(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light,
                             const vuint* mta, const vuint* cover, const vint* won, const vfloat* front, vfloat* T,
                             int px0, int py, int view, ushort4* out) {
  float acc[4][VW];
  for (int k = 0; k < 4; ++k) {
    if (front) vstore_vfloat(front[k], 0, acc[k]);
    else
      for (int l = 0; l < VW; ++l) acc[k][l] = 0.0f;
  }
  fine_shade_winners(in, mtas, cache, light, mta, cover, won, T, false, px0, py, view, acc);
  for (int l = 0; l < VW; ++l) vstore_half4((float4)(acc[0][l], acc[1][l], acc[2][l], acc[3][l]), l, (half*)out);
}

/* Initial visibility state of `rows` slots: nothing drawn. */
inline void fine_clear_state(int rows, const FineState* st) {
  for (int r = 0; r < rows; ++r) {
    st->depth[r] = (vfloat)(INFINITY);
    st->key[r] = (vuint)(PMR_NO_KEY);
    st->mta[r] = (vuint)(0);
    if (NS > 1) st->cover[r] = (vuint)(0);
  }
}

#endif
