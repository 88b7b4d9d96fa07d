#ifndef PMR_CL_BLEND_H
#define PMR_CL_BLEND_H
/* alphaMode BLEND (DESIGN section 4c step 3) in the fine core: order-independent transparency by depth
 * peeling per 3D tile. The tile's opaque walk leaves the BLEND MTAs out (and notes that it met some);
 * then each layer walk takes the BLEND MTAs alone and keeps, per sample, the nearest fragment behind the
 * previous layer's in the (depth, key) order of visibility and not behind the opaque depth. A layer's
 * winners are shaded once per pixel and winner, at the shading point (as opaque winners are: section
 * 3b), and composited front to back: each sample's colour gains T a c and its transmittance T becomes
 * T (1 - a), which is the "over" of far to near. PMR_BLEND_LAYERS layers are exact; the fragments
 * beyond them form one layer behind (BlendRest, one more walk), and the opaque winner comes last with
 * weight T. Each layer is a total order's next element, so the result depends neither on the order of
 * the triangles nor on the queue's: only on the fragments (at equal depth the key decides). Private
 * state: a second visibility state, the previous layer's (depth, key), T per sample, and the pixels'
 * premultiplied sums. */
#include "fine_raster.h"

/* A 3D tile's queue walk: entries [q0, q1) over nx x ny x nv voxels from (x0, y0, v0). */
typedef struct {
  global const PmrMta* mtas;
  global const uint* tile_queue;
  uint q0, q1;
  int x0, y0, v0, nx, ny, nv;
} TileWalk;

inline void walk_tile(const ShadeInputs* in, const TileWalk* W, const FineState* st) {
  fine_raster_queue(W->mtas, W->tile_queue, W->q0, W->q1, in, in->tris, in->materials, W->x0, W->y0, W->v0, W->nx,
                    W->ny, W->nv, W->v0, st);
}

/* One layer's winners (L) shaded and composited into the pixels' sums acc (4 vectors per state row r:
 * acc[4 r + k]) and the samples' transmittance T, row chunk by row chunk. */
inline void blend_composite_layer(const ShadeInputs* in, const TileWalk* W, const FineState* L, vfloat* T,
                                  vfloat* acc) {
  global const PmrParams* P = in->P;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  for (int lv = 0; lv < W->nv; ++lv)
    for (int ly = 0; ly < W->ny; ++ly)
      for (int c = 0; c * VW < W->nx; ++c) {
        const int r = (lv * PMR_TILE_Y + ly) * FINE_CHUNKS + c;
        vint won[NS], any_won = (vint)(0);
        for (int s = 0; s < NS; ++s) any_won |= won[s] = L->key[FINE_SLOT(r, s)] != (vuint)(PMR_NO_KEY);
        if (!any(any_won)) continue;
        float sum[4][VW];
        for (int k = 0; k < 4; ++k) vstore_vfloat(acc[4 * r + k], 0, sum[k]);
        fine_shade_winners(in, W->mtas, &cache, light, L->mta + FINE_SLOT(r, 0),
                           L->cover + (NS > 1 ? FINE_SLOT(r, 0) : 0), won, T + FINE_SLOT(r, 0), true, W->x0 + c * VW,
                           W->y0 + ly, W->v0 + lv, sum);
        for (int k = 0; k < 4; ++k) acc[4 * r + k] = vload_vfloat(0, sum[k]);
      }
}

/* The fragments behind the exact layers (after_depth, after_key) and not behind `limit`, as one layer
 * (DESIGN section 4c step 3): A = 1 - prod(1 - a_k) = 1 - exp(-sum -ln(1 - a_k)), colour
 * (sum a_k c_k / sum a_k) A, composited behind the exact layers. Returns the number of samples that
 * had such fragments. */
