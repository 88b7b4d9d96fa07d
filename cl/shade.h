/* Shading (docs/SHADING.md), the one module every path calls: base colour from baseColorFactor *
 * baseColorTexture (sRGB-decoded; bilinear from level 0, or trilinear from mips at the analytic level of
 * detail, docs/DESIGN.md section 3b; glTF wrap modes) * COLOR_0, then either view-independent
 * Lambert with one directional light, or glTF metallic-roughness (cl/brdf.h) with the material's
 * metallic-roughness, normal, occlusion and emissive maps, seen from each view's own camera, lit by the
 * frame's light table (the file's punctual lights or the default light) and the uniform default
 * environment or an environment image (cl/environment.h).
 *
 * Shading goes SW voxels (or samples) at a time, one per lane (cl/lanes.h), each lane with its own
 * winning MTA: the caller loads each winning MTA's triangle, vertices and material once and blends them
 * into the lanes it won (LaneWinners); the barycentrics, normals, base colour, BRDF and lights then run
 * on all lanes at once. Texture sampling runs on all the lanes of one material at once (cl/texture.h),
 * only its texel loads lane by lane; the split-sum and environment lookups are gathered lane by lane.
 * Each lane's result is a function of its own voxel alone, so it depends neither on the other lanes,
 * nor on the tile shape, nor on the path. */
#ifndef PMR_CL_SHADE_H
#define PMR_CL_SHADE_H

/* The module's parts, each including what it reads (docs/SHADING.md, "Code"):
 *   shade_inputs.h       the buffers every shading kernel takes first (PMR_SHADE_PARAMS)
 *   lane_winners.h       the lanes' winning MTAs, triangles and materials; barycentrics
 *   material_maps.h      the material's textures at the lanes' points
 *   surface.h            the material inputs read once: view-independent, then seen from the view
 *   brdf.h, lights.h     the lobes; what each light delivers at a point
 *   area_lights.h        an area light's lobes integrated over its shape
 *   environment_light.h  the environment's irradiance and prefiltered radiance, the split-sum tables
 *   layering.h           clear coat and sheen layers; transmission (transmission.h)
 * and here: the lights and the environment summed through the lobes (shade_pbr), Lambert, the entry
 * point shade_lanes, and the MASK alpha test. */
#include "area_lights.h"
#include "layering.h"
#include "lights.h"

/* reflect(-v, n), or for anisotropic lanes about the Sample Viewer's bent normal: n bent toward the
 * normal of the plane through the anisotropy bitangent b and v, normalize(mix(cross(cross(b, v), b), n,
 * (1 - s (1 - r))^4)), s the strength and r the roughness. */
inline sfloat3 reflected_direction(const Surface* S, const LaneWinners* L, sfloat nv) {
  const sfloat3 mirror = s3_sub(s3_scale(S->n, 2.0f * nv), S->v);
  if (!any(L->aniso)) return mirror;
  const sfloat3 b = S->aniso.b, an = s3_cross(s3_cross(b, S->v), b);
  const sfloat k = 1.0f - S->aniso.s * (1.0f - S->r), k2 = k * k, bend = k2 * k2;
  const sfloat3 m = s3_add(s3_scale(an, 1.0f - bend), s3_scale(S->n, bend));
  const sfloat3 bent = s3_scale(m, 1.0f / sqrt(s3_dot(m, m)));
  return s3_select(mirror, s3_sub(s3_scale(bent, 2.0f * s3_dot(bent, S->v)), S->v), S->aniso.on);
}

/* The environment's occlusion at the lanes' surfaces S (lights.h, environment_visibility_lanes, with the
 * entry after the light table's lights): *vd for the diffuse term, *vs for the specular lobes about
 * `reflected`, whose width follows the roughness as a spherical Gaussian of GGX's lobe (sharpness
 * 1 / (2 alpha^2) about the reflected direction) but is never narrower than the directions' spacing
 * allows (sharpness at most K / 4 for K directions, a lobe about 20 degrees wide for 64): a glossy
 * surface's occlusion is that of a blurred lobe (docs/SHADING.md gives the error). */
