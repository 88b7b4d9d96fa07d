/* The material's maps at the lanes' surface points (part of the one shading module, cl/shade.h): every
 * texture the model reads, sampled once per batch of lanes into LaneTextures (cl/texture.h: bilinear,
 * or trilinear at the analytic level of detail of the lane's own view), and the tangent frame the
 * normal maps and the anisotropy direction are read in. The values are the surface's, not the view's;
 * only the level of detail comes from the view's pixel footprint. */
#ifndef PMR_CL_MATERIAL_MAPS_H
#define PMR_CL_MATERIAL_MAPS_H

#include "lane_winners.h"
#include "texture.h"

/* A tangent-space normal map's sample in the lanes that have one (mapped), with its scale and, trilinear,
 * its increment of alpha^2 (Toksvig; else 0). */
typedef struct {
  int mapped[SW];
  float s[3][SW], scale[SW], toksvig[SW];
} LaneNormalMap;

/* The texture lookups of the textured lanes as factors: base colour (RGB), metallic and roughness,
 * occlusion, emissive; the normal maps' samples with the interpolated tangent (tw) where there is one.
 * Untextured lanes get factors of 1 and no normal map. */
typedef struct {
  float base[3][SW], base_alpha[SW], metallic[SW], roughness[SW], ao[SW], emissive[3][SW];
  float tw[4][SW];
  LaneNormalMap normal;
  float transmission[SW], thickness[SW];         /* KHR_materials_transmission R, KHR_materials_volume G (glass) */
  float coat[SW], coat_roughness[SW];            /* KHR_materials_clearcoat R, G (coated) */
  LaneNormalMap coat_normal;                     /* ... clearcoatNormalTexture (coated) */
  float spec_weight[SW], spec_color[3][SW];      /* KHR_materials_specular A, RGB (specular) */
  float aniso_dir[2][SW], aniso_strength[SW];    /* KHR_materials_anisotropy: 2 RG - 1, B (aniso) */
  float irid_factor[SW], irid_thickness[SW];     /* KHR_materials_iridescence R, G (irid) */
  float sheen_color[3][SW], sheen_roughness[SW]; /* KHR_materials_sheen RGB, A (sheen) */
} LaneTextures;

/* The three vertices' TEXCOORD set of each lane's triangle (lanes `bits`, triangles tri[l]; others 0). */
typedef struct {
  uint set; /* which set (PMR_NO_KEY: none loaded yet) */
  sfloat u[3], v[3];
} LaneTexcoords;

/* Whether maps a and b read the same texels: texture, TEXCOORD set and transform. */
inline bool same_texture_map(global const PmrTextureMap* a, global const PmrTextureMap* b) {
  bool same = a->texture == b->texture && a->texcoord == b->texcoord;
  for (int k = 0; k < 6; ++k) same = same && a->uv_transform[k] == b->uv_transform[k];
  return same;
}

inline void lane_texcoords(const ShadeInputs* in, const uint* tri, uint bits, uint set, LaneTexcoords* C) {
  float u[3][SW], v[3][SW];
  for (int l = 0; l < SW; ++l) u[0][l] = u[1][l] = u[2][l] = v[0][l] = v[1][l] = v[2][l] = 0.0f;
  const uint first = set * in->P->num_vertices;
  for (uint b = bits; b != 0u; b &= b - 1u) {
    const int l = 31 - (int)clz(b & (0u - b));
    global const uint* vi = in->tris[tri[l]].v;
    for (int k = 0; k < 3; ++k) {
      const float2 t = in->texcoords[first + vi[k]];
      u[k][l] = t.x, v[k][l] = t.y;
    }
  }
  C->set = set;
  for (int k = 0; k < 3; ++k) C->u[k] = vload_s(0, u[k]), C->v[k] = vload_s(0, v[k]);
}

/* Material map `map`, the same for the lanes `act`, at their source barycentrics b: its TEXCOORD set
 * interpolated (C, loaded here when it holds another set), then its KHR_texture_transform. Every map,
 * base colour included, is read here alone, so that a set and a transform mean the same for the colour,
 * the alpha test and the pbr maps. g: the barycentrics' screen-space derivatives, from which the level
 * of detail follows (trilinear); 0: level 0 (bilinear). out: RGBA, 4 vectors. */
