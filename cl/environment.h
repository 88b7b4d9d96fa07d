/* The environment image of --shading pbr (--environment): the tables host/shading/environment.cpp
 * prefilters once per environment (PmrEnvironment says where they lie in the data), sampled exactly as
 * the host lookups Environment::level_sample, irradiance and prefiltered do (host/shading/environment.h
 * states the mapping and the tables; the C++ reference tests read those host lookups), SW lanes at a
 * time (cl/lanes.h): the arithmetic in vectors, the texels gathered lane by lane. */
#ifndef PMR_CL_ENVIRONMENT_H
#define PMR_CL_ENVIRONMENT_H
#include "common.h"
#include "lanes.h"

#define PMR_INV_2PI_F 0.159154943091895f
#define PMR_INV_PI_F 0.318309886183791f

/* atan2 of SW pairs at once, to 2e-8 rad plus rounding (Abramowitz and Stegun 4.4.49 for atan on
 * [0, 1], then the octant), signs and zeros as atan2's: the builtin's scalar calls cost more than the
 * rest of the lookups together. */
inline sfloat env_atan2(sfloat y, sfloat x) {
  const sfloat ax = fabs(x), ay = fabs(y);
  const sfloat hi = fmax(ax, ay), lo = fmin(ax, ay);
  const sfloat t = select(lo / hi, (sfloat)(0.0f), hi == (sfloat)(0.0f));
  const sfloat s = t * t;
  sfloat p = (sfloat)(0.0028662257f);
  p = p * s - 0.0161657367f;
  p = p * s + 0.0429096138f;
  p = p * s - 0.0752896400f;
  p = p * s + 0.1065626393f;
  p = p * s - 0.1420889944f;
  p = p * s + 0.1999355085f;
  p = p * s - 0.3333314528f;
  sfloat a = t + t * s * p;
  a = select(a, 1.57079632679f - a, ay > ax);
  a = select(a, 3.14159265359f - a, signbit(x));
  return copysign(a, y);
}

/* Image coordinates (u, v) of SW directions d (any length), with the map's rotation: the map turned by
 * +angle reads the image at d turned by -angle. u = 1/2 + atan2(x, -z) / (2 pi) from the left,
 * v = acos(y) / pi from the top, written as atan2(sqrt(x^2 + z^2), y) so the directions need no
 * normalizing. */
inline void env_uv(global const PmrEnvironment* e, sfloat3 d, sfloat* u, sfloat* v) {
  const float c = e->rotation_cos, s = e->rotation_sin;
  const sfloat x = c * d.x - s * d.z, z = s * d.x + c * d.z;
  *u = env_atan2(x, -z) * PMR_INV_2PI_F + 0.5f;
  *v = env_atan2(sqrt(x * x + z * z), d.y) * PMR_INV_PI_F;
}

/* The four texels and weights of bilinear lookups at (u, v), one per lane, each lane on its own level
 * of W x H texels whose pole row starts at texel `first` of the data: texel centers at (j + 1/2) / W,
 * wrapping in u; v clamped half a texel beyond the outer rows' centers, between them and the pole rows
 * stored above and below (host/shading/environment.h). */
typedef struct {
  sint i00, i10, i01, i11; /* texel indices into the data */
  sfloat fx, fy;
} EnvTaps;

inline EnvTaps env_taps(sint W, sint H, sint first, sfloat u, sfloat v) {
  const sfloat Hf = convert_sfloat(H);
  const sfloat x = u * convert_sfloat(W) - 0.5f, y = fmin(fmax(v * Hf - 0.5f, -0.5f), Hf - 0.5f);
  const sfloat x0f = floor(x), y0f = floor(y);
  /* u is in [0, 1], so x0 is in [-1, W - 1]: one step of wrapping each way suffices */
  const sint xi = convert_int8(x0f), yi = convert_int8(y0f);
  const sint x0 = select(min(xi, W - 1), W - 1, xi < 0), x1 = select((sint)(0), x0 + 1, x0 + 1 < W);
  const sint y0 = first + (yi + 1) * W, y1 = first + min(yi + 2, H + 1) * W; /* rows with the pole rows */
  EnvTaps k = {y0 + x0, y0 + x1, y1 + x0, y1 + x1, x - x0f, y - y0f};
  return k;
}

/* The taps of level `level` of each lane (a level index per lane). */
inline EnvTaps env_level_taps(global const PmrEnvironment* e, sint level, sfloat u, sfloat v) {
  int l[SW], w[SW], h[SW], first[SW];
  vstore_s(level, 0, l);
  for (int k = 0; k < SW; ++k) {
    global const PmrEnvLevel* L = &e->levels[l[k]];
    w[k] = (int)L->width, h[k] = (int)L->height, first[k] = (int)(L->offset / 4u);
  }
  return env_taps(vload_s(0, w), vload_s(0, h), vload_s(0, first), u, v);
}

/* The bilinear lookups (before intensity) of taps k: the texels gathered lane by lane, the weights
 * applied in vectors. */
