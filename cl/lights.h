/* The lights (part of the one shading module, cl/shade.h): what a light delivers at the lanes' surface
 * points, independent of the view: the direction toward it, its irradiance on a surface facing it, and
 * the fraction of it that arrives past the casters (shadow_visibility: DESIGN section 4d). The lobes
 * (cl/brdf.h) turn that into what each view sees. */
#ifndef PMR_CL_LIGHTS_H
#define PMR_CL_LIGHTS_H

#include "common.h"
#include "lanes.h"

/* KHR_lights_punctual at the surface points p: the unit directions toward the light (*l) and the
 * irradiance E it delivers on a surface facing it. Directional: colour x intensity (lux), travelling
 * along `direction` (the node's -Z). Point and spot: colour x intensity (candela) / d^2, times the range
 * window clamp(1 - (d / range)^4, 0, 1) when range > 0; a spot also times
 * clamp((cos_angle - cos_outer) / max(0.001, cos_inner - cos_outer), 0, 1)^2 with cos_angle between
 * its direction and -l. type is PMR_LIGHT_* (include/pmr/shared.h, with the light table's PmrLight).
 * A point at the light itself receives nothing (l = 0). */
inline sfloat3 light_irradiance(int type, float3 color_intensity, float3 position, float3 direction, float range,
                                float cos_inner, float cos_outer, sfloat3 p, sfloat3* l) {
  if (type == PMR_LIGHT_DIRECTIONAL) {
    *l = s3_splat(-direction);
    return s3_splat(color_intensity);
  }
  const sfloat3 d = s3_sub(s3_splat(position), p);
  const sfloat d2 = s3_dot(d, d);
  const sint lit = d2 > 0.0f;
  const sfloat dist = sqrt(d2);
  *l = s3_select(s3_splat((float3)(0.0f)), s3_scale(d, 1.0f / dist), lit);
  sfloat w = select((sfloat)(0.0f), 1.0f / d2, lit);
  if (range > 0.0f) {
    const sfloat q = dist / range, q2 = q * q;
    w *= clamp(1.0f - q2 * q2, 0.0f, 1.0f);
  }
  if (type == PMR_LIGHT_SPOT) {
    const sfloat c = -s3_dot(s3_splat(direction), *l);
    const sfloat s = clamp((c - cos_outer) / max(0.001f, cos_inner - cos_outer), 0.0f, 1.0f);
    w *= s * s;
  }
  return s3_scale(s3_splat(color_intensity), w);
}

/* Shadow lookups (DESIGN section 4d). Every offset is in texels of the map at the receiver, so it is
 * fixed in world space and a shadow's edge stays on its surface from view to view:
 * - the receiver moves PMR_SHADOW_NORMAL_OFFSET texels along its face normal, turned toward the light;
 * - its depth is compared less PMR_SHADOW_BIAS + PMR_SHADOW_SLOPE_BIAS x min(tan theta, 50) texels,
 *   theta between the face normal and the light.
 * A tap at lateral distance r from the receiver sees the receiver's own plane at most r tan theta
 * nearer: with r up to sqrt(2) texels (the 2 x 2 taps), offset / cos theta + slope bias x tan theta
 * exceeds it at every angle, so flat and curved receivers facing the light have no acne. */
#define PMR_SHADOW_NORMAL_OFFSET 1.0f
#define PMR_SHADOW_BIAS 0.2f
#define PMR_SHADOW_SLOPE_BIAS 0.5f

/* The light passing map m's texel (x, y) to depth `ref`: 0 behind its nearest opaque caster, else the
 * transmittance exp(-optical depth) of its translucent casters when ref lies beyond the nearest of
 * them, else 1; outside the map 1. */
inline float shadow_tap(global const PmrShadowMap* m, global const uint* depth, int x, int y, float ref) {
  if (x < 0 || y < 0 || x >= m->size || y >= m->size) return 1.0f;
  const size_t texel = (size_t)y * (size_t)m->size + (size_t)x;
  if (ref > as_float(depth[m->offset + texel])) return 0.0f;
  if (m->translucent == PMR_NO_TRANSLUCENT) return 1.0f;
  global const uint* pair = depth + m->translucent + 2 * texel;
  return ref > as_float(pair[0]) ? exp(-(float)pair[1] * (1.0f / PMR_SHADOW_OPTICAL_ONE)) : 1.0f;
}

