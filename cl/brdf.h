/* The glTF 2.0 metallic-roughness BRDF of --shading pbr (docs/SHADING.md): Schlick's Fresnel, the GGX
 * (Trowbridge-Reitz) distribution and the height-correlated Smith visibility, for one light, plus the
 * punctual lights of KHR_lights_punctual. Every dot product with n is clamped to [0, 1]. The C++
 * reference (tests/reference/pbr_reference.cpp) computes the same in double precision. */
#ifndef PMR_CL_BRDF_H
#define PMR_CL_BRDF_H

#define PMR_PI_F 3.14159265358979f

/* Roughness as the material gives it (factor x texture G) clamped to [0.03, 1]; alpha = r^2. */
inline float pbr_roughness(float r) { return clamp(r, 0.03f, 1.0f); }

inline float3 pbr_f0(float3 base, float metallic) { return mix((float3)(0.04f), base, metallic); }

/* GGX normal distribution D for cos(n, h) = nh and a2 = alpha^2. */
inline float ggx_d(float nh, float a2) {
  const float d = nh * nh * (a2 - 1.0f) + 1.0f;
  return a2 / (PMR_PI_F * d * d);
}

/* Height-correlated Smith visibility V = G / (4 nl nv); 0 where its denominator is 0. */
inline float smith_vis(float nl, float nv, float a2) {
  const float s = nl * sqrt(nv * nv * (1.0f - a2) + a2) + nv * sqrt(nl * nl * (1.0f - a2) + a2);
  return s > 0.0f ? 0.5f / s : 0.0f;
}

/* f(l, v) * dot(n, l): the radiance reflected toward v per unit irradiance from the direction l (unit,
 * toward the light). n and v are unit vectors; r is the clamped roughness. */
inline float3 brdf_cos(float3 base, float metallic, float r, float3 n, float3 v, float3 l) {
  const float nl = clamp(dot(n, l), 0.0f, 1.0f);
  if (nl <= 0.0f) return (float3)(0.0f);
  const float nv = clamp(dot(n, v), 0.0f, 1.0f);
  const float3 hv = l + v;
  const float hl = length(hv);
  const float3 h = hl > 0.0f ? hv / hl : n;
  const float nh = clamp(dot(n, h), 0.0f, 1.0f), vh = clamp(dot(v, h), 0.0f, 1.0f);
  const float alpha = r * r, a2 = alpha * alpha;
  const float3 f0 = pbr_f0(base, metallic);
  const float k = 1.0f - vh, k2 = k * k;
  const float3 F = f0 + (1.0f - f0) * (k2 * k2 * k);
  const float3 c_diff = base * (1.0f - metallic);
  const float3 f = (1.0f - F) * c_diff * (1.0f / PMR_PI_F) + F * (ggx_d(nh, a2) * smith_vis(nl, nv, a2));
  return f * nl;
}

/* KHR_lights_punctual at the surface point p: the unit direction toward the light (*l) and the
 * irradiance E it delivers on a surface facing it. Directional: colour x intensity (lux), travelling
 * along `direction` (the node's -Z). Point and spot: colour x intensity (candela) / d^2, times the range
 * window clamp(1 - (d / range)^4, 0, 1) when range > 0; a spot also times
 * clamp((cos_angle - cos_outer) / max(0.001, cos_inner - cos_outer), 0, 1)^2 with cos_angle between
 * its direction and -l. type is PMR_LIGHT_* (include/pmr/shared.h, with the light table's PmrLight). */
inline float3 light_irradiance(int type, float3 color_intensity, float3 position, float3 direction, float range,
                               float cos_inner, float cos_outer, float3 p, float3* l) {
  if (type == PMR_LIGHT_DIRECTIONAL) {
    *l = -direction;
    return color_intensity;
  }
  const float3 d = position - p;
  const float d2 = dot(d, d);
  if (!(d2 > 0.0f)) {
    *l = (float3)(0.0f);
    return (float3)(0.0f);
  }
  const float dist = sqrt(d2);
  *l = d / dist;
  float w = 1.0f / d2;
  if (range > 0.0f) {
    const float q = dist / range, q2 = q * q;
    w *= clamp(1.0f - q2 * q2, 0.0f, 1.0f);
  }
  if (type == PMR_LIGHT_SPOT) {
    const float c = dot(direction, -*l);
    const float s = clamp((c - cos_outer) / max(0.001f, cos_inner - cos_outer), 0.0f, 1.0f);
    w *= s * s;
  }
  return color_intensity * w;
}

#endif
