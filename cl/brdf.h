/* The glTF 2.0 metallic-roughness BRDF of --shading pbr (docs/SHADING.md): Schlick's Fresnel, the GGX
 * (Trowbridge-Reitz) distribution and the height-correlated Smith visibility, for one light direction,
 * and the layers' lobes, each for SW lanes at once (cl/lanes.h). Every dot product
 * with n is clamped to [0, 1]. The C++ reference (tests/reference/pbr_reference.cpp) computes the same
 * in double precision. */
#ifndef PMR_CL_BRDF_H
#define PMR_CL_BRDF_H

#include "lanes.h"

#define PMR_PI_F 3.14159265358979f

/* Roughness as the material gives it (factor x texture G) clamped to [0.03, 1]; alpha = r^2. */
inline sfloat pbr_roughness(sfloat r) { return clamp(r, 0.03f, 1.0f); }

/* F0 = mix(f0d, base, metallic) per channel, f0d the dielectric's (0.04, or from KHR_materials_ior,
 * times KHR_materials_specular's colour and weight) */
inline sfloat3 pbr_f0(sfloat3 base, sfloat metallic, sfloat3 f0d) {
  return s3(f0d.x + (base.x - f0d.x) * metallic, f0d.y + (base.y - f0d.y) * metallic,
            f0d.z + (base.z - f0d.z) * metallic);
}

/* KHR_materials_specular: the dielectric's F0 min(f0_ior x colour, 1) x weight per channel, f0_ior
 * from the ior (0.04 at 1.5), colour and weight the extension's factors times their textures. */
inline sfloat3 specular_f0(sfloat f0_ior, sfloat3 color, sfloat weight) {
  return s3(fmin(f0_ior * color.x, 1.0f) * weight, fmin(f0_ior * color.y, 1.0f) * weight,
            fmin(f0_ior * color.z, 1.0f) * weight);
}

/* ... and F90 = mix(weight, 1, metallic) (a metal's Fresnel stays the base colour's). */
inline sfloat pbr_f90(sfloat weight, sfloat metallic) { return weight + (1.0f - weight) * metallic; }

/* GGX normal distribution D for cos(n, h) = nh and a2 = alpha^2. */
inline sfloat ggx_d(sfloat nh, sfloat a2) {
  const sfloat d = nh * nh * (a2 - 1.0f) + 1.0f;
  return a2 / (PMR_PI_F * d * d);
}

/* Height-correlated Smith visibility V = G / (4 nl nv); 0 where its denominator is 0. */
inline sfloat smith_vis(sfloat nl, sfloat nv, sfloat a2) {
  const sfloat s = nl * sqrt(nv * nv * (1.0f - a2) + a2) + nv * sqrt(nl * nl * (1.0f - a2) + a2);
  return select((sfloat)(0.0f), 0.5f / s, s > 0.0f);
}

/* Schlick's Fresnel per channel, F0 + (F90 - F0) (1 - v.h)^5; F90 = mix(the specular weight, 1,
 * metallic) (1 without KHR_materials_specular). */
inline sfloat3 fresnel_schlick(sfloat3 f0, sfloat f90, sfloat vh) {
  const sfloat k = 1.0f - vh, k2 = k * k, k5 = k2 * k2 * k;
  return s3(f0.x + (f90 - f0.x) * k5, f0.y + (f90 - f0.y) * k5, f0.z + (f90 - f0.z) * k5);
}

/* D Vis n.l per lane: a GGX lobe about n (alpha^2 = a2) without Fresnel, as KHR_materials_clearcoat's
 * coat layer uses it (its Fresnel weights the layer); 0 where the light is behind the surface. */
inline sfloat ggx_lobe_cos(sfloat3 n, sfloat3 v, sfloat3 l, sfloat a2) {
  const sfloat nl = clamp(s3_dot(n, l), 0.0f, 1.0f), nv = clamp(s3_dot(n, v), 0.0f, 1.0f);
  const sfloat3 hv = s3_add(l, v);
  const sfloat hl = sqrt(s3_dot(hv, hv));
  const sfloat3 h = s3_select(n, s3_scale(hv, 1.0f / hl), hl > 0.0f);
  const sfloat nh = clamp(s3_dot(n, h), 0.0f, 1.0f);
  return select((sfloat)(0.0f), ggx_d(nh, a2) * smith_vis(nl, nv, a2) * nl, nl > 0.0f);
}

/* KHR_materials_anisotropy's lobe (its specification's implementation section): the tangent t and
 * bitangent b of the anisotropy direction, strength s; GGX stretched to alpha_t = mix(alpha, 1, s^2)
 * along t and alpha_b = alpha along b, with its height-correlated Smith visibility. `on`: the lanes
 * that have it (the others keep the isotropic lobe). */
