/* Texture filtering (docs/DESIGN.md section 3b, "Filtered textures"): texels of a mip level, the
 * bilinear sample of one level with the glTF sampler's wrap modes, the trilinear sample between two,
 * and the level of detail from the analytic screen-space derivatives of the texture coordinates. cl/material_maps.h's
 * sample_map_lanes is the one caller: every path and every map samples through it. */
#ifndef PMR_CL_TEXTURE_H
#define PMR_CL_TEXTURE_H

#include "common.h"
#include "lanes.h"

#define PMR_USE_TRILINEAR(P) (PMR_TRILINEAR && (P)->texture_filter == PMR_FILTER_TRILINEAR)

/* The sampling below runs for SW lanes at once (cl/lanes.h), each lane with its own coordinates and
 * level, all of one texture: the index arithmetic and the filter in vectors, only the texel loads (and
 * the sRGB table) lane by lane, since they are gathers. A lane's result is the scalar arithmetic's,
 * operation for operation. */
typedef uint8 suint;

/* Texel coordinates c wrapped into [0, size) per lane (sizes per lane: the lanes' levels differ). */
inline sint wrap_lanes(sint c, sint size, int mode) {
  const sint inside = (c >= 0) & (c < size);
  if (all(inside)) return c; /* inside: every mode leaves it (and skips a division) */
  sint r;
  if (mode == PMR_WRAP_CLAMP) {
    r = clamp(c, (sint)(0), size - 1);
  } else if (mode == PMR_WRAP_MIRROR) {
    const sint period = 2 * size;
    r = c % period;
    r = select(r, r + period, r < 0);
    r = select(period - 1 - r, r, r < size);
  } else { /* REPEAT */
    r = c % size;
    r = select(r, r + size, r < 0);
  }
  return select(r, c, inside);
}

/* Level k of a texture per lane: its first texel and size (PmrTexture's layout: levels back to back,
 * each side halved, rounding down, at least 1). */
typedef struct {
  suint offset;
  sint width, height;
} LaneLevel;

inline LaneLevel next_level_lanes(LaneLevel l, sint step) {
  l.offset = select(l.offset, l.offset + as_uint8(l.width * l.height), step);
  l.width = select(l.width, max(l.width >> 1, (sint)(1)), step);
  l.height = select(l.height, max(l.height >> 1, (sint)(1)), step);
  return l;
}

/* Level k[l] of every lane; kmax >= every k. */
inline LaneLevel texture_level_lanes(const PmrTexture* t, sint k, int kmax) {
  LaneLevel l = {(suint)(t->offset), (sint)(t->width), (sint)(t->height)};
  for (int j = 0; j < kmax; ++j) l = next_level_lanes(l, (sint)(j) < k);
  return l;
}

/* Bilinear sample of one level per lane where `act` (others 0) with the texture's wrap modes; uv (0,0)
 * is the top-left corner of the image (row 0). Colour maps decode sRGB per texel, data maps
 * (metallic-roughness, normal, occlusion) are linear. Level 0 is the whole of --texture-filter bilinear. */
