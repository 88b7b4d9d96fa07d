/* Texture filtering (docs/DESIGN.md section 3b, "Filtered textures"): texels of a mip level, the
 * bilinear sample of one level with the glTF sampler's wrap modes, the trilinear sample between two,
 * and the level of detail from the analytic screen-space derivatives of the texture coordinates. cl/shade.h's
 * sample_map is the one caller: every path and every map samples through it. */
#ifndef PMR_CL_TEXTURE_H
#define PMR_CL_TEXTURE_H

#include "common.h"

/* The kernels are built for one filter (-DPMR_TRILINEAR, the host's --texture-filter), as for one
 * sample count: built with 0 they carry no per-lane derivatives and no level-of-detail code, so
 * bilinear filtering costs what it did before mips. A build without the define serves both filters,
 * chosen by PmrParams.texture_filter. */
#ifndef PMR_TRILINEAR
#define PMR_TRILINEAR 1
#endif
#define PMR_USE_TRILINEAR(P) (PMR_TRILINEAR && (P)->texture_filter == PMR_FILTER_TRILINEAR)

inline int wrap_texel(int c, int size, int mode) {
  if ((uint)c < (uint)size) return c; /* inside: every mode leaves it (and skips a division) */
  if (mode == PMR_WRAP_CLAMP) return clamp(c, 0, size - 1);
  if (mode == PMR_WRAP_MIRROR) {
    const int period = 2 * size;
    int r = c % period;
    if (r < 0) r += period;
    return r < size ? r : period - 1 - r;
  }
  int r = c % size; /* REPEAT */
  return r < 0 ? r + size : r;
}

/* Level k of a texture: its first texel and size (PmrTexture's layout: levels back to back, each side
 * halved, rounding down, at least 1). */
typedef struct {
  uint offset;
  int width, height;
} TexLevel;

inline TexLevel next_level(TexLevel l) {
  l.offset += (uint)(l.width * l.height);
  l.width = max(1, l.width >> 1), l.height = max(1, l.height >> 1);
  return l;
}

inline TexLevel texture_level(const PmrTexture* t, int k) {
  TexLevel l = {t->offset, t->width, t->height};
  for (int j = 0; j < k; ++j) l = next_level(l);
  return l;
}

/* Texel (x, y) of a level: colour maps decode sRGB, data maps (metallic-roughness, normal, occlusion)
 * are linear. */
inline float4 texel(global const uchar4* texels, global const float* srgb_lut, const TexLevel* t, int x, int y,
                    bool srgb) {
  const uchar4 c = texels[t->offset + (uint)(y * t->width + x)];
  if (!srgb) return convert_float4(c) * (1.0f / 255.0f);
  return (float4)(srgb_lut[c.x], srgb_lut[c.y], srgb_lut[c.z], (float)c.w * (1.0f / 255.0f));
}

/* Bilinear sample of one level with the texture's wrap modes; uv (0,0) is the top-left corner of the
 * image (row 0). Level 0 is the whole of --texture-filter bilinear. */
inline float4 sample_level(global const uchar4* texels, global const float* srgb_lut, const PmrTexture* t,
                           const TexLevel* lv, float u, float v, bool srgb) {
  const float fx = u * (float)lv->width - 0.5f, fy = v * (float)lv->height - 0.5f;
  const float x0f = floor(fx), y0f = floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  /* clamp before converting so huge UVs stay well defined */
  const int x0 = (int)clamp(x0f, -1.0e8f, 1.0e8f), y0 = (int)clamp(y0f, -1.0e8f, 1.0e8f);
  const int xa = wrap_texel(x0, lv->width, t->wrap_s), xb = wrap_texel(x0 + 1, lv->width, t->wrap_s);
  const int ya = wrap_texel(y0, lv->height, t->wrap_t), yb = wrap_texel(y0 + 1, lv->height, t->wrap_t);
  const float4 c00 = texel(texels, srgb_lut, lv, xa, ya, srgb), c10 = texel(texels, srgb_lut, lv, xb, ya, srgb);
  const float4 c01 = texel(texels, srgb_lut, lv, xa, yb, srgb), c11 = texel(texels, srgb_lut, lv, xb, yb, srgb);
  const float4 top = c00 + (c10 - c00) * ax, bottom = c01 + (c11 - c01) * ax;
  return top + (bottom - top) * ay;
}

/* Trilinear sample at level of detail lambda in [0, levels - 1]: bilinear in levels floor(lambda) and
 * the next, mixed by the fraction (one level where lambda is whole, e.g. 0 when magnified). */
inline float4 sample_texture(global const uchar4* texels, global const float* srgb_lut, const PmrTexture* t, float u,
                             float v, float lambda, bool srgb) {
  const int k = (int)lambda;
  const float frac = lambda - (float)k;
  const TexLevel a = texture_level(t, k);
  const float4 ca = sample_level(texels, srgb_lut, t, &a, u, v, srgb);
  if (frac == 0.0f) return ca;
  const TexLevel b = next_level(a);
  return ca + (sample_level(texels, srgb_lut, t, &b, u, v, srgb) - ca) * frac;
}

/* The screen-space derivatives of one lane's source barycentrics, per output pixel in x and in y
 * (cl/shade.h's bary_gradient_lanes computes them). */
typedef struct {
  float3 dx, dy;
} BaryGrad;

/* Level of detail of texture t for texture-coordinate derivatives dx, dy (before the map's transform m,
 * whose 2x2 linear part applies to them): rho = the longer of the two footprint axes in level-0 texels,
 * lambda = log2 rho clamped to [0, levels - 1] (fmax also maps a NaN of a degenerate footprint to 0). */
inline float texture_lod(global const float* m, const PmrTexture* t, float2 dx, float2 dy) {
  const float w = (float)t->width, h = (float)t->height;
  const float2 x = (float2)((m[0] * dx.x + m[1] * dx.y) * w, (m[3] * dx.x + m[4] * dx.y) * h);
  const float2 y = (float2)((m[0] * dy.x + m[1] * dy.y) * w, (m[3] * dy.x + m[4] * dy.y) * h);
  const float rho2 = fmax(dot(x, x), dot(y, y)); /* rho^2: log2 rho = log2(rho^2) / 2, without a sqrt */
  return fmin(fmax(0.5f * log2(rho2), 0.0f), (float)(t->levels - 1));
}

#endif