inline void sample_map_lanes(const ShadeInputs* in, global const PmrTextureMap* map, const uint* tri, uint bits,
                             sint act, sfloat3 b, const LaneBaryGrad* g, bool srgb, LaneTexcoords* C, sfloat* out) {
  if (C->set != map->texcoord) lane_texcoords(in, tri, bits, map->texcoord, C);
  const sfloat uu = b.x * C->u[0] + b.y * C->u[1] + b.z * C->u[2], vv = b.x * C->v[0] + b.y * C->v[1] + b.z * C->v[2];
  global const float* m = map->uv_transform;
  const sfloat u = m[0] * uu + m[1] * vv + m[2], v = m[3] * uu + m[4] * vv + m[5];
  const PmrTexture tex = in->textures[map->texture];
  sfloat lambda = 0.0f;
  if (g && tex.levels > 1u) {
    const sfloat dxu = g->dx.x * C->u[0] + g->dx.y * C->u[1] + g->dx.z * C->u[2],
                 dxv = g->dx.x * C->v[0] + g->dx.y * C->v[1] + g->dx.z * C->v[2],
                 dyu = g->dy.x * C->u[0] + g->dy.y * C->u[1] + g->dy.z * C->u[2],
                 dyv = g->dy.x * C->v[0] + g->dy.y * C->v[1] + g->dy.z * C->v[2];
    lambda = texture_lod_lanes(m, &tex, dxu, dxv, dyu, dyv);
  }
  sample_texture_lanes(in->texels, in->srgb_lut, &tex, u, v, lambda, act, srgb, out);
}

/* Map k of material `mat` into c, unless it reads the texels map `prev`, sampled into c just before
 * (with the same decoding), read: real materials pack maps into one texture (occlusion with
 * metallic-roughness, sheen roughness in the sheen colour's alpha), and c then already holds them. */
inline void sample_map_after(const ShadeInputs* in, global const PmrMaterial* mat, int k, int prev,
                             const LaneWinners* L, uint bits, sint take, sfloat3 b, const LaneBaryGrad* g, bool srgb,
                             LaneTexcoords* C, sfloat* c) {
  if (mat->maps[prev].texture >= 0 && same_texture_map(&mat->maps[prev], &mat->maps[k])) return;
  sample_map_lanes(in, &mat->maps[k], L->tri, bits, take, b, g, srgb, C, c);
}

/* Where `take`, array x (SW floats) gets the lanes of value. */
inline void lanes_put(float* x, sfloat value, sint take) { vstore_s(select(vload_s(0, x), value, take), 0, x); }

/* Normal map `k` of material `mat` (scale `scale`) for its lanes `bits` (`take`) into M. */
inline void sample_normal_map_lanes(const ShadeInputs* in, global const PmrMaterial* mat, int k, float scale,
                                    const LaneWinners* L, uint bits, sint take, sfloat3 b, const LaneBaryGrad* g,
                                    LaneTexcoords* C, LaneNormalMap* M) {
  sfloat c[4];
  sample_map_lanes(in, &mat->maps[k], L->tri, bits, take, b, g, false, C, c);
  for (int i = 0; i < 3; ++i) lanes_put(M->s[i], c[i], take);
  lanes_put(M->scale, (sfloat)(scale), take);
  vstore_s(select(vload_s(0, M->mapped), (sint)(-1), take), 0, M->mapped);
  /* the chain's alpha is the square root of the increment for unit normals (MipKind::Normal); a
   * scale shrinks the normals' spread in x and y with their slopes */
  if (g) lanes_put(M->toksvig, c[3] * c[3] * fmin(1.0f, scale * scale), take);
}

/* The clear coat maps of material `mat` (KHR_materials_clearcoat) for its lanes `bits` (`take`). */
inline void sample_coat_lanes(const ShadeInputs* in, global const PmrMaterial* mat, const LaneWinners* L, uint bits,
                              sint take, sfloat3 b, const LaneBaryGrad* g, LaneTexcoords* C, LaneTextures* T) {
  sfloat c[4];
  if (mat->maps[PMR_MAP_CLEARCOAT].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_CLEARCOAT], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->coat, c[0], take);
  }
  if (mat->maps[PMR_MAP_CLEARCOAT_ROUGHNESS].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_CLEARCOAT_ROUGHNESS], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->coat_roughness, c[1], take);
  }
  if (mat->maps[PMR_MAP_CLEARCOAT_NORMAL].texture >= 0)
    sample_normal_map_lanes(in, mat, PMR_MAP_CLEARCOAT_NORMAL, mat->clearcoat_normal_scale, L, bits, take, b, g, C,
                            &T->coat_normal);
}

