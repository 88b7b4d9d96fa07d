/* Shading (docs/SHADING.md), the one module every path calls: base colour from baseColorFactor *
 * baseColorTexture (sRGB-decoded, bilinear, glTF wrap modes) * COLOR_0, then either view-independent
 * Lambert with one directional light, or glTF metallic-roughness (cl/brdf.h) with the material's
 * metallic-roughness, normal, occlusion and emissive maps, seen from each view's own camera, lit by the
 * frame's light table (the file's punctual lights or the default light) and the uniform default
 * environment or an environment image (cl/environment.h).
 *
 * Shading goes SW voxels (or samples) at a time, one per lane (cl/lanes.h): the callers hand over the
 * lanes that share a winning MTA, so the triangle, its vertices and its material are the same in every
 * lane and their branches are taken once; the barycentrics, the BRDF and the lights are vector
 * arithmetic, and the texture, split-sum and environment lookups are gathered lane by lane. Each lane's
 * result is a function of its own voxel alone, so it does not depend on the grouping, the tile shape or
 * the path. */
#ifndef PMR_CL_SHADE_H
#define PMR_CL_SHADE_H

#include "common.h"
#include "lanes.h"
#include "brdf.h"
#include "environment.h"

inline int wrap_texel(int c, int size, int mode) {
  if ((uint)c < (uint)size) return c; /* inside: every mode leaves it (and skips a division) */
  if (mode == PMR_WRAP_CLAMP) return clamp(c, 0, size - 1);
  if (mode == PMR_WRAP_MIRROR) {
    const int period = 2 * size;
    int r = c % period;
    if (r < 0) r += period;
    return r < size ? r : period - 1 - r;
  }
  int r = c % size; /* REPEAT */
  return r < 0 ? r + size : r;
}

/* Texel (x, y): colour maps decode sRGB, data maps (metallic-roughness, normal, occlusion) are linear. */
inline float4 texel(global const uchar4* texels, global const float* srgb_lut, const PmrTexture* t, int x, int y,
                    bool srgb) {
  const uchar4 c = texels[t->offset + (uint)(y * t->width + x)];
  if (!srgb) return convert_float4(c) * (1.0f / 255.0f);
  return (float4)(srgb_lut[c.x], srgb_lut[c.y], srgb_lut[c.z], (float)c.w * (1.0f / 255.0f));
}

/* Bilinear sample; uv (0,0) is the top-left corner of the image (row 0). */
inline float4 sample_texture(global const uchar4* texels, global const float* srgb_lut, const PmrTexture* t, float u,
                             float v, bool srgb) {
  const float fx = u * (float)t->width - 0.5f, fy = v * (float)t->height - 0.5f;
  const float x0f = floor(fx), y0f = floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  /* clamp before converting so huge UVs stay well defined */
  const int x0 = (int)clamp(x0f, -1.0e8f, 1.0e8f), y0 = (int)clamp(y0f, -1.0e8f, 1.0e8f);
  const int xa = wrap_texel(x0, t->width, t->wrap_s), xb = wrap_texel(x0 + 1, t->width, t->wrap_s);
  const int ya = wrap_texel(y0, t->height, t->wrap_t), yb = wrap_texel(y0 + 1, t->height, t->wrap_t);
  const float4 c00 = texel(texels, srgb_lut, t, xa, ya, srgb), c10 = texel(texels, srgb_lut, t, xb, ya, srgb);
  const float4 c01 = texel(texels, srgb_lut, t, xa, yb, srgb), c11 = texel(texels, srgb_lut, t, xb, yb, srgb);
  const float4 top = c00 + (c10 - c00) * ax, bottom = c01 + (c11 - c01) * ax;
  return top + (bottom - top) * ay;
}

typedef struct {
  global const PmrTriangle* tris;
  global const PmrVertexAttr* attrs;
  global const PmrMaterial* materials;
  global const PmrTexture* textures;
  global const uchar4* texels;
  global const float* srgb_lut;
  global const PmrParams* P;
  global const float* positions;   /* world space, 3 floats per vertex: the surface point (pbr)  */
  global const float4* eyes;       /* each view's camera position, world space (pbr)            */
  global const float2* split_sum;  /* PMR_SPLIT_SUM_N^2 (A, B) (see PMR_SPLIT_SUM_N)             */
  global const float2* texcoords;  /* TEXCOORD set k of vertex v at k * num_vertices + v (pbr maps) */
  global const float4* tangents;   /* world tangent per vertex (w: bitangent sign), pbr normal maps */
  global const PmrEnvironment* env; /* pbr: the environment image's tables, level_count 0 = none */
  global const float4* env_data;    /* ... their data (cl/environment.h)                        */
  global const PmrLight* lights;   /* P->num_lights punctual lights, world space (pbr)           */
} ShadeInputs;

