/* The environment image of --shading pbr (--environment): the tables host/shading/environment.cpp
 * prefilters once per environment (PmrEnvironment says where they lie in the data), sampled exactly as
 * the host lookups Environment::level_sample, irradiance and prefiltered do (host/shading/environment.h
 * states the mapping and the tables; the C++ reference tests read those host lookups). */
#ifndef PMR_CL_ENVIRONMENT_H
#define PMR_CL_ENVIRONMENT_H

#define PMR_INV_2PI_F 0.159154943091895f
#define PMR_INV_PI_F 0.318309886183791f

/* atan2 of four pairs at once, to 2e-8 rad plus rounding (Abramowitz and Stegun 4.4.49 for atan on
 * [0, 1], then the octant), signs and zeros as atan2's: the builtin's scalar calls cost more than the
 * rest of the lookups together. */
inline float4 env_atan2(float4 y, float4 x) {
  const float4 ax = fabs(x), ay = fabs(y);
  const float4 hi = fmax(ax, ay), lo = fmin(ax, ay);
  const float4 t = select(lo / hi, (float4)(0.0f), hi == (float4)(0.0f));
  const float4 s = t * t;
  float4 p = (float4)(0.0028662257f);
  p = p * s - 0.0161657367f;
  p = p * s + 0.0429096138f;
  p = p * s - 0.0752896400f;
  p = p * s + 0.1065626393f;
  p = p * s - 0.1420889944f;
  p = p * s + 0.1999355085f;
  p = p * s - 0.3333314528f;
  float4 a = t + t * s * p;
  a = select(a, 1.57079632679f - a, ay > ax);
  a = select(a, 3.14159265359f - a, signbit(x));
  return copysign(a, y);
}

/* Image coordinates (u, v) of two directions a and b (any length) at once, as (u_a, v_a, u_b, v_b),
 * with the map's rotation: the map turned by +angle reads the image at d turned by -angle.
 * u = 1/2 + atan2(x, -z) / (2 pi) from the left, v = acos(y) / pi from the top, written as
 * atan2(sqrt(x^2 + z^2), y) so the directions need no normalizing. */
inline float4 env_uv(global const PmrEnvironment* e, float3 a, float3 b) {
  const float c = e->rotation_cos, s = e->rotation_sin;
  const float ax = c * a.x - s * a.z, az = s * a.x + c * a.z, bx = c * b.x - s * b.z, bz = s * b.x + c * b.z;
  const float4 y = (float4)(ax, sqrt(ax * ax + az * az), bx, sqrt(bx * bx + bz * bz));
  const float4 x = (float4)(-az, a.y, -bz, b.y);
  return env_atan2(y, x) * (float4)(PMR_INV_2PI_F, PMR_INV_PI_F, PMR_INV_2PI_F, PMR_INV_PI_F) +
         (float4)(0.5f, 0.0f, 0.5f, 0.0f);
}

/* 2^x and log2(x) (x > 0, normal) for the geometric blend, to about 2e-7 relative (Cephes's exp2f and
 * logf polynomials), four lanes at once. */
inline float4 env_exp2(float4 x) {
  x = clamp(x, -126.0f, 126.0f);
  const float4 k = rint(x), f = x - k; /* f in [-1/2, 1/2] */
  float4 p = (float4)(1.535336188319500e-4f);
  p = p * f + 1.339887440266574e-3f;
  p = p * f + 9.618437357674640e-3f;
  p = p * f + 5.550332471162809e-2f;
  p = p * f + 2.402264791363012e-1f;
  p = p * f + 6.931472028550421e-1f;
  const float4 m = 1.0f + f * p;
  return as_float4(as_int4(m) + (convert_int4(k) << 23));
}

inline float4 env_log2(float4 x) {
  const int4 bits = as_int4(x);
  int4 e = ((bits >> 23) & 0xff) - 127;
  float4 m = as_float4((bits & 0x007fffff) | 0x3f800000); /* [1, 2) */
  const int4 big = m > (float4)(1.41421356f);
  m = select(m, m * 0.5f, big);
  e -= big;                              /* -1 where true: e + 1 */
  const float4 z = m - 1.0f, z2 = z * z; /* z in [-0.29, 0.42): ln(1 + z) */
  float4 p = (float4)(7.0376836292e-2f);
  p = p * z - 1.1514610310e-1f;
  p = p * z + 1.1676998740e-1f;
  p = p * z - 1.2420140846e-1f;
  p = p * z + 1.4249322787e-1f;
  p = p * z - 1.6668057665e-1f;
  p = p * z + 2.0000714765e-1f;
  p = p * z - 2.4999993993e-1f;
  p = p * z + 3.3333331174e-1f;
  const float4 ln = z - 0.5f * z2 + z * z2 * p;
  return ln * 1.44269504089f + convert_float4(e);
}