typedef struct {
  sint on;
  sfloat3 t, b;
  sfloat s;
} Anisotropy;

/* KHR_materials_iridescence: the Fresnel term F of a thin film, w the iridescence factor (0 in lanes
 * without), F = mix(Schlick's F, this F, w) in every lobe of the material. */
typedef struct {
  sfloat3 F;
  sfloat w;
} Iridescence;

/* KHR_materials_sheen's layer of fibres: its colour (0 in lanes without), the clamped sheen roughness
 * r, max3 of the colour, Lambda(n.v) and E(n.v, r), the layer's albedo seen from v. */
typedef struct {
  sint on;
  sfloat3 color;
  sfloat r, m, lambda_v, e_v;
} Sheen;

/* Lambda of the Charlie visibility at cosine x (clamped to [0, 1]) for alpha = r^2: the extension's fit
 * exp(l(x)) below x = 1/2, exp(2 l(1/2) - l(1 - x)) above. */
inline sfloat sheen_lambda(sfloat x, sfloat alpha) {
  const sfloat o = (1.0f - alpha) * (1.0f - alpha);
  const sfloat a = 21.5473f + 3.7772f * o, b = 3.82987f - 0.50552f * o, c = 0.19823f - 0.03022f * o;
  const sfloat d = -1.97760f + 0.70367f * o, e = -4.32054f - 0.53913f * o;
  const sint low = x < 0.5f;
  const sfloat y = select(1.0f - x, x, low);
  const sfloat ly = a / (1.0f + b * pow_lanes(y, c)) + d * y + e;
  const sfloat half_l = a / (1.0f + b * exp2_lanes(-c)) + 0.5f * d + e; /* l(1/2) */
  return exp2_lanes(select(2.0f * half_l - ly, ly, low) * 1.44269504089f);
}

/* D V n.l of the Charlie lobe (the extension's implementation notes): D = (2 + 1 / alpha) sin^(1 / alpha)
 * (theta_h) / (2 pi), V = 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 n.v n.l) at most 1 (as the Sample Viewer
 * clamps it: bounded at grazing views), for the clamped cosines given (n.v at least PMR_SHEEN_MIN_COS);
 * 0 where n.l = 0. */
inline sfloat sheen_lobe_cos(const Sheen* s, sfloat nv, sfloat nl, sfloat nh) {
  const sfloat alpha = s->r * s->r, inv = 1.0f / alpha;
  const sfloat sin2h = fmax(1.0f - nh * nh, 0.0f);
  const sfloat D = (2.0f + inv) * pow_lanes(sin2h, 0.5f * inv) * (0.5f / PMR_PI_F);
  const sfloat q = (1.0f + s->lambda_v + sheen_lambda(nl, alpha)) * 4.0f * nv;
  return select((sfloat)(0.0f), D * fmin(1.0f / q, nl), nl > 0.0f);
}

/* The spectral sensitivity term of the thin film's analytic spectral integration (the extension's
 * evalSensitivity: Gaussian fits of the CIE XYZ curves in Fourier space, then XYZ to Rec. 709) for
 * optical path difference opd (nm) and phase shift `shift` per channel. */
inline sfloat3 film_sensitivity(sfloat opd, sfloat3 shift) {
  const sfloat phase = 2.0f * PMR_PI_F * opd * 1.0e-9f, p2 = phase * phase;
  const float two_pi = 2.0f * PMR_PI_F;
  const sfloat x = 5.4856e-13f * sqrt(two_pi * 4.3278e9f) * cos(1.6810e6f * phase + shift.x) * exp(-4.3278e9f * p2) +
                   9.7470e-14f * sqrt(two_pi * 4.5282e9f) * cos(2.2399e6f * phase + shift.x) * exp(-4.5282e9f * p2);
  const sfloat y = 4.4201e-13f * sqrt(two_pi * 9.3046e9f) * cos(1.7953e6f * phase + shift.y) * exp(-9.3046e9f * p2);
  const sfloat z = 5.2481e-13f * sqrt(two_pi * 6.6121e9f) * cos(2.2084e6f * phase + shift.z) * exp(-6.6121e9f * p2);
  const float k = 1.0f / 1.0685e-7f;
  return s3(k * (3.2404542f * x - 1.5371385f * y - 0.4985314f * z),
            k * (-0.9692660f * x + 1.8760108f * y + 0.0415560f * z),
            k * (0.0556434f * x - 0.2040259f * y + 1.0572252f * z));
}