/* The split-sum table's bilinear lookup, as pmr::split_sum (host/shading/environment.cpp) does it. */
inline float2 split_sum(global const float2* t, float nv, float r) {
  const int n = PMR_SPLIT_SUM_N;
  const float x = sqrt(clamp(nv, 0.0f, 1.0f)) * (float)(n - 1), y = clamp(r, 0.0f, 1.0f) * (float)(n - 1);
  const int x0 = min((int)x, n - 2), y0 = min((int)y, n - 2);
  const float fx = x - (float)x0, fy = y - (float)y0;
  const float2 a = t[y0 * n + x0], b = t[y0 * n + x0 + 1], c = t[(y0 + 1) * n + x0], d = t[(y0 + 1) * n + x0 + 1];
  const float2 top = a + (b - a) * fx, bottom = c + (d - c) * fx;
  return top + (bottom - top) * fy;
}

/* Lanes' (u, v) of texture t, bilinear, where `act`; 0 elsewhere. Per lane: texels are gathered. */
inline sfloat4 sample_lanes(const ShadeInputs* in, const PmrTexture* t, sfloat u, sfloat v, const int* act, bool srgb) {
  float us[SW], vs[SW], c[4][SW];
  vstore_s(u, 0, us);
  vstore_s(v, 0, vs);
  for (int l = 0; l < SW; ++l) {
    const float4 s = act[l] ? sample_texture(in->texels, in->srgb_lut, t, us[l], vs[l], srgb) : (float4)(0.0f);
    c[0][l] = s.x, c[1][l] = s.y, c[2][l] = s.z, c[3][l] = s.w;
  }
  return s4_load(c[0], c[1], c[2], c[3]);
}

/* Barycentrics in the SOURCE triangle, perspective-correct, of lanes whose sign-corrected (inside >= 0)
 * edge functions opposite MTA vertices 0, 1, 2 are e.x, e.y, e.z. */
inline sfloat3 lane_barycentrics(const PmrMta* m, sfloat3 e) {
  const sfloat pa = e.x * m->inv_w[0], pb = e.y * m->inv_w[1], pc = e.z * m->inv_w[2];
  const sfloat inv = 1.0f / (pa + pb + pc);
  const sfloat la = pa * inv, lb = pb * inv, lc = pc * inv;
  const sfloat b1 = la * m->bary[0][0] + lb * m->bary[1][0] + lc * m->bary[2][0];
  const sfloat b2 = la * m->bary[0][1] + lb * m->bary[1][1] + lc * m->bary[2][1];
  return s3(1.0f - b1 - b2, b1, b2);
}

/* The sign-corrected edge functions of lanes at the pixel centers (X + l, Y) (16.16 / 24.8), l < SW, of
 * view `view`: exact 64-bit values stepped along the row (E is linear in X), each rounded to float once.
 * Exact, so a voxel's value does not depend on where its row chunk starts. */
inline sfloat3 lane_edges_row(const PmrMta* m, long X, long Y, int view) {
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  float e[3][SW];
  for (int k = 0; k < 3; ++k) {
    long E = (long)m->sign * mta_edge(m, ea[k], eb[k], X, Y, view);
    const long step = (long)m->sign * (long)(m->y[eb[k]] - m->y[ea[k]]) * PMR_X_ONE;
    for (int l = 0; l < SW; ++l, E += step) e[k][l] = (float)E;
  }
  return s3(vload_s(0, e[0]), vload_s(0, e[1]), vload_s(0, e[2]));
}

/* The same at arbitrary points (Xc + sx[l], Yc + sy[l]) for l < n; lanes from n on repeat lane 0. */
inline sfloat3 lane_edges_at(const PmrMta* m, long Xc, long Yc, const int* sx, const int* sy, int n, int view) {
  float e[3][SW];
  for (int l = 0; l < SW; ++l) {
    const int s = l < n ? l : 0;
    const long X = Xc + sx[s], Y = Yc + sy[s];
    e[0][l] = (float)((long)m->sign * mta_edge(m, 1, 2, X, Y, view));
    e[1][l] = (float)((long)m->sign * mta_edge(m, 2, 0, X, Y, view));
    e[2][l] = (float)((long)m->sign * mta_edge(m, 0, 1, X, Y, view));
  }
  return s3(vload_s(0, e[0]), vload_s(0, e[1]), vload_s(0, e[2]));
}

