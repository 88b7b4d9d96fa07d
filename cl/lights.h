/* The lights (part of the one shading module, cl/shade.h): what a light delivers at the lanes' surface
 * points, independent of the view: the direction toward it, its irradiance on a surface facing it, and
 * the fraction of it that arrives past the casters (shadow_visibility_lanes: DESIGN section 4d). The lobes
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

/* The visibility from map m at the lanes' world points p of face normals ng (unit, either side), in
 * the lanes `act` (1 elsewhere): the depth comparisons (shadow_tap) at the 4 texels around each point,
 * bilinearly weighted (filtered over one texel, the same in every view). The arithmetic in vectors,
 * the taps gathered lane by lane. */
inline sfloat shadow_map_visibility_lanes(global const PmrShadowMap* m, global const uint* depth, sfloat3 p, sfloat3 ng,
                                          sint act) {
  const sfloat3 origin = s3_splat(vload3(0, m->origin)), axis = s3_splat(vload3(0, m->axis));
  const sfloat z_p = s3_dot(s3_sub(p, origin), axis);
  const sfloat texel = m->perspective ? m->texel * z_p : (sfloat)(m->texel);
  sfloat3 to_light = s3_neg(axis);
  if (m->perspective) {
    const sfloat3 e = s3_sub(origin, p);
    to_light = s3_scale(e, rsqrt(s3_dot(e, e)));
  }
  const sfloat cos_l = s3_dot(ng, to_light);
  const sfloat3 side = s3_select(ng, s3_neg(ng), cos_l < 0.0f);
  const sfloat c = fmax(fabs(cos_l), 1e-4f), tan_l = fmin(sqrt(fmax(1.0f - c * c, 0.0f)) / c, 50.0f);
  const sfloat3 d = s3_sub(s3_add(p, s3_scale(side, PMR_SHADOW_NORMAL_OFFSET * texel)), origin);
  const sfloat z = s3_dot(d, axis);
  /* a perspective map sees nothing nearer than its near plane */
  const sint live = m->perspective ? act & (z_p > m->near_z) & (z > m->near_z) : act;
  const sfloat w = m->perspective ? 1.0f / z : (sfloat)(1.0f), half_size = 0.5f * (float)m->size;
  const sfloat x = (s3_dot(d, s3_splat(vload3(0, m->right))) * w + 1.0f) * half_size - 0.5f;
  const sfloat y = (s3_dot(d, s3_splat(vload3(0, m->up))) * w + 1.0f) * half_size - 0.5f;
  const sfloat ref = z - (PMR_SHADOW_BIAS + PMR_SHADOW_SLOPE_BIAS * tan_l) * texel;
  const sfloat fx0 = floor(x), fy0 = floor(y);
  float xs[SW], ys[SW], refs[SW], t[4][SW];
  int on[SW];
  vstore_s(fx0, 0, xs), vstore_s(fy0, 0, ys), vstore_s(ref, 0, refs), vstore_s(live, 0, on);
  for (int l = 0; l < SW; ++l) {
    /* idle lanes read nothing (their coordinates may be anything) */
    const int x0 = on[l] ? (int)xs[l] : -2, y0 = on[l] ? (int)ys[l] : -2;
    t[0][l] = shadow_tap(m, depth, x0, y0, refs[l]), t[1][l] = shadow_tap(m, depth, x0 + 1, y0, refs[l]);
    t[2][l] = shadow_tap(m, depth, x0, y0 + 1, refs[l]), t[3][l] = shadow_tap(m, depth, x0 + 1, y0 + 1, refs[l]);
  }
  const sfloat fx = x - fx0, fy = y - fy0;
  const sfloat top = mix(vload_s(0, t[0]), vload_s(0, t[1]), fx), bottom = mix(vload_s(0, t[2]), vload_s(0, t[3]), fx);
  return select((sfloat)(1.0f), mix(top, bottom, fy), live);
}

/* The visibility of light `light`'s sample s at the lanes' points p (`act`; 1 elsewhere): its map, or
 * of its cube the face of each point's major axis from the sample's point (a group of lanes per face). */
inline sfloat shadow_sample_visibility_lanes(global const PmrShadowMap* maps, global const uint* depth,
                                             global const PmrLight* light, int s, sfloat3 p, sfloat3 ng, sint act) {
  const int faces = light->shadow_maps / light->shadow_samples, k = light->shadow + s * faces;
  if (faces == 1) return shadow_map_visibility_lanes(&maps[k], depth, p, ng, act);
  const sfloat3 d = s3_sub(p, s3_splat(vload3(0, maps[k].origin)));
  const sfloat ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
  const sint major_x = (ax >= ay) & (ax >= az), major_y = ~major_x & (ay >= az);
  /* +X, -X, +Y, -Y, +Z, -Z */
  const sint face = select(select((sint)(4), (sint)(2), major_y), (sint)(0), major_x) +
                    select((sint)(0), (sint)(1), select(select(d.z, d.y, major_y), d.x, major_x) < 0.0f);
  sfloat v = 1.0f;
  for (int f = 0; f < 6; ++f) {
    const sint on = act & (face == f);
    if (any(on)) v = select(v, shadow_map_visibility_lanes(&maps[k + f], depth, p, ng, on), on);
  }
  return v;
}