inline sfloat3 env_fetch(global const float4* data, EnvTaps k) {
  int at[4][SW];
  vstore_s(k.i00, 0, at[0]), vstore_s(k.i10, 0, at[1]), vstore_s(k.i01, 0, at[2]), vstore_s(k.i11, 0, at[3]);
  float t[4][3][SW];
  for (int l = 0; l < SW; ++l)
    for (int q = 0; q < 4; ++q) {
      const float4 p = data[at[q][l]];
      t[q][0][l] = p.x, t[q][1][l] = p.y, t[q][2][l] = p.z;
    }
  sfloat c[3];
  for (int ch = 0; ch < 3; ++ch) {
    const sfloat a = vload_s(0, t[0][ch]), b = vload_s(0, t[1][ch]), cc = vload_s(0, t[2][ch]),
                 d = vload_s(0, t[3][ch]);
    const sfloat top = a + (b - a) * k.fx, bottom = cc + (d - cc) * k.fx;
    c[ch] = top + (bottom - top) * k.fy;
  }
  return s3(c[0], c[1], c[2]);
}

/* I(n), the cosine-weighted mean radiance about n (irradiance / pi), for each lane's n at (u, v): the
 * last level (r = 1). */
inline sfloat3 env_irradiance(global const PmrEnvironment* e, global const float4* data, sfloat u, sfloat v) {
  global const PmrEnvLevel* L = &e->levels[e->level_count - 1u]; /* the same level in every lane */
  const EnvTaps k = env_taps((sint)((int)L->width), (sint)((int)L->height), (sint)((int)(L->offset / 4u)), u, v);
  return s3_scale(env_fetch(data, k), (sfloat)(e->intensity));
}

/* c(r), the fractional level coordinate of each lane's roughness, from its table (linear between
 * nodes). */
inline sfloat env_level_coordinate(global const PmrEnvironment* e, global const float4* data, sfloat r) {
  global const float* table = (global const float*)data + e->roughness_offset;
  const int nodes = (int)e->roughness_nodes;
  const sfloat x = clamp(r, 0.0f, 1.0f) * (float)(nodes - 1);
  const sint i = min(convert_int8(x), nodes - 2);
  const sfloat fr = x - convert_float8(i);
  int at[SW];
  float lo[SW], hi[SW];
  vstore_s(i, 0, at);
  for (int l = 0; l < SW; ++l) lo[l] = table[at[l]], hi[l] = table[at[l] + 1];
  return (1.0f - fr) * vload_s(0, lo) + fr * vload_s(0, hi);
}

/* P(d, r) for each lane's d at (u, v) and roughness r (clamped to [0, 1]): levels l = floor(c(r)) and
 * l + 1, blended by f = c - l linearly from level 0 (the image) and geometrically per channel between
 * prefiltered levels where both are positive; f = 0 and f = 1 read one level exactly. */
inline sfloat3 env_prefiltered(global const PmrEnvironment* e, global const float4* data, sfloat u, sfloat v,
                               sfloat r) {
  const sfloat c = env_level_coordinate(e, data, r);
  const int last = (int)e->level_count - 1;
  const sint l0 = clamp(convert_int8(floor(c)), 0, last - 1);
  const sfloat f = clamp(c - convert_float8(l0), 0.0f, 1.0f);
  const sfloat3 a = env_fetch(data, env_level_taps(e, l0, u, v)), b = env_fetch(data, env_level_taps(e, l0 + 1, u, v));
  const sint at_a = f == (sfloat)(0.0f), at_b = f == (sfloat)(1.0f), linear = l0 == (sint)(0);
  sfloat out[3];
  const sfloat ac[3] = {a.x, a.y, a.z}, bc[3] = {b.x, b.y, b.z};
  for (int ch = 0; ch < 3; ++ch) {
    /* a (b / a)^f interpolates a point light's peak exactly (environment.h); linear where a channel is 0 */
    const sfloat lin = ac[ch] + (bc[ch] - ac[ch]) * f;
    const sint geometric = !linear & (ac[ch] > 0.0f) & (bc[ch] > 0.0f);
    sfloat p = select(lin, ac[ch] * exp2_lanes(f * log2_lanes(bc[ch] / ac[ch])), geometric);
    p = select(select(p, bc[ch], at_b), ac[ch], at_a);
    out[ch] = p * e->intensity;
  }
  return s3(out[0], out[1], out[2]);
}

/* S(d, s) of KHR_materials_sheen for each lane's d at (u, v) and sheen roughness s (clamped to
 * [PMR_SHEEN_MIN_ROUGHNESS, 1]): the linear blend of the two sheen levels around s in log(s). */
inline sfloat3 env_sheen(global const PmrEnvironment* e, global const float4* data, sfloat u, sfloat v, sfloat s) {
  /* the levels are evenly spaced in log(s) */
  const float k = (PMR_SHEEN_LEVELS - 1) / -log2(PMR_SHEEN_MIN_ROUGHNESS);
  const sfloat c = log2_lanes(clamp(s, PMR_SHEEN_MIN_ROUGHNESS, 1.0f) * (1.0f / PMR_SHEEN_MIN_ROUGHNESS)) * k;
  const sint l0 = min(convert_int8(c), PMR_SHEEN_LEVELS - 2);
  const sfloat f = c - convert_float8(l0);
  /* the sheen levels are all of one size and back to back: one set of taps, offset by whole levels */
  global const PmrEnvLevel* L = &e->levels[e->sheen_first];
  const int W = (int)L->width, H = (int)L->height, stride = W * (H + 2);
  EnvTaps ta = env_taps((sint)(W), (sint)(H), (sint)((int)(L->offset / 4u)) + l0 * stride, u, v), tb = ta;
  tb.i00 += stride, tb.i10 += stride, tb.i01 += stride, tb.i11 += stride;
  const sfloat3 a = env_fetch(data, ta), b = env_fetch(data, tb);
  return s3_scale(s3_add(s3_scale(a, 1.0f - f), s3_scale(b, f)), (sfloat)(e->intensity));
}

#endif