inline void environment_occlusion_lanes(const ShadeInputs* in, const LaneWinners* L, const Surface* S,
                                        sfloat3 reflected, sfloat* vd, sfloat* vs) {
  global const PmrLight* occ = &in->lights[in->P->num_lights];
  const sfloat a = S->r * S->r;
  const sfloat sharpness = fmin(0.5f / fmax(a * a, 1e-6f), 0.25f * (float)occ->shadow_samples);
  environment_visibility_lanes(in->shadow_maps, in->shadow_depth, occ, S->p, L->face, S->n, reflected, sharpness,
                               L->act, vd, vs);
}

/* Rec. 709 luminance of linear colours. */
inline sfloat luminance_lanes(sfloat3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/* What the light table's lights (the file's punctual lights, or the default light, or none) send toward
 * the view through the lanes' surfaces S, each light's irradiance E times its visibility (lights.h: the
 * same in every view) times the view's lobes: `direct` the sum of f E n.l (the sheen's layering in f), `through` the
 * transmissive lanes' BTDF times E (before their weights), `coat` the clear coat's GGX lobe times E. */
typedef struct {
  sfloat3 direct, through, coat;
  /* with ground catcher lanes: the luminance of the irradiance the lights send onto n, as it arrives
     and as it would unoccluded */
  sfloat received, unoccluded;
} LightSums;

inline LightSums light_table_lanes(const ShadeInputs* in, const LaneWinners* L, const Surface* S) {
  const bool glass = any(L->glass), coated = any(L->coated); /* their terms cost nothing to other lanes */
  const Anisotropy* aniso = any(L->aniso) ? &S->aniso : 0;
  const Iridescence* irid = any(L->irid) ? &S->irid : 0;
  const Sheen* sheen = any(L->sheen) ? &S->sheen : 0;
  const sfloat3 n = S->n, v = S->v, base = S->base, f0 = S->f0;
  const sfloat f90 = S->f90, metallic = S->metallic, r = S->r, transmission = S->transmission;
  const sfloat coat_a2 = coated ? (S->coat_r * S->coat_r) * (S->coat_r * S->coat_r) : 0.0f;
  sfloat3 direct = s3_splat((float3)(0.0f)), lights_through = direct, coat_lights = direct;
  sfloat received = 0.0f, unoccluded = 0.0f;
  const bool catcher = any(L->catcher);
  const uint num_lights = in->P->num_lights;
  for (uint i = 0; i < num_lights; ++i) {
    global const PmrLight* light = &in->lights[i];
    const bool area = light->type == PMR_LIGHT_RECT || light->type == PMR_LIGHT_DISK;
    sfloat3 l, E;
    AreaLanes A;
    if (area) { /* E: on a surface facing the shape's vector irradiance l */
      A = area_light_lanes(in->ltc, light, S->p, S->n, S->v, S->r, S->coat_n, S->coat_r, L->act, L->coated);
      l = A.l, E = s3_scale(s3_splat(vload3(0, light->color)), A.e);
    } else {
      E = light_irradiance((int)light->type, vload3(0, light->color), vload3(0, light->position),
                           vload3(0, light->direction), light->range, light->cos_inner, light->cos_outer, S->p, &l);
    }
    const sfloat V = light->shadow >= 0
                         ? shadow_visibility_lanes(in->shadow_maps, in->shadow_depth, light, S->p, L->face, S->n, L->act)
                         : (sfloat)(1.0f);
    if (catcher) {
      const sfloat e = luminance_lanes(E) * fmax(s3_dot(n, l), 0.0f);
      unoccluded += e, received += e * V;
    }
    if (light->shadow >= 0) E = s3_scale(E, V); /* (--shadows off: E as before, bit for bit) */
    /* an area light's lobes are integrated over its shape, but for anisotropic lanes (a point at l) */
    sfloat3 f = area ? area_brdf(S, &A, transmission, irid) : s3_splat((float3)(0.0f));
    if (!area || aniso) {
      const sfloat3 point = glass
                                ? brdf_cos_transmissive(base, metallic, f0, f90, r, n, v, l, transmission, aniso, irid)
                                : brdf_cos(base, metallic, f0, f90, r, n, v, l, aniso, irid);
      f = !area ? point : s3_select(f, point, aniso->on);
    }
    if (sheen) f = sheen_over_light(in, sheen, f, n, v, l);
    direct = s3_add(direct, s3_mul(f, E));
    if (glass) lights_through = s3_add(lights_through, s3_mul(btdf_light(f0, f90, r, L->ior, n, v, l), E));
    if (coated) {
      const sfloat coat =
          area ? select((sfloat)(0.0f), A.coat / A.e, A.e > 0.0f) : ggx_lobe_cos(S->coat_n, v, l, coat_a2);
      coat_lights = s3_add(coat_lights, s3_scale(E, coat));
    }
  }
  const LightSums sums = {direct, lights_through, coat_lights, received, unoccluded};
  return sums;
}

/* The ground catcher's alpha (--ground shadow; DESIGN section 4d): 1 - the irradiance that reaches it
 * over what would reach it unoccluded, the lights' (`sums`) and the environment's (`irradiance` I(n),
 * times its diffuse visibility vd), each as luminance; 0 where nothing would reach it. */
inline sfloat catcher_alpha(const LightSums* sums, sfloat3 irradiance, sfloat vd) {
  const sfloat sky = luminance_lanes(irradiance) * M_PI_F;
  const sfloat all = sums->unoccluded + sky, arrived = sums->received + sky * vd;
  return select((sfloat)(0.0f), clamp(1.0f - arrived / all, 0.0f, 1.0f), all > 0.0f);
}

/* glTF metallic-roughness of the lanes' surfaces S seen from view `view`'s camera: the sum over the
 * light table of f E n.l (the file's punctual lights, or the default light, or none), the environment
 * times the occlusion, plus the emissive term, under the sheen and then the clear coat where there are
 * ones; an unlit material is its base colour; the ground catcher is black, and its opacity (*alpha,
 * the lanes' alpha so far elsewhere) the shadow on it (catcher_alpha). */
inline sfloat3 shade_pbr(const ShadeInputs* in, const LaneWinners* L, const Surface* S, int view, sfloat* alpha) {
  const bool glass = any(L->glass), coated = any(L->coated); /* their terms cost nothing to other lanes */
  const Iridescence* irid = any(L->irid) ? &S->irid : 0;
  const Sheen* sheen = any(L->sheen) ? &S->sheen : 0;
  const sfloat3 n = S->n, v = S->v, base = S->base, f0 = S->f0;
  const sfloat f90 = S->f90;
  const sfloat metallic = S->metallic, r = S->r, transmission = S->transmission;
  const LightSums sums = light_table_lanes(in, L, S);
  sfloat3 direct = sums.direct;
  const sfloat3 lights_through = sums.through, coat_lights = sums.coat;
  const sfloat nv = s3_dot(n, v);
  sfloat A, B;
  split_sum_lanes(in->split_sum, nv, r, &A, &B);
  sfloat3 irradiance, prefiltered;
  const sfloat3 reflected = reflected_direction(S, L, nv);
  environment_lanes(in, n, reflected, metallic, r, L->act, &irradiance, &prefiltered);
  const sfloat3 open_irradiance = irradiance;
  sfloat vd = 1.0f, vs = 1.0f; /* the environment's occlusion, with shadows on */
  if (in->P->env_occlusion) {
    environment_occlusion_lanes(in, L, S, reflected, &vd, &vs);
    irradiance = s3_scale(irradiance, vd), prefiltered = s3_scale(prefiltered, vs);
  }
  sfloat keep = 1.0f; /* clear glass: the opacity left where the glass sees past the scene */
  /* transmission replaces the diffuse lobe */
  const sfloat kd = glass ? (1.0f - metallic) * (1.0f - transmission) : 1.0f - metallic;
  const sfloat ao = S->ao;
  const sfloat3 R = environment_reflectance(f0, f90, A, B, irid);
  sfloat3 ambient = s3(ao * (base.x * kd * irradiance.x + R.x * prefiltered.x),
                       ao * (base.y * kd * irradiance.y + R.y * prefiltered.y),
                       ao * (base.z * kd * irradiance.z + R.z * prefiltered.z));
  if (glass) { /* KHR_materials_transmission's BTDF: (1 - R) c_diff x the light through */
    const sfloat w = select((sfloat)(0.0f), transmission * (1.0f - metallic), L->glass);
    sfloat3 attenuation;
    sfloat escaped;
    const sfloat3 through = transmitted_lanes(in, L, S->p, n, v, r, S->thickness, view, &attenuation, &escaped);
    const sfloat3 weight = btdf_weight(ao * w, R, base);
    ambient = s3_add(ambient, s3_mul(weight, through));
    /* clear glass: what would have shown the environment lets the image's background through instead */
    if (in->P->clear_glass) keep = fmax(1.0f - escaped * luminance_lanes(s3_mul(weight, attenuation)), 1.0f / 1024.0f);
    sfloat3 lights_in = s3_mul(s3_scale(s3_mul(base, attenuation), w), lights_through);
    if (sheen) lights_in = sheen_view_scaled(sheen, lights_in);
    direct = s3_add(direct, lights_in);
  }
  sfloat3 lit = s3_add(s3_add(direct, ambient), S->emissive);
  if (sheen) /* the sheen between the view and the rest (the lights' layering is in f) */
    lit = s3_select(lit, s3_add(direct, sheen_over_environment(in, L, S, s3_add(ambient, S->emissive), vd)), sheen->on);
  if (coated) lit = coated_lanes(in, L, S, lit, coat_lights, vs);
  if (any(L->catcher)) { /* the shadow alone, as premultiplied black */
    *alpha = select(*alpha, catcher_alpha(&sums, open_irradiance, vd), L->catcher);
    lit = s3_select(lit, s3_splat((float3)(0.0f)), L->catcher);
  }
  /* the colour is returned straight (the raster multiplies it by alpha): the light drawn over `keep` */
  if (glass && in->P->clear_glass) *alpha *= keep, lit = s3_scale(lit, 1.0f / keep);
  return s3_select(lit, base, L->unlit);
}

/* Colours are stored as halves, whose largest finite value is 65504: a brighter value (the peak of a
 * mirror-like highlight under a strong light) saturates there instead of becoming infinite. */
inline sfloat3 s3_half_range(sfloat3 c) {
  const sfloat m = (sfloat)(65504.0f);
  return s3(fmin(c.x, m), fmin(c.y, m), fmin(c.z, m));
}

/* Lit colours (RGB) of the winners L in view `view` of the pass (the volume's view + P->view_base), at
 * most 65504, and their opacity (*alpha: lane_alpha). `light`: the unit direction toward Lambert's one
 * light (pbr reads the light table instead). Each lane's value depends on its own winner and voxel
 * alone. */
inline sfloat3 shade_lanes(const ShadeInputs* in, const LaneWinners* L, float3 light, int view, sfloat* alpha) {
  const bool pbr = in->P->shading == PMR_SHADING_PBR;
  const sfloat3 b = lane_barycentrics(L);
  LaneTextures T;
  const bool textured = L->textured != 0u;
  const LaneBaryGrad* grad = 0; /* the barycentrics' derivatives: trilinear maps, specular antialiasing */
#if PMR_TRILINEAR
  LaneBaryGrad g;
  if (PMR_USE_TRILINEAR(in->P) && (pbr || textured)) g = lane_bary_gradient(L), grad = &g;
#endif
  if (textured) sample_lanes(in, L, b, grad, pbr, &T);
  const sfloat3 base = lane_base_color(L, &T, textured, b);
  *alpha = lane_alpha(L, &T, textured, b);
  const sfloat3 ni = s3_interp_lanes(b, L->n);
  const sfloat len = sqrt(s3_dot(ni, ni));
  sfloat3 n = s3_select(L->face, s3_scale(ni, 1.0f / len), L->smooth & (len > 0.0f));
  const float exposure = in->P->exposure;
  if (pbr) {
    sfloat spread = 0.0f, coat_spread = 0.0f;
#if PMR_TRILINEAR
    if (grad) {
      spread = coat_spread = geometric_spread(L, grad, n, len);
      if (textured) spread += vload_s(0, T.normal.toksvig);
      if (textured && any(L->coated)) coat_spread += vload_s(0, T.coat_normal.toksvig);
    }
#endif
    /* anisotropic lanes count as textured: they have a tangent frame */
    TangentFrame F;
    if (textured) F = tangent_frame(&T, n);
    const sfloat3 aniso_t = any(L->aniso) ? anisotropy_direction(L, &T, &F) : s3_splat((float3)(0.0f));
    /* the coat has its own normal map, or none: it follows the geometric normal */
    sfloat3 coat_n = n;
    if (any(L->coated)) {
      if (textured) coat_n = mapped_normal(&T.coat_normal, &F, n);
      coat_n = s3_select(coat_n, s3_neg(coat_n), L->back);
    }
    if (textured) n = mapped_normal(&T.normal, &F, n);
    n = s3_select(n, s3_neg(n), L->back); /* t, b and n together */
    Surface S = surface_material(L, &T, textured, b, n, coat_n, aniso_t, base, spread, coat_spread);
    surface_seen_from(&S, in, L, &T, textured, view);
    return s3_half_range(s3_scale(shade_pbr(in, L, &S, view, alpha), exposure));
  }
  n = s3_select(n, s3_neg(n), L->back);
  *alpha = select(*alpha, (sfloat)(0.0f), L->catcher); /* lambert draws no shadow to catch */
  const sfloat lambert = 0.2f + 0.8f * max(s3_dot(n, s3_splat(light)), 0.0f);
  return s3_half_range(s3(base.x * lambert * exposure, base.y * lambert * exposure, base.z * lambert * exposure));
}

/* The base colour alpha (baseColorFactor alpha x COLOR_0 alpha x the base colour map's alpha) of
 * triangle `tri` at source barycentrics b[.][j] of lanes j < n (lanes from n on: copies of lane 0,
 * finite, unused), the map trilinear with the barycentrics' derivatives g, or at level 0 (g = 0). Each
 * lane is one lane of sample_map_lanes, so how lanes are batched changes no value. */
inline void triangle_alpha_lanes(const ShadeInputs* in, uint tri, float b[3][SW], int n, const LaneBaryGrad* g,
                                 float* alpha) {
  const PmrTriangle t = in->tris[tri];
  global const PmrMaterial* mat = &in->materials[t.material];
  const float ca[3] = {in->attrs[t.v[0]].color[3], in->attrs[t.v[1]].color[3], in->attrs[t.v[2]].color[3]};
  for (int j = 0; j < SW; ++j) alpha[j] = mat->base_color[3] * (b[0][j] * ca[0] + b[1][j] * ca[1] + b[2][j] * ca[2]);
  if (mat->maps[PMR_MAP_BASE_COLOR].texture < 0) return;
  uint tris[SW];
  for (int j = 0; j < SW; ++j) tris[j] = tri;
  LaneTexcoords C;
  C.set = PMR_NO_KEY;
  sfloat c[4];
  sample_map_lanes(in, &mat->maps[PMR_MAP_BASE_COLOR], tris, (1u << n) - 1u, vload_s(0, lane_index) < (sint)(n),
                   LANE3(b), g, true, &C, c);
  float a[SW];
  vstore_s(c[3], 0, a);
  for (int j = 0; j < n; ++j) alpha[j] *= a[j];
}

/* alphaMode MASK: whether the base colour alpha of MTA m at raster points (X[j], Y[j]), j < n <= SW, of
 * view `view` passes the cutoff (pass[j]): the alpha of triangle_alpha_lanes at the points' source
 * barycentrics, the map trilinear at the view's level of detail. */
inline void mta_alpha_lanes(const ShadeInputs* in, const PmrMta* m, const long* X, const long* Y, int n, int view,
                            float cutoff, int* pass) {
  const long f = view_coord(in->P, view);
  float alpha[SW], b[3][SW], e[3][SW];
  for (int j = 0; j < SW; ++j) {
    if (j >= n) { /* idle: a copy of lane 0, evaluated once */
      for (int i = 0; i < 3; ++i) b[i][j] = b[i][0], e[i][j] = e[i][0];
      continue;
    }
    const long ej[3] = {m->sign * mta_edge(m, 1, 2, X[j], Y[j], f), m->sign * mta_edge(m, 2, 0, X[j], Y[j], f),
                        m->sign * mta_edge(m, 0, 1, X[j], Y[j], f)};
    const float pa = (float)ej[0] * m->inv_w[0], pb = (float)ej[1] * m->inv_w[1], pc = (float)ej[2] * m->inv_w[2];
    const float inv = 1.0f / (pa + pb + pc);
    const float la = pa * inv, lb = pb * inv, lc = pc * inv;
    const float b1 = la * m->bary[0][0] + lb * m->bary[1][0] + lc * m->bary[2][0];
    const float b2 = la * m->bary[0][1] + lb * m->bary[1][1] + lc * m->bary[2][1];
    b[0][j] = 1.0f - b1 - b2, b[1][j] = b1, b[2][j] = b2;
    for (int i = 0; i < 3; ++i) e[i][j] = (float)ej[i];
  }
  LaneBaryGrad g;
  const bool trilinear = PMR_USE_TRILINEAR(in->P);
  if (trilinear && in->materials[in->tris[m->tri].material].maps[PMR_MAP_BASE_COLOR].texture >= 0) {
    float3 ex, ey;
    mta_edge_derivatives(in->P, m, f, &ex, &ey);
    g = bary_gradient_lanes(LANE3(e), s3_splat(ex), s3_splat(ey),
                            s3_splat((float3)(m->inv_w[0], m->inv_w[1], m->inv_w[2])),
                            s3_splat((float3)(m->bary[0][0], m->bary[1][0], m->bary[2][0])),
                            s3_splat((float3)(m->bary[0][1], m->bary[1][1], m->bary[2][1])));
  }
  triangle_alpha_lanes(in, m->tri, b, n, trilinear ? &g : 0, alpha);
  for (int j = 0; j < n; ++j) pass[j] = alpha[j] >= cutoff;
}

/* How much of a light triangle `tri` blocks at source barycentrics b[.][j], j < n (DESIGN section 4d):
 * alphaMode MASK 1 or 0 by its cutoff, BLEND its alpha (clamped to [0, 1]), a transmissive material
 * 1 - transmission (factor x the map's R; colourless), others 1. Maps at level 0. */
inline void caster_opacity_lanes(const ShadeInputs* in, uint tri, float b[3][SW], int n, float* opacity) {
  global const PmrMaterial* mat = &in->materials[in->tris[tri].material];
  if (mat->transmission > 0.0f) {
    float t[SW];
    for (int j = 0; j < SW; ++j) t[j] = mat->transmission;
    if (mat->maps[PMR_MAP_TRANSMISSION].texture >= 0) {
      uint tris[SW];
      for (int j = 0; j < SW; ++j) tris[j] = tri;
      LaneTexcoords C;
      C.set = PMR_NO_KEY;
      sfloat c[4];
      sample_map_lanes(in, &mat->maps[PMR_MAP_TRANSMISSION], tris, (1u << n) - 1u, vload_s(0, lane_index) < (sint)(n),
                       LANE3(b), 0, false, &C, c);
      vstore_s(vload_s(0, t) * c[0], 0, t);
    }
    for (int j = 0; j < n; ++j) opacity[j] = clamp(1.0f - t[j], 0.0f, 1.0f);
    return;
  }
  if (mat->alpha_mode == PMR_ALPHA_OPAQUE) {
    for (int j = 0; j < n; ++j) opacity[j] = 1.0f;
    return;
  }
  triangle_alpha_lanes(in, tri, b, n, 0, opacity);
  for (int j = 0; j < n; ++j)
    opacity[j] = mat->alpha_mode == PMR_ALPHA_MASK ? (opacity[j] >= mat->alpha_cutoff ? 1.0f : 0.0f)
                                                   : clamp(opacity[j], 0.0f, 1.0f);
}

/* The MTA loaded last for shading: neighbouring voxels and samples mostly share their winner, and an
 * MTA is 108 bytes from anywhere in the queue. Start with id = PMR_NO_KEY. */
typedef struct {
  uint id;
  PmrMta m;
} MtaCache;

inline const PmrMta* cached_mta(MtaCache* c, global const PmrMta* mtas, uint id) {
  if (c->id != id) {
    c->id = id;
    c->m = mtas[id];
  }
  return &c->m;
}

#endif