/* Material map `map` of triangle t at the lanes' source barycentrics b: its TEXCOORD set interpolated,
 * then its KHR_texture_transform. */
inline sfloat4 sample_map(const ShadeInputs* in, global const PmrTextureMap* map, const PmrTriangle* t, sfloat3 b,
                          const int* act, bool srgb) {
  const uint set = map->texcoord * in->P->num_vertices;
  const float2 t0 = in->texcoords[set + t->v[0]], t1 = in->texcoords[set + t->v[1]], t2 = in->texcoords[set + t->v[2]];
  const sfloat u0 = s_interp(b, t0.x, t1.x, t2.x), v0 = s_interp(b, t0.y, t1.y, t2.y);
  const sfloat u = map->uv_transform[0] * u0 + map->uv_transform[1] * v0 + map->uv_transform[2];
  const sfloat v = map->uv_transform[3] * u0 + map->uv_transform[4] * v0 + map->uv_transform[5];
  const PmrTexture tex = in->textures[map->texture];
  return sample_lanes(in, &tex, u, v, act, srgb);
}

/* The normal map applied to the interpolated normal n (before any back-face flip): the interpolated
 * tangent made orthogonal to n, the bitangent sign(w) * cross(n, t), m = (2 s - 1) * (scale, scale, 1).
 * A lane without a tangent (zero) keeps n as it is. */
inline sfloat3 mapped_normal(const ShadeInputs* in, global const PmrMaterial* mat, const PmrTriangle* t, sfloat3 b,
                             sfloat3 n, const int* act) {
  const float4 T0 = in->tangents[t->v[0]], T1 = in->tangents[t->v[1]], T2 = in->tangents[t->v[2]];
  const sfloat3 tw = s3_interp(b, T0.xyz, T1.xyz, T2.xyz);
  const sfloat w = s_interp(b, T0.w, T1.w, T2.w);
  sfloat3 tangent = s3_sub(tw, s3_scale(n, s3_dot(n, tw)));
  const sfloat len = sqrt(s3_dot(tangent, tangent));
  tangent = s3_scale(tangent, 1.0f / len);
  const sfloat3 bitangent = s3_scale(s3_cross(n, tangent), select((sfloat)(1.0f), (sfloat)(-1.0f), w < 0.0f));
  const sfloat4 s = sample_map(in, &mat->maps[PMR_MAP_NORMAL], t, b, act, false);
  const float scale = mat->normal_scale;
  const sfloat3 m = s3((2.0f * s.x - 1.0f) * scale, (2.0f * s.y - 1.0f) * scale, 2.0f * s.z - 1.0f);
  const sfloat3 mapped = s3_add(s3_add(s3_scale(tangent, m.x), s3_scale(bitangent, m.y)), s3_scale(n, m.z));
  const sfloat mlen = sqrt(s3_dot(mapped, mapped));
  return s3_select(n, s3_scale(mapped, 1.0f / mlen), (len > 1e-12f) & (mlen > 0.0f));
}

/* The environment's I(n) and P(reflect(-v, n), r) per lane where `act` (cl/environment.h), or the
 * uniform default of radiance L, for which I(n) = P = L and no table is read. I is not needed (0) where
 * metallic is 1 (c_diff = 0). */
inline void environment_lanes(const ShadeInputs* in, sfloat3 n, sfloat3 v, sfloat nv, sfloat metallic, sfloat r,
                              const int* act, sfloat3* irradiance, sfloat3* prefiltered) {
  if (in->env->level_count == 0) {
    *irradiance = *prefiltered = s3_splat((float3)(in->P->env_radiance));
    return;
  }
  float nx[SW], ny[SW], nz[SW], dx[SW], dy[SW], dz[SW], ms[SW], rs[SW], c[6][SW];
  s3_store(n, nx, ny, nz);
  s3_store(s3_sub(s3_scale(n, 2.0f * nv), v), dx, dy, dz); /* reflect(-v, n) */
  vstore_s(metallic, 0, ms);
  vstore_s(r, 0, rs);
  for (int l = 0; l < SW; ++l) {
    float3 irr = (float3)(0.0f), pre = (float3)(0.0f);
    if (act[l]) {
      const float4 uv = env_uv(in->env, (float3)(nx[l], ny[l], nz[l]), (float3)(dx[l], dy[l], dz[l]));
      if (ms[l] < 1.0f) irr = env_irradiance(in->env, in->env_data, uv.xy);
      pre = env_prefiltered(in->env, in->env_data, uv.zw, rs[l]);
    }
    c[0][l] = irr.x, c[1][l] = irr.y, c[2][l] = irr.z, c[3][l] = pre.x, c[4][l] = pre.y, c[5][l] = pre.z;
  }
  *irradiance = s3(vload_s(0, c[0]), vload_s(0, c[1]), vload_s(0, c[2]));
  *prefiltered = s3(vload_s(0, c[3]), vload_s(0, c[4]), vload_s(0, c[5]));
}