/* Whether map `alpha` (read for its alpha alone) is map `colour` (sRGB): then it is sampled decoded as
 * colour, its alpha being linear either way (the host gives both the colour chain: material_tables.cpp),
 * and the packed texture is read once (sample_map_after). */
inline bool packed_alpha(global const PmrMaterial* mat, int alpha, int colour) {
  return mat->maps[colour].texture >= 0 && same_texture_map(&mat->maps[colour], &mat->maps[alpha]);
}

/* The sheen maps of material `mat` (KHR_materials_sheen) for its lanes `bits` (`take`). */
inline void sample_sheen_lanes(const ShadeInputs* in, global const PmrMaterial* mat, const LaneWinners* L, uint bits,
                               sint take, sfloat3 b, const LaneBaryGrad* g, LaneTexcoords* C, LaneTextures* T) {
  sfloat c[4];
  if (mat->maps[PMR_MAP_SHEEN_COLOR].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_SHEEN_COLOR], L->tri, bits, take, b, g, true, C, c);
    for (int k = 0; k < 3; ++k) lanes_put(T->sheen_color[k], c[k], take);
  }
  if (mat->maps[PMR_MAP_SHEEN_ROUGHNESS].texture >= 0) {
    sample_map_after(in, mat, PMR_MAP_SHEEN_ROUGHNESS, PMR_MAP_SHEEN_COLOR, L, bits, take, b, g, false, C, c);
    lanes_put(T->sheen_roughness, c[3], take);
  }
}

/* No normal map in any lane. */
inline void normal_map_clear(LaneNormalMap* M) {
  for (int l = 0; l < SW; ++l) {
    for (int k = 0; k < 3; ++k) M->s[k][l] = 0.0f;
    M->scale[l] = 1.0f, M->mapped[l] = 0, M->toksvig[l] = 0.0f;
  }
}

/* The maps of material `mat` for its lanes `bits` (`take`). */
inline void sample_material_lanes(const ShadeInputs* in, global const PmrMaterial* mat, const LaneWinners* L, uint bits,
                                  sint take, sfloat3 b, const LaneBaryGrad* g, bool pbr, LaneTexcoords* C,
                                  LaneTextures* T) {
  sfloat c[4];
  if (mat->maps[PMR_MAP_BASE_COLOR].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_BASE_COLOR], L->tri, bits, take, b, g, true, C, c);
    for (int k = 0; k < 3; ++k) lanes_put(T->base[k], c[k], take);
    if (PMR_WITH_BLEND && any(L->blended)) lanes_put(T->base_alpha, c[3], take);
  }
  if (!pbr) return;
  if (mat->maps[PMR_MAP_METALLIC_ROUGHNESS].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_METALLIC_ROUGHNESS], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->metallic, c[2], take), lanes_put(T->roughness, c[1], take);
  }
  if (mat->maps[PMR_MAP_OCCLUSION].texture >= 0) {
    sample_map_after(in, mat, PMR_MAP_OCCLUSION, PMR_MAP_METALLIC_ROUGHNESS, L, bits, take, b, g, false, C, c);
    lanes_put(T->ao, 1.0f + mat->occlusion_strength * (c[0] - 1.0f), take);
  }
  if (mat->maps[PMR_MAP_EMISSIVE].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_EMISSIVE], L->tri, bits, take, b, g, true, C, c);
    for (int k = 0; k < 3; ++k) lanes_put(T->emissive[k], c[k], take);
  }
  if (mat->maps[PMR_MAP_TRANSMISSION].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_TRANSMISSION], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->transmission, c[0], take);
  }
  if (mat->maps[PMR_MAP_THICKNESS].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_THICKNESS], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->thickness, c[1], take);
  }
  if (mat->clearcoat > 0.0f) sample_coat_lanes(in, mat, L, bits, take, b, g, C, T);
  if (mat->maps[PMR_MAP_SPECULAR].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_SPECULAR], L->tri, bits, take, b, g,
                     packed_alpha(mat, PMR_MAP_SPECULAR, PMR_MAP_SPECULAR_COLOR), C, c);
    lanes_put(T->spec_weight, c[3], take);
  }
  if (mat->maps[PMR_MAP_SPECULAR_COLOR].texture >= 0) {
    sample_map_after(in, mat, PMR_MAP_SPECULAR_COLOR, PMR_MAP_SPECULAR, L, bits, take, b, g, true, C, c);
    for (int k = 0; k < 3; ++k) lanes_put(T->spec_color[k], c[k], take);
  }
  if (mat->maps[PMR_MAP_IRIDESCENCE].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_IRIDESCENCE], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->irid_factor, c[0], take);
  }
  if (mat->maps[PMR_MAP_IRIDESCENCE_THICKNESS].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_IRIDESCENCE_THICKNESS], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->irid_thickness, c[1], take);
  }
  if (mat->flags & PMR_MATERIAL_SHEEN) sample_sheen_lanes(in, mat, L, bits, take, b, g, C, T);
  if (mat->maps[PMR_MAP_ANISOTROPY].texture >= 0) {
    sample_map_lanes(in, &mat->maps[PMR_MAP_ANISOTROPY], L->tri, bits, take, b, g, false, C, c);
    lanes_put(T->aniso_dir[0], 2.0f * c[0] - 1.0f, take), lanes_put(T->aniso_dir[1], 2.0f * c[1] - 1.0f, take);
    lanes_put(T->aniso_strength, c[2], take);
  }
  const bool normal = mat->maps[PMR_MAP_NORMAL].texture >= 0;
  if (normal) sample_normal_map_lanes(in, mat, PMR_MAP_NORMAL, mat->normal_scale, L, bits, take, b, g, C, &T->normal);
  if (normal || (mat->clearcoat > 0.0f && mat->maps[PMR_MAP_CLEARCOAT_NORMAL].texture >= 0) ||
      (mat->flags & PMR_MATERIAL_ANISOTROPY)) {
    float bs[3][SW];
    s3_store(b, bs[0], bs[1], bs[2]);
    for (uint r = bits; r != 0u; r &= r - 1u) { /* the interpolated tangent, lane by lane (a gather) */
      const int l = 31 - (int)clz(r & (0u - r));
      global const uint* vi = in->tris[L->tri[l]].v;
      const float4 tw =
          bs[0][l] * in->tangents[vi[0]] + bs[1][l] * in->tangents[vi[1]] + bs[2][l] * in->tangents[vi[2]];
      T->tw[0][l] = tw.x, T->tw[1][l] = tw.y, T->tw[2][l] = tw.z, T->tw[3][l] = tw.w;
    }
  }
}

