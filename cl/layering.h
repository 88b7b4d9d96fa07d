/* Layering and transmission (part of the one shading module, cl/shade.h; DESIGN section 4c): the
 * clear coat's and the sheen's layers over the base lobes, and the light through a transmissive surface
 * (cl/transmission.h). Each layer weights what lies beneath by a Fresnel or albedo term at n.v, so all
 * of this depends on the view. */
#ifndef PMR_CL_LAYERING_H
#define PMR_CL_LAYERING_H

#include "surface.h"
#include "transmission.h"

/* w (1 - R) c: the weight of the light through a transmissive surface (w = ao T (1 - metallic)), R its
 * environment reflectance (environment_reflectance). */
inline sfloat3 btdf_weight(sfloat w, sfloat3 R, sfloat3 c) {
  return s3(w * (1.0f - R.x) * c.x, w * (1.0f - R.y) * c.y, w * (1.0f - R.z) * c.z);
}

/* The split-sum reflectance F0 A + F90 B of the lanes' specular lobe, or with a thin film
 * mix(F0 A + F90 B, F_iridescence (A + B), w): the film's Fresnel term is constant over the lobe. */
inline sfloat3 environment_reflectance(sfloat3 f0, sfloat f90, sfloat A, sfloat B, const Iridescence* irid) {
  const sfloat f90B = f90 * B;
  const sfloat3 R = s3(f0.x * A + f90B, f0.y * A + f90B, f0.z * A + f90B);
  return irid ? s3_add(R, s3_scale(s3_sub(s3_scale(irid->F, A + B), R), irid->w)) : R;
}

/* KHR_materials_clearcoat's layering (its specification's fresnel_coat): the material's colour `under`
 * seen through a coat of intensity c and ior 1.5, mix(under, coat lobe, c Fc), Fc = 0.04 + 0.96
 * (1 - |coat_n . v|)^5; the coat lobe is `lights` (the GGX lobe about coat_n of roughness coat_r with no
 * Fresnel of its own, summed over the lights) plus ao V (A + B) P(reflect(-v, coat_n), coat_r), V the
 * environment's visibility env_v (1 without shadows). Lanes without a coat keep `under` bit for bit. */
inline sfloat3 coated_lanes(const ShadeInputs* in, const LaneWinners* L, const Surface* S, sfloat3 under,
                            sfloat3 lights, sfloat env_v) {
  const sfloat nv = s3_dot(S->coat_n, S->v);
  const sfloat k = 1.0f - fmin(fabs(nv), 1.0f), k2 = k * k;
  const sfloat w = S->coat * (0.04f + 0.96f * (k2 * k2 * k));
  sfloat A, B;
  split_sum_lanes(in->split_sum, nv, S->coat_r, &A, &B);
  const sint act = L->act & L->coated;
  const sfloat3 env = environment_along(in, s3_sub(s3_scale(S->coat_n, 2.0f * nv), S->v), S->coat_r, act);
  const sfloat3 coat = s3_add(lights, s3_scale(env, S->ao * env_v * (A + B)));
  return s3_select(under, s3_add(s3_scale(under, 1.0f - w), s3_scale(coat, w)), L->coated);
}

/* KHR_materials_sheen over a light: f (the layers beneath, per unit irradiance, n.l included) scaled by
 * the extension's albedo scaling min(1 - m E(n.v), 1 - m E(n.l)) (clamped to [0, 1]), plus the sheen
 * lobe c D V n.l. Lanes without sheen keep f bit for bit. */
inline sfloat3 sheen_over_light(const ShadeInputs* in, const Sheen* s, sfloat3 f, sfloat3 n, sfloat3 v, sfloat3 l) {
  const sfloat nl = clamp(s3_dot(n, l), 0.0f, 1.0f), nv = clamp(s3_dot(n, v), PMR_SHEEN_MIN_COS, 1.0f);
  const sfloat3 hv = s3_add(l, v);
  const sfloat hl = sqrt(s3_dot(hv, hv));
  const sfloat3 h = s3_select(n, s3_scale(hv, 1.0f / hl), hl > 0.0f);
  const sfloat nh = clamp(s3_dot(n, h), 0.0f, 1.0f);
  const sfloat e = fmax(s->e_v, sheen_albedo_lanes(in->sheen_albedo, nl, s->r));
  const sfloat scale = clamp(1.0f - s->m * e, 0.0f, 1.0f);
  const sfloat3 layered = s3_add(s3_scale(f, scale), s3_scale(s->color, sheen_lobe_cos(s, nv, nl, nh)));
  return s3_select(f, layered, s->on);
}

/* What the sheen lets through from the view's side, x (1 - m E(n.v)) (clamped to [0, 1]), in its lanes. */
inline sfloat3 sheen_view_scaled(const Sheen* s, sfloat3 x) {
  return s3_select(x, s3_scale(x, clamp(1.0f - s->m * s->e_v, 0.0f, 1.0f)), s->on);
}

/* KHR_materials_sheen over the environment, in the lanes with sheen: `under` (the environment's, the
 * transmission's and the emission's light through the layer) scaled as the view sees it
 * (sheen_view_scaled), plus the sheen's environment term ao V c E(n.v) S(reflect(-v, n), r) (the
 * Charlie-prefiltered levels; the uniform default's radiance without an image), V the environment's
 * diffuse visibility env_v (1 without shadows). */
inline sfloat3 sheen_over_environment(const ShadeInputs* in, const LaneWinners* L, const Surface* S, sfloat3 under,
                                      sfloat env_v) {
  const Sheen* s = &S->sheen;
  sfloat3 light = s3_splat((float3)(in->P->env_radiance));
  if (in->env->level_count != 0) {
    sfloat u, v;
    environment_uv(in, s3_sub(s3_scale(S->n, 2.0f * s3_dot(S->n, S->v)), S->v), L->act, &u, &v);
    light = env_sheen(in->env, in->env_data, u, v, s->r);
  }
  return s3_add(sheen_view_scaled(s, under), s3_scale(s3_mul(s->color, light), S->ao * env_v * s->e_v));
}

#endif
