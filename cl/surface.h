/* The surface at the lanes' points (part of the one shading module, cl/shade.h): the material's inputs
 * read once into one Surface, split into what the surface is (the same in every view that sees the
 * point: surface_material) and how the view sees it (surface_seen_from), plus the base colour and the
 * BLEND opacity every model reads. */
#ifndef PMR_CL_SURFACE_H
#define PMR_CL_SURFACE_H

#include "brdf.h"
#include "environment_light.h"
#include "material_maps.h"

/* Specular antialiasing (docs/DESIGN.md section 3b): roughness r widened so that alpha^2 = r^4 grows by
 * `spread` (at most to 1); lanes without spread keep r bit for bit. */
inline sfloat widened_roughness(sfloat r, sfloat spread) {
  const sfloat a2 = (r * r) * (r * r);
  return select(r, sqrt(sqrt(fmin(a2 + spread, 1.0f))), spread > 0.0f);
}

#if PMR_TRILINEAR
/* The geometric term of specular antialiasing: the increment of alpha^2 from the interpolated normal's
 * change across the pixel, min(2 sigma^2 (|dn/dx|^2 + |dn/dy|^2), 0.18) with sigma^2 = 1 / (2 pi) and
 * n = ni / |ni| (ni = sum b_k n_k, len = |ni|), so dn = (dni - n (n . dni)) / |ni|. Flat lanes: 0. */
inline sfloat geometric_spread(const LaneWinners* L, const LaneBaryGrad* g, sfloat3 n, sfloat len) {
  const sfloat3 nix = s3_interp_lanes(g->dx, L->n), niy = s3_interp_lanes(g->dy, L->n);
  const sfloat inv = 1.0f / len;
  const sfloat3 dx = s3_scale(s3_sub(nix, s3_scale(n, s3_dot(n, nix))), inv);
  const sfloat3 dy = s3_scale(s3_sub(niy, s3_scale(n, s3_dot(n, niy))), inv);
  const sfloat spread = fmin((s3_dot(dx, dx) + s3_dot(dy, dy)) * (1.0f / PMR_PI_F), 0.18f);
  return select((sfloat)(0.0f), spread, L->smooth & (len > 0.0f) & isfinite(spread));
}
#endif

/* What the lobes read of each lane's surface (pbr): the one place a material input is combined with its
 * texture. The fields above `v` are the surface's own and the same in every view that sees the point
 * (surface_material); the rest depend on the view (surface_seen_from): the direction toward the view's
 * camera, and the layers' terms at n.v. Shading shared between views may share the first
 * group between views, never the second. */
typedef struct {
  /* view-independent */
  sfloat3 p;       /* world position                                                                 */
  sfloat3 n, base; /* unit shading normal (normal map applied, back faces flipped), base colour     */
  sfloat3 f0, emissive;
  sfloat f90;                     /* the Fresnel term's F0 and F90 (pbr_f0, pbr_f90)                          */
  sfloat metallic, r, ao;         /* r: the clamped, widened roughness                                        */
  sfloat transmission, thickness; /* glass lanes (0 elsewhere)                                        */
  sfloat coat, coat_r;            /* KHR_materials_clearcoat (coated lanes): intensity, roughness  */
  sfloat3 coat_n;                 /* ... the coat's unit normal (its own normal map, or the geometric one) */
  Anisotropy aniso;               /* KHR_materials_anisotropy (lanes aniso.on)                       */
  /* view-dependent */
  sfloat3 v;        /* unit direction toward the view's camera                                       */
  Iridescence irid; /* KHR_materials_iridescence (w 0 in lanes without): its Fresnel term at n.v      */
  Sheen sheen;      /* KHR_materials_sheen (lanes sheen.on): colour and roughness the surface's,
                     * Lambda(n.v) and E(n.v) the view's                                             */
} Surface;

/* The Fresnel term's F0 and F90 of the surface S (base and metallic set): the dielectric's F0 from the
 * ior, times KHR_materials_specular's colour and weight in its lanes. */
inline void surface_fresnel(Surface* S, const LaneWinners* L, const LaneTextures* T, bool textured) {
  if (!any(L->specular)) {
    S->f0 = pbr_f0(S->base, S->metallic, s3(L->f0d, L->f0d, L->f0d));
    S->f90 = 1.0f;
    return;
  }
  sfloat weight = L->spec_weight;
  sfloat3 color = L->spec_color;
  if (textured) weight *= vload_s(0, T->spec_weight), color = s3_mul(color, LANE3(T->spec_color));
  S->f0 = pbr_f0(S->base, S->metallic, specular_f0(L->f0d, color, weight));
  S->f90 = pbr_f90(weight, S->metallic);
}

/* KHR_materials_anisotropy's frame of the surface S (n set), for the lanes that have it: the direction
 * aniso_t and the bitangent from the shading normal, as the specification's implementation. */
inline void surface_anisotropy(Surface* S, const LaneWinners* L, const LaneTextures* T, sfloat3 aniso_t) {
  const sfloat3 ab = s3_cross(S->n, aniso_t);
  const sfloat len = sqrt(s3_dot(ab, ab));
  S->aniso.on = L->aniso & (len > 0.0f);
  S->aniso.t = aniso_t, S->aniso.b = s3_scale(ab, 1.0f / len);
  S->aniso.s = L->aniso_strength * vload_s(0, T->aniso_strength);
}

