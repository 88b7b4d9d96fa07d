/* The environment's light at the lanes (part of the one shading module, cl/shade.h): the environment
 * image's irradiance I(n) and prefiltered radiance P(d, r) (cl/environment.h), or the uniform default's
 * radiance, and the split-sum and sheen albedo tables the lobes scale them by. I(n) depends on the
 * surface alone; P, A and B on the view through the reflected direction and n.v. */
#ifndef PMR_CL_ENVIRONMENT_LIGHT_H
#define PMR_CL_ENVIRONMENT_LIGHT_H

#include "environment.h"
#include "shade_inputs.h"

/* The image coordinates of the directions d where `act`: idle lanes look up +Y (their values are
 * ignored, but their texel indices are read). */
inline void environment_uv(const ShadeInputs* in, sfloat3 d, sint act, sfloat* u, sfloat* v) {
  const sfloat3 up = s3((sfloat)(0.0f), (sfloat)(1.0f), (sfloat)(0.0f));
  env_uv(in->env, s3_select(up, d, act), u, v);
}

/* The environment's P(d, r) per lane where `act` (0 elsewhere; idle lanes read roughness 1), or the
 * uniform default's radiance. */
inline sfloat3 environment_along(const ShadeInputs* in, sfloat3 d, sfloat r, sint act) {
  if (in->env->level_count == 0) return s3_splat((float3)(in->P->env_radiance));
  sfloat u, v;
  environment_uv(in, d, act, &u, &v);
  return s3_select(s3_splat((float3)(0.0f)),
                   env_prefiltered(in->env, in->env_data, u, v, select((sfloat)(1.0f), r, act)), act);
}

/* The environment's I(n) and P(d, r) per lane where `act` (cl/environment.h), d the reflected direction
 * (reflected_direction), or the uniform default of radiance L, for which I(n) = P = L and no table is
 * read. I is not needed (0) where metallic is 1 (c_diff = 0). */
inline void environment_lanes(const ShadeInputs* in, sfloat3 n, sfloat3 d, sfloat metallic, sfloat r, sint act,
                              sfloat3* irradiance, sfloat3* prefiltered) {
  if (in->env->level_count == 0) {
    *irradiance = *prefiltered = s3_splat((float3)(in->P->env_radiance));
    return;
  }
  sfloat un, vn;
  environment_uv(in, n, act, &un, &vn);
  /* a metal has no diffuse term: its lanes skip the irradiance (0) */
  const sint diffuse = act & (metallic < 1.0f);
  const sfloat3 zero = s3_splat((float3)(0.0f));
  *irradiance = any(diffuse) ? s3_select(zero, env_irradiance(in->env, in->env_data, un, vn), diffuse) : zero;
  *prefiltered = environment_along(in, d, r, act);
}

/* The bilinear lookups of the n x n tables below at (x, y) in node units (0 .. n - 1): each lane's
 * first node's index y0 n + x0 (at[l]) and the weights fx, fy of the next column and row. */
inline void table_node_lanes(int n, sfloat x, sfloat y, int* at, sfloat* fx, sfloat* fy) {
  const sint x0 = min(convert_int8(x), n - 2), y0 = min(convert_int8(y), n - 2);
  *fx = x - convert_float8(x0), *fy = y - convert_float8(y0);
  vstore_s(y0 * n + x0, 0, at);
}

/* The bilinear blend of taps a = (x0, y0), b = (x0 + 1, y0), c = (x0, y0 + 1), d = (x0 + 1, y0 + 1). */
inline sfloat bilinear_lanes(sfloat a, sfloat b, sfloat c, sfloat d, sfloat fx, sfloat fy) {
  const sfloat top = a + (b - a) * fx, bottom = c + (d - c) * fx;
  return top + (bottom - top) * fy;
}

/* The split-sum table's bilinear lookup for every lane, as pmr::split_sum (host/shading/environment.cpp)
 * does it: the index arithmetic in vectors, the four taps gathered lane by lane. */
inline void split_sum_lanes(global const float2* t, sfloat nv, sfloat r, sfloat* A, sfloat* B) {
  const int n = PMR_SPLIT_SUM_N;
  const sfloat x = sqrt(clamp(nv, 0.0f, 1.0f)) * (float)(n - 1), y = clamp(r, 0.0f, 1.0f) * (float)(n - 1);
  int at[SW];
  sfloat fx, fy;
  table_node_lanes(n, x, y, at, &fx, &fy);
  float tap[8][SW];
  for (int l = 0; l < SW; ++l) {
    const float4 top = vload4(0, (global const float*)(t + at[l])),
                 bottom = vload4(0, (global const float*)(t + at[l] + n));
    tap[0][l] = top.x, tap[1][l] = top.y, tap[2][l] = top.z, tap[3][l] = top.w;
    tap[4][l] = bottom.x, tap[5][l] = bottom.y, tap[6][l] = bottom.z, tap[7][l] = bottom.w;
  }
  /* taps a = (x0, y0), b = (x0 + 1, y0), c = (x0, y0 + 1), d = (x0 + 1, y0 + 1), each (A, B) */
  for (int k = 0; k < 2; ++k) {
    const sfloat a = vload_s(0, tap[k]), b = vload_s(0, tap[2 + k]), c = vload_s(0, tap[4 + k]),
                 d = vload_s(0, tap[6 + k]);
    const sfloat v = bilinear_lanes(a, b, c, d, fx, fy);
    if (k == 0) *A = v;
    else *B = v;
  }
}

/* E(n.v, r) of the sheen's albedo table for every lane (host/shading/sheen.h: sheen_albedo), bilinear
 * in (sqrt(n.v), r), r the clamped sheen roughness: the index arithmetic in vectors, the taps gathered
 * lane by lane. */
inline sfloat sheen_albedo_lanes(global const float* t, sfloat nv, sfloat r) {
  const int n = PMR_SHEEN_ALBEDO_N;
  const float span = 1.0f - PMR_SHEEN_MIN_ROUGHNESS;
  const sfloat x = sqrt(clamp(nv, 0.0f, 1.0f)) * (float)(n - 1),
               y = (clamp(r, PMR_SHEEN_MIN_ROUGHNESS, 1.0f) - PMR_SHEEN_MIN_ROUGHNESS) * ((float)(n - 1) / span);
  int at[SW];
  sfloat fx, fy;
  table_node_lanes(n, x, y, at, &fx, &fy);
  float tap[4][SW];
  for (int l = 0; l < SW; ++l) {
    const float2 top = vload2(0, t + at[l]), bottom = vload2(0, t + at[l] + n);
    tap[0][l] = top.x, tap[1][l] = top.y, tap[2][l] = bottom.x, tap[3][l] = bottom.y;
  }
  const sfloat a = vload_s(0, tap[0]), b = vload_s(0, tap[1]), c = vload_s(0, tap[2]), d = vload_s(0, tap[3]);
  return bilinear_lanes(a, b, c, d, fx, fy);
}

#endif