/* glTF metallic-roughness of the lanes of triangle t at source barycentrics b with interpolated normals
 * n (not yet flipped for a back face) and base colours `base`, seen from view `view`'s camera: the
 * material's maps (metallic-roughness, normal, occlusion, emissive), the sum over the light table of
 * f E n.l (the file's punctual lights, or the default light, or none), the environment times the
 * occlusion, plus the emissive term; an unlit material is its base colour. */
inline sfloat3 shade_pbr(const ShadeInputs* in, const PmrTriangle* t, sfloat3 b, sfloat3 n, bool back, sfloat3 base,
                         int view, const int* act) {
  global const PmrParams* P = in->P;
  /* a pointer, not a copy: most lanes read a few of its 192 bytes */
  global const PmrMaterial* mat = &in->materials[t->material];
  if (mat->unlit) return base;
  sfloat metallic = (sfloat)(mat->metallic), roughness = (sfloat)(mat->roughness);
  if (mat->maps[PMR_MAP_METALLIC_ROUGHNESS].texture >= 0) {
    const sfloat4 s = sample_map(in, &mat->maps[PMR_MAP_METALLIC_ROUGHNESS], t, b, act, false);
    metallic *= s.z, roughness *= s.y;
  }
  if (mat->maps[PMR_MAP_NORMAL].texture >= 0) n = mapped_normal(in, mat, t, b, n, act);
  if (back) n = s3_neg(n); /* t, b and n together */
  sfloat ao = 1.0f;
  if (mat->maps[PMR_MAP_OCCLUSION].texture >= 0)
    ao = 1.0f + mat->occlusion_strength * (sample_map(in, &mat->maps[PMR_MAP_OCCLUSION], t, b, act, false).x - 1.0f);
  sfloat3 emissive = s3_splat(vload3(0, mat->emissive));
  if (mat->maps[PMR_MAP_EMISSIVE].texture >= 0) {
    const sfloat4 s = sample_map(in, &mat->maps[PMR_MAP_EMISSIVE], t, b, act, true);
    emissive = s3_mul(emissive, s3(s.x, s.y, s.z));
  }

  const sfloat3 p = s3_interp(b, vload3(t->v[0], in->positions), vload3(t->v[1], in->positions),
                              vload3(t->v[2], in->positions));
  const sfloat3 to_eye = s3_sub(s3_splat(in->eyes[view + (int)P->view_base].xyz), p);
  const sfloat3 v = s3_scale(to_eye, 1.0f / sqrt(s3_dot(to_eye, to_eye)));
  const sfloat r = pbr_roughness(roughness);
  sfloat3 direct = s3_splat((float3)(0.0f));
  const uint num_lights = P->num_lights;
  for (uint i = 0; i < num_lights; ++i) {
    global const PmrLight* light = &in->lights[i];
    sfloat3 l;
    const sfloat3 E = light_irradiance((int)light->type, vload3(0, light->color), vload3(0, light->position),
                                       vload3(0, light->direction), light->range, light->cos_inner, light->cos_outer, p, &l);
    direct = s3_add(direct, s3_mul(brdf_cos(base, metallic, r, n, v, l), E));
  }
  const sfloat nv = s3_dot(n, v);
  /* the split-sum table and the environment: gathers, lane by lane */
  float nvs[SW], rs[SW], A[SW], B[SW];
  vstore_s(nv, 0, nvs);
  vstore_s(r, 0, rs);
  for (int l = 0; l < SW; ++l) {
    const float2 ab = act[l] ? split_sum(in->split_sum, clamp(nvs[l], 0.0f, 1.0f), rs[l]) : (float2)(0.0f);
    A[l] = ab.x, B[l] = ab.y;
  }
  sfloat3 irradiance, prefiltered;
  environment_lanes(in, n, v, nv, metallic, r, act, &irradiance, &prefiltered);
  const sfloat3 f0 = pbr_f0(base, metallic);
  const sfloat a = vload_s(0, A), bb = vload_s(0, B), kd = 1.0f - metallic;
  const sfloat3 ambient = s3(ao * (base.x * kd * irradiance.x + (f0.x * a + bb) * prefiltered.x),
                             ao * (base.y * kd * irradiance.y + (f0.y * a + bb) * prefiltered.y),
                             ao * (base.z * kd * irradiance.z + (f0.z * a + bb) * prefiltered.z));
  return s3_add(s3_add(direct, ambient), emissive);
}