/* The texture lookups of the textured lanes, material by material (a row's lanes mostly share one), as
 * factors (LaneTextures). grad: the lanes' barycentric derivatives (trilinear), or 0 (bilinear). */
inline void sample_lanes(const ShadeInputs* in, const LaneWinners* L, sfloat3 b, const LaneBaryGrad* grad, bool pbr,
                         LaneTextures* T) {
  for (int l = 0; l < SW; ++l) {
    for (int k = 0; k < 3; ++k) T->base[k][l] = T->emissive[k][l] = 1.0f;
    for (int k = 0; k < 4; ++k) T->tw[k][l] = 0.0f;
    T->metallic[l] = T->roughness[l] = T->ao[l] = 1.0f;
  }
  normal_map_clear(&T->normal);
  if (any(L->glass))
    for (int l = 0; l < SW; ++l) T->transmission[l] = T->thickness[l] = 1.0f;
  if (any(L->coated)) {
    for (int l = 0; l < SW; ++l) T->coat[l] = T->coat_roughness[l] = 1.0f;
    normal_map_clear(&T->coat_normal);
  }
  if (any(L->specular))
    for (int l = 0; l < SW; ++l)
      T->spec_weight[l] = T->spec_color[0][l] = T->spec_color[1][l] = T->spec_color[2][l] = 1.0f;
  if (any(L->aniso))
    for (int l = 0; l < SW; ++l) T->aniso_dir[0][l] = T->aniso_strength[l] = 1.0f, T->aniso_dir[1][l] = 0.0f;
  if (any(L->sheen))
    for (int l = 0; l < SW; ++l)
      T->sheen_color[0][l] = T->sheen_color[1][l] = T->sheen_color[2][l] = T->sheen_roughness[l] = 1.0f;
  if (any(L->irid)) /* without a thickness texture the film is the maximum thickness */
    for (int l = 0; l < SW; ++l) T->irid_factor[l] = T->irid_thickness[l] = 1.0f;
  if (PMR_WITH_BLEND && any(L->blended))
    for (int l = 0; l < SW; ++l) T->base_alpha[l] = 1.0f;
  uint material[SW];
  for (uint r = L->textured; r != 0u; r &= r - 1u) {
    const int l = 31 - (int)clz(r & (0u - r));
    material[l] = in->tris[L->tri[l]].material;
  }
  const sint lane = vload_s(0, lane_index);
  uint todo = L->textured;
  while (todo != 0u) {
    const uint mat = material[31 - (int)clz(todo & (0u - todo))];
    uint bits = 0u;
    for (uint r = todo; r != 0u; r &= r - 1u) {
      const int l = 31 - (int)clz(r & (0u - r));
      if (material[l] == mat) bits |= 1u << l;
    }
    todo &= ~bits;
    const sint take = ((sint)(bits) >> lane & 1) != 0;
    LaneTexcoords C;
    C.set = PMR_NO_KEY;
    sample_material_lanes(in, &in->materials[mat], L, bits, take, b, grad, pbr, &C, T);
  }
}

