/* The environment image of --shading pbr (--environment): the tables host/shading/environment.cpp
 * prefilters once per environment (PmrEnvironment says where they lie in the data), sampled exactly as
 * the host lookups Environment::level_sample, irradiance and prefiltered do (host/shading/environment.h
 * states the mapping and the tables; the C++ reference tests read those host lookups). */
#ifndef PMR_CL_ENVIRONMENT_H
#define PMR_CL_ENVIRONMENT_H

#define PMR_INV_2PI_F 0.159154943091895f
#define PMR_INV_PI_F 0.318309886183791f

/* Image coordinates (u, v) of direction d (any length), with the map's rotation: the map turned by
 * +angle reads the image at d turned by -angle. u = 1/2 + atan2(x, -z) / (2 pi) from the left,
 * v = acos(y) / pi from the top, written as atan2(sqrt(x^2 + z^2), y) so d needs no normalizing. */
inline float2 env_uv(global const PmrEnvironment* e, float3 d) {
  const float c = e->rotation_cos, s = e->rotation_sin;
  const float x = c * d.x - s * d.z, y = d.y, z = s * d.x + c * d.z;
  return (float2)(0.5f + atan2(x, -z) * PMR_INV_2PI_F, atan2(sqrt(x * x + z * z), y) * PMR_INV_PI_F);
}

/* Level `level` at (u, v): bilinear between texel centers (j + 1/2) / W, wrapping in u, clamped in v.
 * Before intensity. */
inline float3 env_level(global const PmrEnvironment* e, global const float4* data, int level, float2 uv) {
  const uint W = e->levels[level].width, H = e->levels[level].height;
  global const float4* t = data + e->levels[level].offset / 4u;
  const float x = uv.x * (float)W - 0.5f, y = uv.y * (float)H - 0.5f;
  const float x0f = floor(x), y0f = floor(y);
  const float fx = x - x0f, fy = y - y0f;
  /* u is in [0, 1], so x0 is in [-1, W - 1]: one step of wrapping each way suffices */
  const int xi = (int)x0f;
  const uint x0 = xi < 0 ? W - 1u : min((uint)xi, W - 1u), x1 = x0 + 1u < W ? x0 + 1u : 0u;
  const int yi = (int)y0f;
  const uint y0 = (uint)clamp(yi, 0, (int)H - 1), y1 = (uint)clamp(yi + 1, 0, (int)H - 1);
  const float3 a = t[y0 * W + x0].xyz, b = t[y0 * W + x1].xyz, c = t[y1 * W + x0].xyz, d = t[y1 * W + x1].xyz;
  const float3 top = a + (b - a) * fx, bottom = c + (d - c) * fx;
  return top + (bottom - top) * fy;
}

/* I(n), the cosine-weighted mean radiance about n (irradiance / pi): the last level (r = 1). */
inline float3 env_irradiance(global const PmrEnvironment* e, global const float4* data, float3 n) {
  return env_level(e, data, (int)e->level_count - 1, env_uv(e, n)) * e->intensity;
}

/* P(d, r), the GGX-prefiltered radiance about d for roughness r (clamped to [0, 1]): the fractional
 * level coordinate c(r) from its table (linear between nodes), then levels l = floor(c) and l + 1 at
 * the same (u, v), blended by f = c - l linearly from level 0 (the image) and geometrically per
 * channel between prefiltered levels where both are positive. */
inline float3 env_prefiltered(global const PmrEnvironment* e, global const float4* data, float3 d, float r) {
  global const float* table = (global const float*)data + e->roughness_offset;
  const int nodes = (int)e->roughness_nodes;
  const float x = clamp(r, 0.0f, 1.0f) * (float)(nodes - 1);
  const int i = min((int)x, nodes - 2);
  const float fr = x - (float)i;
  const float c = (1.0f - fr) * table[i] + fr * table[i + 1];
  const int last = (int)e->level_count - 1;
  const int l0 = clamp((int)floor(c), 0, last - 1);
  const float f = clamp(c - (float)l0, 0.0f, 1.0f);
  const float2 uv = env_uv(e, d);
  if (f == 0.0f) return env_level(e, data, l0, uv) * e->intensity;
  if (f == 1.0f) return env_level(e, data, l0 + 1, uv) * e->intensity;
  const float3 a = env_level(e, data, l0, uv), b = env_level(e, data, l0 + 1, uv);
  float3 p = a + (b - a) * f;
  if (l0 >= 1) {
    /* a (b / a)^f interpolates a point light's peak exactly (environment.h); linear where a channel is 0 */
    if (a.x > 0.0f && b.x > 0.0f) p.x = a.x * pow(b.x / a.x, f);
    if (a.y > 0.0f && b.y > 0.0f) p.y = a.y * pow(b.y / a.y, f);
    if (a.z > 0.0f && b.z > 0.0f) p.z = a.z * pow(b.z / a.z, f);
  }
  return p * e->intensity;
}

#endif