/* Unlit base colours (RGBA) of the lanes of triangle t at source barycentrics b: baseColorFactor x
 * COLOR_0 x the base colour texture. */
inline sfloat4 base_color(const ShadeInputs* in, const PmrTriangle* t, sfloat3 b, const int* act) {
  global const PmrMaterial* mat = &in->materials[t->material];
  global const PmrVertexAttr* a0 = &in->attrs[t->v[0]];
  global const PmrVertexAttr* a1 = &in->attrs[t->v[1]];
  global const PmrVertexAttr* a2 = &in->attrs[t->v[2]];
  sfloat4 c;
  c.x = mat->base_color[0] * s_interp(b, a0->color[0], a1->color[0], a2->color[0]);
  c.y = mat->base_color[1] * s_interp(b, a0->color[1], a1->color[1], a2->color[1]);
  c.z = mat->base_color[2] * s_interp(b, a0->color[2], a1->color[2], a2->color[2]);
  c.w = mat->base_color[3] * s_interp(b, a0->color[3], a1->color[3], a2->color[3]);
  if (mat->texture >= 0) {
    const PmrTexture tex = in->textures[mat->texture];
    const sfloat4 s = sample_lanes(in, &tex, s_interp(b, a0->uv[0], a1->uv[0], a2->uv[0]),
                                   s_interp(b, a0->uv[1], a1->uv[1], a2->uv[1]), act, true);
    c.x *= s.x, c.y *= s.y, c.z *= s.z, c.w *= s.w;
  }
  return c;
}

/* Lit colours (RGB; alpha is coverage, 1) of the lanes `act` of MTA m in view `view` of the pass (the
 * volume's view + P->view_base), from their edge functions e (lane_edges_row / lane_edges_at).
 * `light`: the unit direction toward Lambert's one light (pbr reads the light table instead). Every
 * lane's value depends on its own edge functions alone, never on the other lanes. */
inline sfloat3 shade_lanes(const ShadeInputs* in, const PmrMta* m, float3 light, sfloat3 e, sint act, int view) {
  int acts[SW];
  vstore_s(act, 0, acts);
  const sfloat3 b = lane_barycentrics(m, e);
  const PmrTriangle t = in->tris[m->tri];
  const float3 face = vload3(0, t.face_normal);
  sfloat3 n = s3_splat(face);
  if (t.has_normals) {
    const sfloat3 ni = s3_interp(b, vload3(0, in->attrs[t.v[0]].normal), vload3(0, in->attrs[t.v[1]].normal),
                                 vload3(0, in->attrs[t.v[2]].normal));
    const sfloat len = sqrt(s3_dot(ni, ni));
    n = s3_select(n, s3_scale(ni, 1.0f / len), len > 0.0f);
  }
  const sfloat4 c = base_color(in, &t, b, acts);
  const float exposure = in->P->exposure;
  const bool back = (m->flags & PMR_MTA_BACK) != 0;
  if (in->P->shading == PMR_SHADING_PBR)
    return s3_scale(shade_pbr(in, &t, b, n, back, s3(c.x, c.y, c.z), view, acts), exposure);
  if (back) n = s3_neg(n);
  const sfloat lambert = 0.2f + 0.8f * max(s3_dot(n, s3_splat(light)), 0.0f);
  return s3(c.x * lambert * exposure, c.y * lambert * exposure, c.z * lambert * exposure);
}

/* alphaMode MASK: of the lanes `act` of MTA m (edge functions e, view `view`), those whose base colour
 * alpha passes the cutoff. */
inline sint mta_alpha_lanes(const ShadeInputs* in, const PmrMta* m, sfloat3 e, sint act, float cutoff) {
  int acts[SW];
  vstore_s(act, 0, acts);
  const PmrTriangle t = in->tris[m->tri];
  return act & (base_color(in, &t, lane_barycentrics(m, e), acts).w >= cutoff);
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