/* The tangent frame about the unit normals n (before any back-face flip): the interpolated tangent made
 * orthogonal to n and normalized (t), the bitangent sign(w) * cross(n, t) (b), and the length of the
 * orthogonalized tangent (a lane without a tangent: 0, and t, b of no use). Computed once per batch of
 * textured lanes; every normal map and the anisotropy direction read it. */
typedef struct {
  sfloat3 t, b;
  sfloat len;
} TangentFrame;

inline TangentFrame tangent_frame(const LaneTextures* T, sfloat3 n) {
  const sfloat3 tw = LANE3(T->tw);
  const sfloat3 o = s3_sub(tw, s3_scale(n, s3_dot(n, tw)));
  TangentFrame F;
  F.len = sqrt(s3_dot(o, o));
  F.t = s3_scale(o, 1.0f / F.len);
  F.b = s3_scale(s3_cross(n, F.t), select((sfloat)(1.0f), (sfloat)(-1.0f), vload_s(0, T->tw[3]) < 0.0f));
  return F;
}

/* Normal map M applied to the unit normals n (before any back-face flip; F their tangent frame), in the
 * lanes that have one: m = (2 s - 1) * (scale, scale, 1) in the frame. A lane without a tangent (zero)
 * keeps n. */
inline sfloat3 mapped_normal(const LaneNormalMap* M, const TangentFrame* F, sfloat3 n) {
  const sfloat3 tangent = F->t, bitangent = F->b;
  const sfloat len = F->len;
  const sfloat scale = vload_s(0, M->scale);
  const sfloat3 s = LANE3(M->s);
  const sfloat3 m = s3((2.0f * s.x - 1.0f) * scale, (2.0f * s.y - 1.0f) * scale, 2.0f * s.z - 1.0f);
  const sfloat3 mapped = s3_add(s3_add(s3_scale(tangent, m.x), s3_scale(bitangent, m.y)), s3_scale(n, m.z));
  const sfloat mlen = sqrt(s3_dot(mapped, mapped));
  return s3_select(n, s3_scale(mapped, 1.0f / mlen), vload_s(0, M->mapped) & (len > 1e-12f) & (mlen > 0.0f));
}

/* KHR_materials_anisotropy's direction in world space, for the lanes L->aniso: (cos, sin) of the
 * material's rotation applied to the texture's direction 2 RG - 1 (else (1, 0)), in the tangent frame F
 * about the interpolated normal (before any normal map or back-face flip), normalized; 0 where a lane
 * has no tangent (it is drawn isotropic). */
inline sfloat3 anisotropy_direction(const LaneWinners* L, const LaneTextures* T, const TangentFrame* F) {
  const sfloat3 t = F->t, b = F->b;
  const sfloat len = F->len;
  const sfloat dx = vload_s(0, T->aniso_dir[0]), dy = vload_s(0, T->aniso_dir[1]);
  const sfloat rx = L->aniso_cos * dx - L->aniso_sin * dy, ry = L->aniso_sin * dx + L->aniso_cos * dy;
  const sfloat3 d = s3_add(s3_scale(t, rx), s3_scale(b, ry));
  const sfloat dl = sqrt(s3_dot(d, d));
  return s3_select(s3_splat((float3)(0.0f)), s3_scale(d, 1.0f / dl), (len > 1e-12f) & (dl > 0.0f));
}

#endif