/* The four texels and weights of a bilinear lookup at (u, v) on a W x H level: texel centers at
 * (j + 1/2) / W, wrapping in u; v clamped half a texel beyond the outer rows' centers, between them
 * and the pole rows stored above and below (host/shading/environment.h). */
typedef struct {
  uint i00, i10, i01, i11; /* texel indices, row-major */
  float fx, fy;
} EnvTaps;

inline EnvTaps env_taps(uint W, uint H, float2 uv) {
  const float x = uv.x * (float)W - 0.5f, y = clamp(uv.y * (float)H - 0.5f, -0.5f, (float)H - 0.5f);
  const float x0f = floor(x), y0f = floor(y);
  /* u is in [0, 1], so x0 is in [-1, W - 1]: one step of wrapping each way suffices */
  const int xi = (int)x0f, yi = (int)y0f;
  const uint x0 = xi < 0 ? W - 1u : min((uint)xi, W - 1u), x1 = x0 + 1u < W ? x0 + 1u : 0u;
  const uint y0 = (uint)(yi + 1) * W, y1 = (uint)min(yi + 2, (int)H + 1) * W; /* rows with the pole rows */
  EnvTaps k = {y0 + x0, y0 + x1, y1 + x0, y1 + x1, x - x0f, y - y0f};
  return k;
}

/* The bilinear lookup of level `level` (before intensity) with taps k. */
inline float3 env_fetch(global const PmrEnvironment* e, global const float4* data, int level, EnvTaps k) {
  global const float4* t = data + e->levels[level].offset / 4u;
  const float3 a = t[k.i00].xyz, b = t[k.i10].xyz, c = t[k.i01].xyz, d = t[k.i11].xyz;
  const float3 top = a + (b - a) * k.fx, bottom = c + (d - c) * k.fx;
  return top + (bottom - top) * k.fy;
}

inline EnvTaps env_level_taps(global const PmrEnvironment* e, int level, float2 uv) {
  return env_taps(e->levels[level].width, e->levels[level].height, uv);
}

/* I(n), the cosine-weighted mean radiance about n (irradiance / pi): the last level (r = 1), at n's
 * (u, v). */
inline float3 env_irradiance(global const PmrEnvironment* e, global const float4* data, float2 uv) {
  const int last = (int)e->level_count - 1;
  return env_fetch(e, data, last, env_level_taps(e, last, uv)) * e->intensity;
}

/* P(d, r) at d's (u, v), the GGX-prefiltered radiance about d for roughness r (clamped to [0, 1]): the
 * fractional level coordinate c(r) from its table (linear between nodes), then levels l = floor(c) and
 * l + 1, blended by f = c - l linearly from level 0 (the image) and geometrically per channel between
 * prefiltered levels where both are positive. */
inline float3 env_prefiltered(global const PmrEnvironment* e, global const float4* data, float2 uv, float r) {
  global const float* table = (global const float*)data + e->roughness_offset;
  const int nodes = (int)e->roughness_nodes;
  const float x = clamp(r, 0.0f, 1.0f) * (float)(nodes - 1);
  const int i = min((int)x, nodes - 2);
  const float fr = x - (float)i;
  const float c = (1.0f - fr) * table[i] + fr * table[i + 1];
  const int last = (int)e->level_count - 1;
  const int l0 = clamp((int)floor(c), 0, last - 1);
  const float f = clamp(c - (float)l0, 0.0f, 1.0f);
  const EnvTaps ka = env_level_taps(e, l0, uv);
  if (f == 0.0f) return env_fetch(e, data, l0, ka) * e->intensity;
  /* neighbouring levels mostly share their size, and then their taps */
  const EnvTaps kb = e->levels[l0 + 1].width == e->levels[l0].width ? ka : env_level_taps(e, l0 + 1, uv);
  if (f == 1.0f) return env_fetch(e, data, l0 + 1, kb) * e->intensity;
  const float4 a = (float4)(env_fetch(e, data, l0, ka), 1.0f), b = (float4)(env_fetch(e, data, l0 + 1, kb), 1.0f);
  const float4 linear = a + (b - a) * f;
  if (l0 == 0) return linear.xyz * e->intensity;
  /* a (b / a)^f interpolates a point light's peak exactly (environment.h); linear where a channel is 0 */
  const float4 geometric = a * env_exp2(f * env_log2(b / a));
  return select(linear, geometric, a > (float4)(0.0f) && b > (float4)(0.0f)).xyz * e->intensity;
}

#endif
