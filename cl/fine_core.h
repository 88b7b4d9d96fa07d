#ifndef PMR_CL_FINE_CORE_H
#define PMR_CL_FINE_CORE_H
/* The fine raster's core, shared by its three entry points: fine.cl (writes the view volume),
 * fine_encode.cl (writes the display image from the same pixel-center raster, fine_raster.h) and
 * fine_subpixel.cl (rasterizes every display subpixel at its own sample). They differ in where their
 * samples lie, so the routines here take the samples' positions: the pixel centers of a row, or
 * per-lane offsets from a base point. Every test is exact either way (integer edge functions), so a
 * sample's outcome depends on the MTA, the view and the sample alone. */
#include "shade.h"

/* Samples per pixel (DESIGN section 3b; P->sample_x/y): the programs are built for one count. */
#ifndef PMR_SAMPLES
#define PMR_SAMPLES 1
#endif

/* alphaMode BLEND (DESIGN section 4c step 3; blend.h): the nearest PMR_BLEND_LAYERS fragments of a
 * sample are composited exactly, the rest as one layer behind them from sums in fixed point (so that
 * their bytes do not depend on the order in which the fragments arrive) of a c, a and -ln(1 - a). */
#define PMR_BLEND_LAYERS 8
#define REST_ALPHA_ONE 16777216.0f /* 2^24: a and -ln(1 - a) */
#define REST_COLOUR_ONE 65536.0f   /* 2^16: a c (c at most 65504) */
#define REST_LN_MAX 40.0f          /* -ln(1 - a) for a = 1: a transmittance of 4e-18 */
/* The rule's terms, for scalars and vectors alike (the subpixel raster sums per sample, the pixel-center
 * raster per vector): a fragment's -ln(1 - a), capped; the layer's opacity 1 - prod(1 - a_k) from the
 * fixed-point sum of those. */
#define REST_LN(a) fmin(-log1p(-(a)), REST_LN_MAX)
#define REST_OPACITY(ln_sum) (1.0f - exp(-(ln_sum) / REST_ALPHA_ONE))

/* Where a vector's lanes sample the raster (16.16 / 24.8): lane l at (X + sx[l], Y + sy[l]), or, when
 * sx is null, along the pixel-center row (X + l PMR_X_ONE, Y). */
typedef struct {
  long X, Y;
  const int* sx;
  const int* sy;
} SampleLanes;

inline SampleLanes row_samples(long X, long Y) {
  const SampleLanes S = {X, Y, 0, 0};
  return S;
}

inline SampleLanes offset_samples(long X, long Y, const int* sx, const int* sy) {
  const SampleLanes S = {X, Y, sx, sy};
  return S;
}

inline long sample_lane_x(const SampleLanes* S, int l) { return S->sx ? S->X + S->sx[l] : S->X + (long)l * PMR_X_ONE; }
inline long sample_lane_y(const SampleLanes* S, int l) { return S->sx ? S->Y + S->sy[l] : S->Y; }

/* Bit l set: in view ib + l (l < count <= 16) some sample x of the form X0 + k 2^shift, 0 <= k <= last,
 * lies within the MTA's x extent: a tile's pixel-center columns (shift PMR_X_FRAC_BITS, last = columns
 * - 1), or any raster x of a span (shift 0). Views failing it cannot hold a covered sample; a sub-pixel
 * MTA passes in an irregular part of the views, so testing 16 views at once (lanes = views) replaces 16
 * unpredictable branches. Every view is passed on when the vertices do not fit view_x_lanes or `last`
 * is 2^29 or more (the edge tests decide exactly either way). Arithmetic shifts floor. */
PMR_HOT uint view_pass_mask(global const PmrParams* P, const PmrMta* m, int ib, int count, long X0, int shift,
                            long last) {
  const uint all = (1u << count) - 1u; /* count <= 16 */
  int16 x[3];
  if (last >= (1L << 29) || !view_x_lanes(P, m, ib, count, X0, x)) return all;
  const int16 kmax = max(x[0], max(x[1], x[2])) >> shift;
  const int16 kmin = -((-min(x[0], min(x[1], x[2]))) >> shift);
  const int16 pass = max(kmin, 0) <= min(kmax, (int16)((int)last));
  return mask_bits16(pass) & all;
}

