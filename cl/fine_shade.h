/* Shading the winners of the pixel-center fine raster (fine_raster.h): per row chunk, each pixel's
 * first winner in lanes, the rest (edge pixels, BLEND layers) packed into batches, all through the one
 * shading module (cl/shade.h), summed into premultiplied pixels. */
#ifndef PMR_CL_FINE_SHADE_H
#define PMR_CL_FINE_SHADE_H

#include "fine_lanes.h"

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
 * shade_point_lanes), into acc. One sample and no layers (`assign`): the winner's colour as shaded, times
 * its opacity. */
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
      if (assign) { /* opaque winners have alpha exactly 1; clear glass less */
        for (int k = 0; k < 3; ++k) acc[k][h + l] = c[k][l] * c[3][l];
        acc[3][h + l] += c[3][l];
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