/* KHR_materials_sheen's layer of the surface S: colour and roughness times their maps. */
inline void surface_sheen(Surface* S, const LaneWinners* L, const LaneTextures* T, bool textured) {
  sfloat3 c = L->sheen_color;
  sfloat r = L->sheen_roughness;
  if (textured) c = s3_mul(c, LANE3(T->sheen_color)), r *= vload_s(0, T->sheen_roughness);
  S->sheen.on = L->sheen;
  S->sheen.color = c;
  S->sheen.r = clamp(r, PMR_SHEEN_MIN_ROUGHNESS, 1.0f);
  S->sheen.m = fmax(fmax(c.x, c.y), c.z);
}

/* The view-independent part of the lanes' surface (Surface): n and coat_n are unit normals, flipped for
 * back faces; spread and coat_spread the specular antialiasing increments of the two lobes. */
inline Surface surface_material(const LaneWinners* L, const LaneTextures* T, bool textured, sfloat3 b, sfloat3 n,
                                sfloat3 coat_n, sfloat3 aniso_t, sfloat3 base, sfloat spread, sfloat coat_spread) {
  Surface S;
  S.p = s3_interp_lanes(b, L->p);
  const bool glass = any(L->glass), coated = any(L->coated);
  sfloat metallic = L->metallic, roughness = L->roughness, ao = 1.0f;
  sfloat transmission = glass ? L->transmission : 0.0f, thickness = glass ? L->thickness : 0.0f;
  sfloat coat = coated ? L->coat : 0.0f, coat_roughness = coated ? L->coat_roughness : 0.0f;
  sfloat3 emissive = L->emissive;
  if (textured) {
    metallic *= vload_s(0, T->metallic), roughness *= vload_s(0, T->roughness), ao = vload_s(0, T->ao);
    emissive = s3_mul(emissive, LANE3(T->emissive));
    if (glass) transmission *= vload_s(0, T->transmission), thickness *= vload_s(0, T->thickness);
    if (coated) coat *= vload_s(0, T->coat), coat_roughness *= vload_s(0, T->coat_roughness);
  }
  S.n = n, S.base = base, S.emissive = emissive;
  S.metallic = metallic, S.ao = ao, S.transmission = transmission, S.thickness = thickness;
  S.r = widened_roughness(pbr_roughness(roughness), spread);
  surface_fresnel(&S, L, T, textured);
  S.coat = coat, S.coat_n = coat_n;
  S.coat_r = coated ? widened_roughness(pbr_roughness(coat_roughness), coat_spread) : (sfloat)(1.0f);
  if (any(L->aniso)) surface_anisotropy(&S, L, T, aniso_t);
  if (any(L->sheen)) surface_sheen(&S, L, T, textured);
  return S;
}

/* KHR_materials_iridescence's film over the surface S (n, v, F0 and the coat set): its Fresnel term at
 * n.v and weight. Under a clear coat the film's outside is the coat (ior 1.5), else air; without a
 * thickness texture the film has the maximum thickness. */
inline void surface_iridescence(Surface* S, const LaneWinners* L, const LaneTextures* T, bool textured) {
  const sfloat t = textured ? vload_s(0, T->irid_thickness) : (sfloat)(1.0f);
  const sfloat d = L->irid_min + (L->irid_max - L->irid_min) * t;
  const sfloat outside = select((sfloat)(1.0f), (sfloat)(1.5f), L->coated & (S->coat > 0.0f));
  const sfloat cos1 = clamp(s3_dot(S->n, S->v), 0.0f, 1.0f);
  S->irid.F = thin_film_fresnel(outside, L->irid_ior, cos1, d, S->f0);
  S->irid.w = textured ? L->irid_factor * vload_s(0, T->irid_factor) : L->irid_factor;
}

/* The view-dependent part of the surface S (surface_material set) seen from view `view` of the pass:
 * v, and what the thin film and the sheen are at n.v (Lambda(n.v), E(n.v)). */
inline void surface_seen_from(Surface* S, const ShadeInputs* in, const LaneWinners* L, const LaneTextures* T,
                              bool textured, int view) {
  const sfloat3 to_eye = s3_sub(s3_splat(in->eyes[view + (int)in->P->view_base].xyz), S->p);
  S->v = s3_scale(to_eye, 1.0f / sqrt(s3_dot(to_eye, to_eye)));
  if (any(L->irid)) surface_iridescence(S, L, T, textured);
  if (any(L->sheen)) {
    const sfloat nv = clamp(s3_dot(S->n, S->v), PMR_SHEEN_MIN_COS, 1.0f);
    S->sheen.lambda_v = sheen_lambda(nv, S->sheen.r * S->sheen.r);
    S->sheen.e_v = sheen_albedo_lanes(in->sheen_albedo, nv, S->sheen.r);
  }
}

/* Base colours (RGB): baseColorFactor x COLOR_0 x the base colour texture. */
inline sfloat3 lane_base_color(const LaneWinners* L, const LaneTextures* T, bool textured, sfloat3 b) {
  const sfloat3 c = s3_mul(L->factor, s3_interp_lanes(b, L->c));
  return textured ? s3_mul(c, LANE3(T->base)) : c;
}

/* The opacity of each lane: 1, or for alphaMode BLEND baseColorFactor alpha x COLOR_0 alpha x the base
 * colour texture's alpha, clamped to [0, 1] (the MASK test's alpha, mta_alpha_lanes). */
inline sfloat lane_alpha(const LaneWinners* L, const LaneTextures* T, bool textured, sfloat3 b) {
  if (!PMR_WITH_BLEND || !any(L->blended)) return (sfloat)(1.0f);
  sfloat a = L->alpha[0] * (b.x * L->alpha[1] + b.y * L->alpha[2] + b.z * L->alpha[3]);
  if (textured) a *= vload_s(0, T->base_alpha);
  return select((sfloat)(1.0f), clamp(a, 0.0f, 1.0f), L->blended);
}

#endif