/* A directional sample's share of the irradiance at receivers of normal rn (unit, on the side seen):
 * its cosine there. A sun's or a distant light's directions are spread evenly over the light, but a
 * large one low over the receiver's horizon (the studio's boxes) sends most of its irradiance through
 * its upper part: weighting by the cosine makes V the fraction of the irradiance that arrives (DESIGN
 * 4d). The points of a local light see a receiver at nearly one angle and keep weight 1 (measured on
 * the rect and disk of Shadows.SoftShadowsMatchTheExactFraction, weighting them by the irradiance each
 * sends, cos cos / d^2, gave a larger mean error: 0.0329 and 0.0290 against 0.0266 and 0.0235). */
inline sfloat shadow_sample_weight_lanes(global const PmrShadowMap* m, sfloat3 rn) {
  return m->perspective ? (sfloat)(1.0f) : fmax(s3_dot(rn, s3_splat(-vload3(0, m->axis))), 0.0f);
}

/* The visibility of light `light` at the lanes' world points p of face normals ng, seen on the side of
 * shading normals n (`act`; 1 elsewhere). A point-like light: its map's visibility. A light with a
 * size: the mean of its samples' visibilities weighted by their share (shadow_sample_weight_lanes;
 * samples below a receiver's horizon are not read); a receiver facing away from every sample gets
 * none of the light's irradiance, and its first sample (nearest the light's centre) stands for the rest
 * in what ignores the horizon (transmission, sheen). */
inline sfloat shadow_visibility_lanes(global const PmrShadowMap* maps, global const uint* depth,
                                      global const PmrLight* light, sfloat3 p, sfloat3 ng, sfloat3 n, sint act) {
  const int samples = light->shadow_samples;
  if (samples == 1) return shadow_sample_visibility_lanes(maps, depth, light, 0, p, ng, act);
  const sfloat3 rn = s3_select(ng, s3_neg(ng), s3_dot(ng, n) < 0.0f);
  sfloat sum = 0.0f, weight = 0.0f;
  for (int s = 0; s < samples; ++s) {
    const sfloat w = shadow_sample_weight_lanes(&maps[light->shadow + s * (light->shadow_maps / samples)], rn);
    const sint on = act & (w > 0.0f);
    if (!any(on)) continue;
    sum += select((sfloat)(0.0f), w * shadow_sample_visibility_lanes(maps, depth, light, s, p, ng, on), on);
    weight += select((sfloat)(0.0f), w, on);
  }
  const sint none = act & (weight == 0.0f);
  const sfloat first = any(none) ? shadow_sample_visibility_lanes(maps, depth, light, 0, p, ng, none) : (sfloat)(1.0f);
  return select(select(sum / weight, first, none), (sfloat)(1.0f), ~act);
}

/* The environment's occlusion (DESIGN section 4d; host/shading/environment_occlusion.h) at the lanes'
 * points p of face normals ng, seen on the side of shading normals n (`act`; 1 elsewhere), from the
 * light table's entry `occ`: one orthographic map along each of its directions d toward the environment,
 * of weight w (the environment's radiance about d). *diffuse: the directions' visibilities weighted by
 * w max(n.d, 0); *specular: weighted by that times exp(sharpness (r.d - 1)), a lobe about the reflected
 * direction r (unit). Directions below the face's horizon are not read; where no direction weighs
 * anything the visibility is 1. The maps' lookups are the same in every view; r and the lobe are the
 * view's. */
inline void environment_visibility_lanes(global const PmrShadowMap* maps, global const uint* depth,
                                         global const PmrLight* occ, sfloat3 p, sfloat3 ng, sfloat3 n, sfloat3 r,
                                         sfloat sharpness, sint act, sfloat* diffuse, sfloat* specular) {
  const sfloat3 rn = s3_select(ng, s3_neg(ng), s3_dot(ng, n) < 0.0f);
  sfloat vd = 0.0f, wd = 0.0f, vs = 0.0f, ws = 0.0f;
  for (int k = 0; k < occ->shadow_samples; ++k) {
    global const PmrShadowMap* m = &maps[occ->shadow + k];
    const sfloat3 d = s3_splat(-vload3(0, m->axis));
    const sfloat c = fmax(s3_dot(n, d), 0.0f);
    const sint on = act & (s3_dot(rn, d) > 0.0f) & (c > 0.0f);
    if (!any(on)) continue;
    const sfloat v = shadow_map_visibility_lanes(m, depth, p, ng, on);
    const sfloat w = select((sfloat)(0.0f), m->weight * c, on), g = w * exp(sharpness * (s3_dot(r, d) - 1.0f));
    vd += w * v, wd += w, vs += g * v, ws += g;
  }
  *diffuse = select((sfloat)(1.0f), vd / wd, act & (wd > 0.0f));
  *specular = select((sfloat)(1.0f), vs / ws, act & (ws > 0.0f));
}

#endif