/* The visibility from map m at world point p of face normal ng (unit, either side): the depth
 * comparisons (shadow_tap) at the 4 texels around p, bilinearly weighted (filtered over one texel, the
 * same in every view). */
inline float shadow_map_visibility(global const PmrShadowMap* m, global const uint* depth, float3 p, float3 ng) {
  const float3 origin = vload3(0, m->origin), axis = vload3(0, m->axis);
  const float z_p = dot(p - origin, axis);
  if (m->perspective && z_p <= m->near_z) return 1.0f;
  const float texel = m->perspective ? m->texel * z_p : m->texel;
  const float3 to_light = m->perspective ? normalize(origin - p) : -axis;
  const float cos_l = dot(ng, to_light);
  const float3 side = cos_l < 0.0f ? -ng : ng;
  const float c = fmax(fabs(cos_l), 1e-4f), tan_l = fmin(sqrt(fmax(1.0f - c * c, 0.0f)) / c, 50.0f);
  const float3 d = p + side * (PMR_SHADOW_NORMAL_OFFSET * texel) - origin;
  const float z = dot(d, axis);
  if (m->perspective && z <= m->near_z) return 1.0f;
  const float w = m->perspective ? 1.0f / z : 1.0f, half_size = 0.5f * (float)m->size;
  const float x = (dot(d, vload3(0, m->right)) * w + 1.0f) * half_size - 0.5f;
  const float y = (dot(d, vload3(0, m->up)) * w + 1.0f) * half_size - 0.5f;
  const float ref = z - (PMR_SHADOW_BIAS + PMR_SHADOW_SLOPE_BIAS * tan_l) * texel;
  const float fx0 = floor(x), fy0 = floor(y), fx = x - fx0, fy = y - fy0;
  const int x0 = (int)fx0, y0 = (int)fy0;
  const float top = mix(shadow_tap(m, depth, x0, y0, ref), shadow_tap(m, depth, x0 + 1, y0, ref), fx);
  const float bottom = mix(shadow_tap(m, depth, x0, y0 + 1, ref), shadow_tap(m, depth, x0 + 1, y0 + 1, ref), fx);
  return mix(top, bottom, fy);
}

/* The visibility of light `light` at world point p of face normal ng: the mean over the light's
 * samples (1 for a point-like light; points or directions of its size) of their maps' visibility, a
 * cube's read at the face of p's major axis from the sample's point. 1: unshadowed. */
inline float shadow_visibility(global const PmrShadowMap* maps, global const uint* depth, global const PmrLight* light,
                               float3 p, float3 ng) {
  const int samples = light->shadow_samples, faces = light->shadow_maps / samples;
  float sum = 0.0f;
  for (int s = 0; s < samples; ++s) {
    int k = light->shadow + s * faces;
    if (faces == 6) {
      const float3 d = p - vload3(0, maps[k].origin), a = fabs(d);
      const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
      k += 2 * axis + ((axis == 0 ? d.x : axis == 1 ? d.y : d.z) < 0.0f ? 1 : 0);
    }
    sum += shadow_map_visibility(&maps[k], depth, p, ng);
  }
  return samples == 1 ? sum : sum * (1.0f / (float)samples);
}

/* shadow_visibility of the lanes `act` (1 elsewhere) at their points p, face normals ng. */
inline sfloat shadow_visibility_lanes(global const PmrShadowMap* maps, global const uint* depth,
                                      global const PmrLight* light, sfloat3 p, sfloat3 ng, sint act) {
  float px[SW], py[SW], pz[SW], nx[SW], ny[SW], nz[SW], v[SW];
  s3_store(p, px, py, pz);
  s3_store(ng, nx, ny, nz);
  int on[SW];
  vstore_s(act, 0, on);
  for (int l = 0; l < SW; ++l)
    v[l] = on[l] ? shadow_visibility(maps, depth, light, (float3)(px[l], py[l], pz[l]), (float3)(nx[l], ny[l], nz[l]))
                 : 1.0f;
  return vload_s(0, v);
}

#endif