/* The thin film's Fresnel term (the extension's implementation notes, Belcour and Barla 2017), one
 * reflection at cos1 = n.v: a film of ior `film` (eased to `outside` as the thickness goes to 0) and
 * thickness d nm between a medium of ior `outside` and the base of Fresnel F0 f0 (its ior from F0).
 * Schlick's Fresnel at both interfaces, the phase shifts of 0 or pi, and two orders of the Fourier
 * series. Total internal reflection in the film gives 1. */
inline sfloat3 thin_film_fresnel(sfloat outside, sfloat film, sfloat cos1, sfloat d, sfloat3 f0) {
  const sfloat ior = outside + (film - outside) * smoothstep(0.0f, 0.03f, d);
  const sfloat ratio = outside / ior, sin2sq = ratio * ratio * (1.0f - cos1 * cos1), cos2sq = 1.0f - sin2sq;
  const sfloat cos2 = sqrt(fmax(cos2sq, 0.0f));
  const sfloat q0 = (ior - outside) / (ior + outside), r0 = q0 * q0;
  const sfloat k1 = 1.0f - cos1, k2 = 1.0f - cos2;
  const sfloat R12 = r0 + (1.0f - r0) * (k1 * k1) * (k1 * k1) * k1, T121 = 1.0f - R12;
  const sfloat phi21 = select((sfloat)(PMR_PI_F), (sfloat)(0.0f), ior < outside);
  const sfloat opd = 2.0f * ior * d * cos2, k2_5 = (k2 * k2) * (k2 * k2) * k2;
  const sfloat f0c[3] = {f0.x, f0.y, f0.z};
  sfloat R23[3], phi[3];
  for (int c = 0; c < 3; ++c) {
    const sfloat s0 = sqrt(clamp(f0c[c], 0.0f, 0.9999f)), base = (1.0f + s0) / (1.0f - s0);
    const sfloat q1 = (base - ior) / (base + ior), r1 = q1 * q1;
    R23[c] = r1 + (1.0f - r1) * k2_5;
    phi[c] = phi21 + select((sfloat)(0.0f), (sfloat)(PMR_PI_F), base < ior);
  }
  const sfloat3 s1 = film_sensitivity(opd, s3(phi[0], phi[1], phi[2]));
  const sfloat3 s2 = film_sensitivity(2.0f * opd, s3(2.0f * phi[0], 2.0f * phi[1], 2.0f * phi[2]));
  const sfloat sens1[3] = {s1.x, s1.y, s1.z}, sens2[3] = {s2.x, s2.y, s2.z};
  sfloat F[3];
  for (int c = 0; c < 3; ++c) {
    const sfloat R123 = clamp(R12 * R23[c], 1e-5f, 0.9999f), r123 = sqrt(R123);
    const sfloat Rs = T121 * T121 * R23[c] / (1.0f - R123);
    const sfloat C1 = (Rs - T121) * r123, C2 = C1 * r123;
    const sfloat I = R12 + Rs + C1 * 2.0f * sens1[c] + C2 * 2.0f * sens2[c];
    F[c] = select(fmax(I, 0.0f), (sfloat)(1.0f), cos2sq < 0.0f);
  }
  return s3(F[0], F[1], F[2]);
}

/* D Vis of the anisotropic lobe for alpha = r^2, at the dot products of n, h, v and l given. */
inline sfloat ggx_aniso_dv(const Anisotropy* A, sfloat alpha, sfloat3 h, sfloat3 v, sfloat3 l, sfloat nh, sfloat nv,
                           sfloat nl) {
  const sfloat at = alpha + (1.0f - alpha) * A->s * A->s, ab = alpha, a2 = at * ab;
  const sfloat th = s3_dot(A->t, h), bh = s3_dot(A->b, h);
  const sfloat fx = th * ab, fy = bh * at, fz = a2 * nh;
  const sfloat w2 = a2 / (fx * fx + fy * fy + fz * fz);
  const sfloat D = a2 * w2 * w2 * (1.0f / PMR_PI_F);
  const sfloat tv = s3_dot(A->t, v), bv = s3_dot(A->b, v), tl = s3_dot(A->t, l), bl = s3_dot(A->b, l);
  const sfloat gv = nl * sqrt(at * at * tv * tv + ab * ab * bv * bv + nv * nv),
               gl = nv * sqrt(at * at * tl * tl + ab * ab * bl * bl + nl * nl);
  const sfloat s = gv + gl;
  return D * select((sfloat)(0.0f), 0.5f / s, s > 0.0f);
}

