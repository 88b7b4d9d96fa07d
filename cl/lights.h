/* The lights (part of the one shading module, cl/shade.h): what a light delivers at the lanes' surface
 * points, independent of the view: the direction toward it and its irradiance on a surface facing it.
 * The lobes (cl/brdf.h) turn that into what each view sees. */
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

#endif
