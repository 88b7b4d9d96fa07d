/* Shading (docs/SHADING.md), the one module every path calls: base colour from baseColorFactor *
 * baseColorTexture (sRGB-decoded, bilinear, glTF wrap modes) * COLOR_0, then either view-independent
 * Lambert with one directional light, or glTF metallic-roughness (cl/brdf.h) with the material's
 * metallic-roughness, normal, occlusion and emissive maps, seen from each view's own camera, lit by the
 * frame's light table (the file's punctual lights or the default light) and the uniform default
 * environment or an environment image (cl/environment.h). */
#ifndef PMR_CL_SHADE_H
#define PMR_CL_SHADE_H

#include "common.h"
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

/* Barycentrics of voxel point in the SOURCE triangle, perspective-correct. e[k] are the (sign-
 * corrected, non-negative) edge functions opposite MTA vertex k. */
inline float3 source_barycentrics(const PmrMta* m, const long* e) {
  const float pa = (float)e[0] * m->inv_w[0], pb = (float)e[1] * m->inv_w[1], pc = (float)e[2] * m->inv_w[2];
  const float inv = 1.0f / (pa + pb + pc);
  const float la = pa * inv, lb = pb * inv, lc = pc * inv;
  const float b1 = la * m->bary[0][0] + lb * m->bary[1][0] + lc * m->bary[2][0];
  const float b2 = la * m->bary[0][1] + lb * m->bary[1][1] + lc * m->bary[2][1];
  return (float3)(1.0f - b1 - b2, b1, b2);
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

/* Material map `map` of triangle t at source barycentrics b: its TEXCOORD set interpolated, then its
 * KHR_texture_transform. */
inline float4 sample_map(const ShadeInputs* in, global const PmrTextureMap* map, const PmrTriangle* t, float3 b, bool srgb) {
  const uint set = map->texcoord * in->P->num_vertices;
  const float2 uv = b.x * in->texcoords[set + t->v[0]] + b.y * in->texcoords[set + t->v[1]] +
                    b.z * in->texcoords[set + t->v[2]];
  const float u = map->uv_transform[0] * uv.x + map->uv_transform[1] * uv.y + map->uv_transform[2];
  const float v = map->uv_transform[3] * uv.x + map->uv_transform[4] * uv.y + map->uv_transform[5];
  const PmrTexture tex = in->textures[map->texture];
  return sample_texture(in->texels, in->srgb_lut, &tex, u, v, srgb);
}

/* The normal map applied to the interpolated normal n (before any back-face flip): the interpolated
 * tangent made orthogonal to n, the bitangent sign(w) * cross(n, t), m = (2 s - 1) * (scale, scale, 1).
 * A vertex without a tangent (zero) leaves n as it is. */
inline float3 mapped_normal(const ShadeInputs* in, global const PmrMaterial* mat, const PmrTriangle* t, float3 b, float3 n) {
  const float4 tw = b.x * in->tangents[t->v[0]] + b.y * in->tangents[t->v[1]] + b.z * in->tangents[t->v[2]];
  float3 tangent = tw.xyz - n * dot(n, tw.xyz);
  const float len = length(tangent);
  if (!(len > 1e-12f)) return n;
  tangent *= 1.0f / len;
  const float3 bitangent = (tw.w < 0.0f ? -1.0f : 1.0f) * cross(n, tangent);
  const float3 s = sample_map(in, &mat->maps[PMR_MAP_NORMAL], t, b, false).xyz;
  const float3 m = (2.0f * s - 1.0f) * (float3)(mat->normal_scale, mat->normal_scale, 1.0f);
  const float3 mapped = tangent * m.x + bitangent * m.y + n * m.z;
  const float mlen = length(mapped);
  return mlen > 0.0f ? mapped * (1.0f / mlen) : n;
}

/* glTF metallic-roughness at source barycentrics b of triangle t with interpolated normal n (not yet
 * flipped for a back face) and base colour c, seen from view `view`'s camera: the material's maps
 * (metallic-roughness, normal, occlusion, emissive), the sum over the light table of f E n.l (the
 * file's punctual lights, or the default light, or none), the environment times the occlusion, plus the
 * emissive term; an unlit material is its base colour. The environment is the image's I(n) and
 * P(reflect(-v, n), r) when one is given, else the uniform default of radiance L, for which
 * I(n) = P = L and no table is read. */
inline float3 shade_pbr(const ShadeInputs* in, const PmrTriangle* t, float3 b, float3 n, bool back, float3 base,
                        int view) {
  global const PmrParams* P = in->P;
  /* a pointer, not a copy: most voxels read a few of its 192 bytes */
  global const PmrMaterial* mat = &in->materials[t->material];
  if (mat->unlit) return base;
  float metallic = mat->metallic, roughness = mat->roughness;
  if (mat->maps[PMR_MAP_METALLIC_ROUGHNESS].texture >= 0) {
    const float4 s = sample_map(in, &mat->maps[PMR_MAP_METALLIC_ROUGHNESS], t, b, false);
    metallic *= s.z, roughness *= s.y;
  }
  if (mat->maps[PMR_MAP_NORMAL].texture >= 0) n = mapped_normal(in, mat, t, b, n);
  if (back) n = -n; /* t, b and n together */
  float ao = 1.0f;
  if (mat->maps[PMR_MAP_OCCLUSION].texture >= 0)
    ao = 1.0f + mat->occlusion_strength * (sample_map(in, &mat->maps[PMR_MAP_OCCLUSION], t, b, false).x - 1.0f);
  float3 emissive = vload3(0, mat->emissive);
  if (mat->maps[PMR_MAP_EMISSIVE].texture >= 0) emissive *= sample_map(in, &mat->maps[PMR_MAP_EMISSIVE], t, b, true).xyz;

  const float3 p = b.x * vload3(t->v[0], in->positions) + b.y * vload3(t->v[1], in->positions) +
                   b.z * vload3(t->v[2], in->positions);
  const float3 v = normalize(in->eyes[view + (int)P->view_base].xyz - p);
  const float r = pbr_roughness(roughness);
  float3 direct = (float3)(0.0f);
  const uint num_lights = P->num_lights;
  for (uint i = 0; i < num_lights; ++i) {
    global const PmrLight* light = &in->lights[i];
    float3 l;
    const float3 E = light_irradiance((int)light->type, vload3(0, light->color), vload3(0, light->position),
                                      vload3(0, light->direction), light->range, light->cos_inner, light->cos_outer, p, &l);
    direct += brdf_cos(base, metallic, r, n, v, l) * E;
  }
  const float nv = dot(n, v);
  const float2 ab = split_sum(in->split_sum, clamp(nv, 0.0f, 1.0f), r);
  float3 irradiance, prefiltered;
  if (in->env->level_count == 0) {
    irradiance = prefiltered = (float3)(P->env_radiance);
  } else {
    const float4 uv = env_uv(in->env, n, 2.0f * nv * n - v); /* n and reflect(-v, n) */
    irradiance = metallic < 1.0f ? env_irradiance(in->env, in->env_data, uv.xy) : (float3)(0.0f); /* c_diff = 0 */
    prefiltered = env_prefiltered(in->env, in->env_data, uv.zw, r);
  }
  const float3 ambient = ao * (base * (1.0f - metallic) * irradiance + (pbr_f0(base, metallic) * ab.x + ab.y) * prefiltered);
  return direct + ambient + emissive;
}

/* Unlit base colour (RGBA) at source barycentrics b of triangle `tri`. */
inline float4 base_color(const ShadeInputs* in, uint tri, float3 b) {
  const PmrTriangle t = in->tris[tri];
  global const PmrMaterial* mat = &in->materials[t.material];
  global const PmrVertexAttr* a0 = &in->attrs[t.v[0]];
  global const PmrVertexAttr* a1 = &in->attrs[t.v[1]];
  global const PmrVertexAttr* a2 = &in->attrs[t.v[2]];
  float4 c = (float4)(mat->base_color[0], mat->base_color[1], mat->base_color[2], mat->base_color[3]);
  const float4 vc = b.x * vload4(0, a0->color) + b.y * vload4(0, a1->color) + b.z * vload4(0, a2->color);
  c *= vc;
  if (mat->texture >= 0) {
    const PmrTexture tex = in->textures[mat->texture];
    const float u = b.x * a0->uv[0] + b.y * a1->uv[0] + b.z * a2->uv[0];
    const float v = b.x * a0->uv[1] + b.y * a1->uv[1] + b.z * a2->uv[1];
    c *= sample_texture(in->texels, in->srgb_lut, &tex, u, v, true);
  }
  return c;
}

/* Lit colour in view `view` of the pass (the volume's view + P->view_base); alpha is coverage (1).
 * `light`: the unit direction toward Lambert's one light (pbr reads the light table instead). */
inline float4 shade(const ShadeInputs* in, float3 light, uint tri, float3 b, bool back, int view) {
  const PmrTriangle t = in->tris[tri];
  float3 n;
  if (t.has_normals) {
    n = b.x * vload3(0, in->attrs[t.v[0]].normal) + b.y * vload3(0, in->attrs[t.v[1]].normal) +
        b.z * vload3(0, in->attrs[t.v[2]].normal);
    const float len = length(n);
    n = len > 0.0f ? n * (1.0f / len) : vload3(0, t.face_normal);
  } else {
    n = vload3(0, t.face_normal);
  }
  const float4 c = base_color(in, tri, b);
  const float exposure = in->P->exposure;
  if (in->P->shading == PMR_SHADING_PBR) {
    const float3 rgb = shade_pbr(in, &t, b, n, back, c.xyz, view) * exposure;
    return (float4)(rgb, 1.0f);
  }
  if (back) n = -n;
  const float lambert = 0.2f + 0.8f * max(0.0f, dot(n, light));
  return (float4)(c.x * lambert * exposure, c.y * lambert * exposure, c.z * lambert * exposure, 1.0f);
}

/* alphaMode MASK: the MTA's base colour alpha at raster point (X, Y) of view `view` passes the cutoff
 * (barycentrics from its exact edge functions there). */
inline bool mta_alpha_passes(const ShadeInputs* in, const PmrMta* m, long X, long Y, int view, float cutoff) {
  const long e[3] = {m->sign * mta_edge(m, 1, 2, X, Y, view), m->sign * mta_edge(m, 2, 0, X, Y, view),
                     m->sign * mta_edge(m, 0, 1, X, Y, view)};
  return base_color(in, m->tri, source_barycentrics(m, e)).w >= cutoff;
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

/* Lit colour of MTA m at raster point (X, Y) (16.16 / 24.8) of view `view`: barycentrics from its exact
 * edge functions there. */
inline float4 shade_mta_at(const ShadeInputs* in, const PmrMta* m, float3 light, long X, long Y, int view) {
  const long e[3] = {m->sign * mta_edge(m, 1, 2, X, Y, view), m->sign * mta_edge(m, 2, 0, X, Y, view),
                     m->sign * mta_edge(m, 0, 1, X, Y, view)};
  return shade(in, light, m->tri, source_barycentrics(m, e), (m->flags & PMR_MTA_BACK) != 0, view);
}

#endif