/* f(l, v) * dot(n, l) per lane: the radiance reflected toward v per unit irradiance from the direction
 * l (unit, toward the light). n and v are unit vectors; r is the clamped roughness; f0 and f90 the
 * Fresnel term's (pbr_f0); `transmission` (KHR_materials_transmission) the part of the diffuse lobe
 * that transmits instead (the environment's transmission term takes its place: cl/transmission.h);
 * `aniso` the anisotropic lobe where it is on (0: none), `irid` the thin film's Fresnel term (0: none). */
inline sfloat3 brdf_cos_transmissive(sfloat3 base, sfloat metallic, sfloat3 f0, sfloat f90, sfloat r, sfloat3 n,
                                     sfloat3 v, sfloat3 l, sfloat transmission, const Anisotropy* aniso,
                                     const Iridescence* irid) {
  const sfloat nl = clamp(s3_dot(n, l), 0.0f, 1.0f);
  const sfloat nv = clamp(s3_dot(n, v), 0.0f, 1.0f);
  const sfloat3 hv = s3_add(l, v);
  const sfloat hl = sqrt(s3_dot(hv, hv));
  const sfloat3 h = s3_select(n, s3_scale(hv, 1.0f / hl), hl > 0.0f);
  const sfloat nh = clamp(s3_dot(n, h), 0.0f, 1.0f), vh = clamp(s3_dot(v, h), 0.0f, 1.0f);
  const sfloat alpha = r * r, a2 = alpha * alpha;
  sfloat3 F = fresnel_schlick(f0, f90, vh);
  if (irid) F = s3_add(F, s3_scale(s3_sub(irid->F, F), irid->w));
  const sfloat diffuse = (1.0f - metallic) * (1.0f - transmission) * (1.0f / PMR_PI_F),
               iso = ggx_d(nh, a2) * smith_vis(nl, nv, a2);
  const sfloat spec = aniso ? select(iso, ggx_aniso_dv(aniso, alpha, h, v, l, nh, nv, nl), aniso->on) : iso;
  const sfloat3 f = s3((1.0f - F.x) * base.x * diffuse + F.x * spec, (1.0f - F.y) * base.y * diffuse + F.y * spec,
                       (1.0f - F.z) * base.z * diffuse + F.z * spec);
  /* nl = 0 (the light behind the surface) gives 0, whatever the rest computed */
  return s3_scale(f, select((sfloat)(0.0f), nl, nl > 0.0f));
}

/* The same for an opaque surface. */
inline sfloat3 brdf_cos(sfloat3 base, sfloat metallic, sfloat3 f0, sfloat f90, sfloat r, sfloat3 n, sfloat3 v,
                        sfloat3 l, const Anisotropy* aniso, const Iridescence* irid) {
  return brdf_cos_transmissive(base, metallic, f0, f90, r, n, v, l, (sfloat)(0.0f), aniso, irid);
}

/* KHR_materials_transmission's BTDF for a punctual light seen through the surface (as the Khronos
 * Sample Viewer's getPunctualRadianceTransmission): (1 - F(v.h)) D(n.h) Vis(n.l', n.v), l' the direction
 * toward the light mirrored on the surface's plane, h = normalize(l' + v), GGX with the transmission
 * roughness max(r clamp(2 ior - 2, 0, 1), 0.03) (alpha its square; the floor keeps ior 1 finite). Per
 * unit irradiance E; the caller weights it by T (1 - metallic) c and Beer-Lambert. */
inline sfloat3 btdf_light(sfloat3 f0, sfloat f90, sfloat r, sfloat ior, sfloat3 n, sfloat3 v, sfloat3 l) {
  const sfloat3 lm = s3_sub(l, s3_scale(n, 2.0f * s3_dot(n, l)));
  const sfloat3 hv = s3_add(lm, v);
  const sfloat hl = sqrt(s3_dot(hv, hv));
  const sfloat3 h = s3_select(n, s3_scale(hv, 1.0f / hl), hl > 0.0f);
  const sfloat rt = fmax(r * clamp(2.0f * ior - 2.0f, 0.0f, 1.0f), 0.03f), a2 = (rt * rt) * (rt * rt);
  const sfloat nh = clamp(s3_dot(n, h), 0.0f, 1.0f), vh = clamp(s3_dot(v, h), 0.0f, 1.0f);
  const sfloat nl = clamp(s3_dot(n, lm), 0.0f, 1.0f), nv = clamp(s3_dot(n, v), 0.0f, 1.0f);
  const sfloat3 F = fresnel_schlick(f0, f90, vh);
  const sfloat s = ggx_d(nh, a2) * smith_vis(nl, nv, a2);
  return s3((1.0f - F.x) * s, (1.0f - F.y) * s, (1.0f - F.z) * s);
}

#endif