/* The shading point of a pixel and triangle (DESIGN section 3b), as an offset from the pixel center
 * (16.16 / 24.8): the center where the triangle covers it, else the centroid of the samples it covers
 * (bits of `covered`; at least one), each coordinate's sum divided by their count with truncation. */
inline void shading_point(global const PmrParams* P, bool center, uint covered, int* ox, int* oy) {
  *ox = *oy = 0;
  if (center) return;
  int n = 0;
  long sx = 0, sy = 0;
  for (uint b = covered; b != 0u; b &= b - 1u) {
    const int s = 31 - (int)clz(b & (0u - b));
    sx += P->sample_x[s], sy += P->sample_y[s], ++n;
  }
  if (n > 0) *ox = (int)(sx / n), *oy = (int)(sy / n); /* (n = 0 only for a lane the caller ignores) */
}

/* Whether MTA m covers raster point (X, Y) of the view with view coordinate f. */
inline bool mta_covers(global const PmrParams* P, const PmrMta* m, long X, long Y, long f) {
  const long f_first = view_coord(P, m->view_lo);
  long E[3];
  mta_edges_at(m, X, Y, f, E);
  return E[0] >= mta_edge_bias(m, 1, 2, f_first) && E[1] >= mta_edge_bias(m, 2, 0, f_first) &&
         E[2] >= mta_edge_bias(m, 0, 1, f_first);
}

/* Whether MTA m covers the pixel center (X, Y) of the view with view coordinate f, and, where it does
 * not, which of the NS samples around it it covers (bits): what its shading point there depends on. */
inline uint mta_sample_cover(global const PmrParams* P, const PmrMta* m, long X, long Y, long f, bool* center) {
  *center = mta_covers(P, m, X, Y, f);
  uint bits = 0u;
  for (int s = 0; s < PMR_SAMPLES && !*center; ++s)
    if (mta_covers(P, m, X + P->sample_x[s], Y + P->sample_y[s], f)) bits |= 1u << s;
  return bits;
}

/* alphaMode MASK: of the lanes l < n with w[l] set (candidate winners at samples S of view `view`), clears
 * those whose base colour alpha fails the cutoff, SW candidates at a time (mta_alpha_lanes). */
inline void mask_alpha_lanes(const ShadeInputs* in, const PmrMta* m, int* w, int n, const SampleLanes* S, int view,
                             float cutoff) {
  long X[SW], Y[SW];
  int lane_of[SW], pass[SW], k = 0;
  for (int l = 0; l < n; ++l) {
    if (w[l]) X[k] = sample_lane_x(S, l), Y[k] = sample_lane_y(S, l), lane_of[k++] = l;
    if (k == SW || (k > 0 && l == n - 1)) {
      mta_alpha_lanes(in, m, X, Y, k, view, cutoff, pass);
      for (int j = 0; j < k; ++j)
        if (!pass[j]) w[lane_of[j]] = 0;
      k = 0;
    }
  }
}

/* The winners of SW samples S of view `view` for shade_lanes, one per lane: MTA ids[l] where `act`. Each
 * distinct winning MTA is loaded once (through the cache) and blended into the lanes it won (lanes_add).
 * The lanes' edge functions: along a pixel-center row stepped from the MTA's first lane
 * (lanes_step_edges), else each lane's own; both round the same exact values to float. */
PMR_HOT void lanes_gather(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, sint act, sint ids,
                          const SampleLanes* S, int view, LaneWinners* L) {
  const bool pbr = in->P->shading == PMR_SHADING_PBR;
  const bool trilinear = PMR_USE_TRILINEAR(in->P);
  const long f = view_coord(in->P, view);
  int id_of[SW];
  vstore_s(ids, 0, id_of);
  float e[3][SW]; /* per-lane edge functions (samples off a row); idle lanes 1, as lanes_clear's */
  for (int l = 0; l < SW; ++l) e[0][l] = e[1][l] = e[2][l] = 1.0f;
  lanes_clear(L);
  uint todo = lane_bits(act);
  while (todo != 0u) {
    const int first = 31 - (int)clz(todo & (0u - todo));
    const sint take = act & (ids == (sint)(id_of[first]));
    const uint bits = lane_bits(take);
    todo &= ~bits;
    const PmrMta* m = cached_mta(cache, mtas, (uint)id_of[first]);
    lanes_add(L, in, m, take, bits, pbr);
#if PMR_TRILINEAR
    /* read by the maps and by pbr's specular antialiasing */
    if (trilinear && (pbr || (L->textured & bits))) lanes_edge_derivatives(L, in->P, m, f, bits);
#endif
    long E[3];
    if (!S->sx) {
      long step[3];
      mta_edges_at(m, sample_lane_x(S, first), S->Y, f, E);
      mta_edge_steps(m, step);
      lanes_step_edges(L, take, first, E, step);
      continue;
    }
    for (uint b = bits; b != 0u; b &= b - 1u) {
      const int l = 31 - (int)clz(b & (0u - b));
      mta_edges_at(m, sample_lane_x(S, l), sample_lane_y(S, l), f, E);
      e[0][l] = (float)E[0], e[1][l] = (float)E[1], e[2][l] = (float)E[2];
    }
  }
  if (S->sx) L->e = LANE3(e);
}

