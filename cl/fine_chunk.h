/* The one visibility update of the pixel-center fine raster (fine_raster.h): a row chunk's covered
 * samples tested against the tile's state (depth, key, MASK alpha, BLEND layers and the rest beyond
 * them), whichever path (general or small-triangle) found them. */
#ifndef PMR_CL_FINE_CHUNK_H
#define PMR_CL_FINE_CHUNK_H

#include "fine_lanes.h"

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

#endif