inline uint blend_rest(const ShadeInputs* in, const TileWalk* W, FineState* L, vfloat* T, vfloat* acc) {
  vlong ca[3][FINE_ROWS * NS], a[FINE_ROWS * NS], ln[FINE_ROWS * NS];
  for (int k = 0; k < FINE_ROWS * NS; ++k) ca[0][k] = ca[1][k] = ca[2][k] = a[k] = ln[k] = (vlong)(0);
  struct BlendRest R = {{ca[0], ca[1], ca[2]}, a, ln};
  uint found = 0u;
  L->found = &found;
  L->rest = &R;
  walk_tile(in, W, L);
  if (!found) return 0u;
  uint samples = 0u;
  for (int r = 0; r < FINE_ROWS; ++r)
    for (int s = 0; s < NS; ++s) {
      const int k = FINE_SLOT(r, s);
      const vfloat sum_a = convert_vfloat(a[k]) / REST_ALPHA_ONE;
      const vint some = convert_vint(sum_a > 0.0f);
      const vfloat alpha = REST_OPACITY(convert_vfloat(ln[k]));
      const vfloat w = T[k] * alpha / (float)NS;
      for (int j = 0; j < 3; ++j) {
        const vfloat c = convert_vfloat(ca[j][k]) / REST_COLOUR_ONE / sum_a;
        acc[4 * r + j] += select((vfloat)(0.0f), w * c, some);
      }
      acc[4 * r + 3] += select((vfloat)(0.0f), w, some);
      T[k] = select(T[k], T[k] * (1.0f - alpha), some);
      int on[VW];
      vstore_vint(some, 0, on);
      for (int l = 0; l < VW; ++l) samples += on[l] != 0 ? 1u : 0u;
    }
  return samples;
}

/* BLEND over the tile whose opaque walk `opaque` met BLEND MTAs: the layers composited into the pixels'
 * sums acc (4 vectors per state row, premultiplied RGBA) and the samples' transmittance T, with which
 * the opaque winners are then added (fine_shade_winners). `front`, if not null: the nearest glass of
 * each sample (the transmission source's pass, which holds only the BLEND fragments behind it: DESIGN
 * 4c step 2). Returns the number of samples with more than PMR_BLEND_LAYERS fragments (for the log). */
inline uint blend_layers(const ShadeInputs* in, const TileWalk* W, const FineState* opaque, const FineState* front,
                         vfloat* T, vfloat* acc) {
  vfloat depth[FINE_ROWS * NS], after_depth[FINE_ROWS * NS];
  vuint key[FINE_ROWS * NS], mta[FINE_ROWS * NS], cover[NS > 1 ? FINE_ROWS * NS : 1], after_key[FINE_ROWS * NS];
  for (int k = 0; k < FINE_ROWS * NS; ++k) {
    T[k] = (vfloat)(1.0f);
    after_depth[k] = (vfloat)(-INFINITY), after_key[k] = (vuint)(0u);
    if (!front) continue;
    const vint glass = front->key[k] != (vuint)(PMR_NO_KEY);
    after_depth[k] = select(after_depth[k], front->depth[k], glass);
    after_key[k] = select(after_key[k], front->key[k], as_vuint(glass));
  }
  for (int k = 0; k < 4 * FINE_ROWS; ++k) acc[k] = (vfloat)(0.0f);
  FineState L = fine_state(depth, key, mta, cover, 0, 0u);
  L.need = PMR_MTA_BLEND;
  L.after_depth = after_depth, L.after_key = after_key, L.limit = opaque->depth;
  for (int layer = 0; layer < PMR_BLEND_LAYERS; ++layer) {
    uint found = 0u;
    L.found = &found;
    fine_clear_state(FINE_ROWS * NS, &L);
    walk_tile(in, W, &L);
    if (!found) return 0u;
    blend_composite_layer(in, W, &L, T, acc);
    for (int k = 0; k < FINE_ROWS * NS; ++k) after_depth[k] = depth[k], after_key[k] = key[k];
  }
  return blend_rest(in, W, &L, T, acc);
}

#endif
