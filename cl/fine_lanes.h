/* The pixel-center fine raster's lanes (fine_raster.h): PMR_VW-wide vector types over a row chunk of a
 * tile, the exact edge thresholds of a row and the samples' offsets from them, cover bits, the tile's
 * visibility state (FineState), and the shading of a chunk's winners at pixel centers or sample points
 * through the one shading module. */
#ifndef PMR_CL_FINE_LANES_H
#define PMR_CL_FINE_LANES_H

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

#endif