/* SW winners (MTA ids where `act`) shaded at the raster points S of view `view`, as colours c[0..2][SW]
 * and opacities c[3][SW] (lane_alpha). */
inline void shade_sample_lanes(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light,
                               sint act, sint ids, const SampleLanes* S, int view, float c[4][SW]) {
  LaneWinners L;
  lanes_gather(in, mtas, cache, act, ids, S, view, &L);
  sfloat alpha;
  s3_store(shade_lanes(in, &L, light, view, &alpha), c[0], c[1], c[2]);
  vstore_s(alpha, 0, c[3]);
}

/* A packed batch's first n lanes shaded: winner ids[l] at raster point (X + sx[l], Y + sy[l]); the lanes
 * from n on are set idle (their entries zeroed). */
inline void shade_packed_lanes(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light, long X,
                               long Y, int view, int n, int* ids, int* sx, int* sy, float c[4][SW]) {
  int on[SW];
  for (int l = 0; l < SW; ++l) {
    on[l] = l < n ? -1 : 0;
    if (l >= n) ids[l] = sx[l] = sy[l] = 0;
  }
  const SampleLanes S = offset_samples(X, Y, sx, sy);
  shade_sample_lanes(in, mtas, cache, light, vload_s(0, on), vload_s(0, ids), &S, view, c);
}

/* Where the kernels that write the display image from screen tiles (fine_encode.cl, fine_subpixel.cl)
 * write it: the image (half RGBA bits) and each subpixel's own alpha (store_sub_alpha), from which
 * encode_straddle_alpha (straddle_alpha.cl) sets the alpha of the display pixels whose subpixels belong
 * to different tiles ("straddling"). */
typedef struct {
  global ushort* bits;
  global ushort* sub_alpha;
  int width; /* display pixels per row */
} DisplayOut;

/* Display pixel (j, i) from the half RGBA bits of its subpixels' samples s0, s1, s2 (channel k from
 * subpixel k, alpha its coverage), of which the calling tile owns subpixels s_lo <= 3 j + k < s_hi (the
 * others' values are not read). Wholly owned: the pixel, its alpha the mean coverage, and each
 * subpixel's alpha. Straddling: the owned channels and their own alpha (written by this tile alone),
 * from which encode_straddle_alpha sets the pixel's alpha once all tiles are done. */
PMR_HOT void write_display_pixel(const DisplayOut* D, int i, int j, int s_lo, int s_hi, ushort4 s0, ushort4 s1,
                                 ushort4 s2) {
  const size_t pixel = (size_t)i * (size_t)D->width + (size_t)j;
  const int k_lo = max(s_lo - 3 * j, 0), k_hi = min(s_hi - 3 * j, 3);
  if (k_lo == 0 && k_hi == 3) {
    vstore4(encode_pixel(s0, s1, s2), pixel, D->bits);
    store_sub_alpha(D->sub_alpha, pixel, s0, s1, s2);
    return;
  }
  for (int k = k_lo; k < k_hi; ++k) {
    const ushort4 s = k == 0 ? s0 : (k == 1 ? s1 : s2);
    D->bits[pixel * 4 + (size_t)k] = k == 0 ? s.x : (k == 1 ? s.y : s.z);
    D->sub_alpha[pixel * 3 + (size_t)k] = s.w;
  }
}

#endif