inline void sample_level_lanes(global const uchar4* texels, global const float* srgb_lut, const PmrTexture* t,
                               const LaneLevel* lv, sfloat u, sfloat v, sint act, bool srgb, sfloat* out) {
  const sfloat fx = u * convert_float8(lv->width) - 0.5f, fy = v * convert_float8(lv->height) - 0.5f;
  const sfloat x0f = floor(fx), y0f = floor(fy);
  const sfloat ax = fx - x0f, ay = fy - y0f;
  /* clamp before converting so huge UVs stay well defined; idle lanes read texel 0 (and are not loaded) */
  const sint x0 = select((sint)(0), convert_int8(clamp(x0f, -1.0e8f, 1.0e8f)), act);
  const sint y0 = select((sint)(0), convert_int8(clamp(y0f, -1.0e8f, 1.0e8f)), act);
  const sint xa = wrap_lanes(x0, lv->width, t->wrap_s), xb = wrap_lanes(x0 + 1, lv->width, t->wrap_s);
  const sint ya = wrap_lanes(y0, lv->height, t->wrap_t), yb = wrap_lanes(y0 + 1, lv->height, t->wrap_t);
  uint at[4][SW]; /* taps (xa, ya), (xb, ya), (xa, yb), (xb, yb) */
  vstore8(lv->offset + as_uint8(ya * lv->width + xa), 0, at[0]);
  vstore8(lv->offset + as_uint8(ya * lv->width + xb), 0, at[1]);
  vstore8(lv->offset + as_uint8(yb * lv->width + xa), 0, at[2]);
  vstore8(lv->offset + as_uint8(yb * lv->width + xb), 0, at[3]);
  int on[SW];
  vstore_s(act, 0, on);
  uint raw[4][SW]; /* the taps' RGBA8 texels (idle lanes 0), as stored: x in the low byte */
  for (int l = 0; l < SW; ++l)
    for (int k = 0; k < 4; ++k) raw[k][l] = on[l] ? as_uint(texels[at[k][l]]) : 0u;
  sfloat c[4][4]; /* [tap][channel], decoded in vectors (sRGB colour through the table, lane by lane) */
  for (int k = 0; k < 4; ++k) {
    const suint r = vload8(0, raw[k]);
    for (int ch = 0; ch < 4; ++ch) c[k][ch] = convert_float8((r >> (uint)(8 * ch)) & 0xffu) * (1.0f / 255.0f);
    if (!srgb) continue;
    float lin[3][SW];
    for (int l = 0; l < SW; ++l)
      for (int ch = 0; ch < 3; ++ch) lin[ch][l] = srgb_lut[(raw[k][l] >> (8 * ch)) & 0xffu];
    for (int ch = 0; ch < 3; ++ch) c[k][ch] = vload_s(0, lin[ch]);
  }
  for (int ch = 0; ch < 4; ++ch) {
    const sfloat c00 = c[0][ch], c10 = c[1][ch], c01 = c[2][ch], c11 = c[3][ch];
    const sfloat top = c00 + (c10 - c00) * ax, bottom = c01 + (c11 - c01) * ax;
    out[ch] = top + (bottom - top) * ay;
  }
}

/* Trilinear sample per lane where `act` at level of detail lambda in [0, levels - 1]: bilinear in levels
 * floor(lambda) and the next, mixed by the fraction (one level where lambda is whole, e.g. 0 when
 * magnified). out: RGBA, 4 vectors. */
inline void sample_texture_lanes(global const uchar4* texels, global const float* srgb_lut, const PmrTexture* t,
                                 sfloat u, sfloat v, sfloat lambda, sint act, bool srgb, sfloat* out) {
  const sint k = select((sint)(0), convert_int8(lambda), act);
  const sfloat frac = lambda - convert_float8(k);
  int ks[SW], kmax = 0;
  vstore_s(k, 0, ks);
  for (int l = 0; l < SW; ++l) kmax = max(kmax, ks[l]);
  const LaneLevel a = texture_level_lanes(t, k, kmax);
  sample_level_lanes(texels, srgb_lut, t, &a, u, v, act, srgb, out);
  const sint mix = act & (frac != 0.0f);
  if (!any(mix)) return;
  const LaneLevel b = next_level_lanes(a, (sint)(-1));
  sfloat cb[4];
  sample_level_lanes(texels, srgb_lut, t, &b, u, v, mix, srgb, cb);
  for (int ch = 0; ch < 4; ++ch) out[ch] = select(out[ch], out[ch] + (cb[ch] - out[ch]) * frac, mix);
}

/* Level of detail per lane of texture t for texture-coordinate derivatives (du/dx, dv/dx), (du/dy,
 * dv/dy) (before the map's transform m, whose 2x2 linear part applies to them): rho = the longer of the
 * two footprint axes in level-0 texels, lambda = log2 rho clamped to [0, levels - 1] (fmax also maps a
 * NaN of a degenerate footprint to 0). */
inline sfloat texture_lod_lanes(global const float* m, const PmrTexture* t, sfloat dxu, sfloat dxv, sfloat dyu,
                                sfloat dyv) {
  const float w = (float)t->width, h = (float)t->height;
  const sfloat xu = (m[0] * dxu + m[1] * dxv) * w, xv = (m[3] * dxu + m[4] * dxv) * h;
  const sfloat yu = (m[0] * dyu + m[1] * dyv) * w, yv = (m[3] * dyu + m[4] * dyv) * h;
  const sfloat rho2 = fmax(xu * xu + xv * xv, yu * yu + yv * yv); /* rho^2: log2 rho = log2(rho^2) / 2 */
  return fmin(fmax(0.5f * log2(rho2), 0.0f), (float)(t->levels - 1));
}

#endif
