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

#include "common.h"
#include "lanes.h"
#include "brdf.h"
#include "environment.h"
#include "texture.h"

/* The shading inputs: the leading parameters of every kernel that shades, bound in this order by the
 * host (SceneBuffers::bind_shading, host/pipeline/scene_buffers.cpp), and gathered into one ShadeInputs
 * by PMR_SHADE_INPUTS. A new input is one entry in each of the three lists and in the struct. */
#define PMR_SHADE_PARAMS                                                                                   \
  global const PmrParams *P, global const PmrTriangle *tris, global const PmrVertexAttr *attrs,            \
      global const PmrMaterial *materials, global const PmrTexture *textures, global const uchar4 *texels, \
      global const float *srgb_lut, global const float *positions, global const float4 *eyes,              \
      global const float2 *split_sum, global const float *sheen_albedo, global const float2 *texcoords,    \
      global const float4 *tangents, global const PmrEnvironment *env, global const float4 *env_data,      \
      global const PmrLight *lights, global const half *source, global const PmrSource *source_info,       \
      global uint *source_tiles
#define PMR_SHADE_INPUTS                                                                                        \
  {                                                                                                             \
    tris, attrs, materials, textures, texels, srgb_lut, P, positions, eyes, split_sum, sheen_albedo, texcoords, \
        tangents, env, env_data, lights, source, source_info, source_tiles                                      \
  }

typedef struct {
  global const PmrTriangle* tris;
  global const PmrVertexAttr* attrs;
  global const PmrMaterial* materials;
  global const PmrTexture* textures;
  global const uchar4* texels;
  global const float* srgb_lut;
  global const PmrParams* P;
  global const float* positions;       /* world space, 3 floats per vertex: the surface point (pbr)  */
  global const float4* eyes;           /* each view's camera position, world space (pbr)            */
  global const float2* split_sum;      /* PMR_SPLIT_SUM_N^2 (A, B) (see PMR_SPLIT_SUM_N)             */
  global const float* sheen_albedo;    /* PMR_SHEEN_ALBEDO_N^2 E (see PMR_SHEEN_ALBEDO_N)            */
  global const float2* texcoords;      /* TEXCOORD set k of vertex v at k * num_vertices + v (the maps) */
  global const float4* tangents;       /* world tangent per vertex (w: bitangent sign), pbr normal maps */
  global const PmrEnvironment* env;    /* pbr: the environment image's tables, level_count 0 = none */
  global const float4* env_data;       /* ... their data (cl/environment.h)                        */
  global const PmrLight* lights;       /* P->num_lights punctual lights, world space (pbr)           */
  global const half* source;           /* pbr: the transmission source (cl/transmission.h)           */
  global const PmrSource* source_info; /* ... its levels, and whether this is the opaque pass       */
  global uint* source_tiles;           /* ... per 3D tile: 1 if the opaque pass left a transmissive MTA out  */
} ShadeInputs;

/* 0 in programs that never see alphaMode BLEND (the fused raster + encode: the host renders BLEND
 * scenes through the view volume), which then carry none of its per-lane work. */
#ifndef PMR_WITH_BLEND
#define PMR_WITH_BLEND 1
#endif

#define LANE3(a) s3(vload_s(0, (a)[0]), vload_s(0, (a)[1]), vload_s(0, (a)[2]))

/* SW winners to shade, one per lane (a row of 8 voxels of a real model holds a few small triangles):
 * what shading reads of each lane's MTA, triangle, vertices and material, as vectors. The caller fills
 * it one MTA at a time (lanes_add): each value is loaded once per MTA and blended into the lanes the
 * MTA won, in registers (a lane-by-lane gather through memory costs what the vector arithmetic saves). */
typedef struct {
  sint act;           /* -1: a winner to shade                                           */
  sint back;          /* -1: seen from behind                                            */
  sint smooth;        /* -1: vertex normals (else the face normal)                       */
  sint unlit;         /* pbr: KHR_materials_unlit                                        */
  sfloat3 e;          /* sign-corrected edge functions opposite MTA vertices 0, 1, 2     */
  sfloat inv_w[3];    /* the MTA vertices' 1 / w                                         */
  sfloat bary[3][2];  /* ... and barycentrics in the source triangle                     */
  sfloat3 face, n[3]; /* face normal, vertex normals                                     */
  sfloat3 c[3];       /* vertex colours (COLOR_0, RGB)                                   */
  sfloat3 factor;     /* baseColorFactor (RGB)                                           */
  sint blended;       /* alphaMode BLEND: lanes whose alpha is their opacity, not 1      */
  sfloat alpha[4];    /* ... their baseColorFactor and vertex colour alphas (if any is) */
  sfloat3 p[3];       /* pbr: vertex positions, world space                              */
  sfloat metallic, roughness;
  sfloat f0d; /* pbr: the dielectric F0 (PmrMaterial.f0_dielectric)                  */
  sfloat3 emissive;
  /* pbr, transmissive materials: lanes `glass`; the fields below are set only when some lane is (and
   * then hold the opaque values in the others) */
  sint glass;
  sfloat transmission, ior, thickness, att_dist; /* thickness in world units (x the node's scale) */
  sfloat3 att_color;
  /* pbr, KHR_materials_clearcoat: lanes `coated`; their factors are set only when some lane is (0 in
   * the others) */
  sint coated;
  sfloat coat, coat_roughness;
  /* pbr, KHR_materials_specular: lanes `specular`; the factors are set only when some lane is (1 in the
   * others) */
  sint specular;
  sfloat spec_weight;
  sfloat3 spec_color;
  /* pbr, KHR_materials_anisotropy: lanes `aniso` (strength, cos and sin of the rotation); set only when
   * some lane is (strength 0 in the others). Their lanes count as textured: they read the tangent. */
  sint aniso;
  sfloat aniso_strength, aniso_cos, aniso_sin;
  /* pbr, KHR_materials_iridescence: lanes `irid` (factor, film ior, thickness range in nm); set only
   * when some lane is (factor 0 in the others) */
  sint irid;
  sfloat irid_factor, irid_ior, irid_min, irid_max;
  /* pbr, KHR_materials_sheen: lanes `sheen` (colour and roughness factors); set only when some lane
   * is (colour 0 in the others) */
  sint sheen;
  sfloat3 sheen_color;
  sfloat sheen_roughness;
  uint textured; /* bit l: lane l's material has a map the model reads (lambert: base colour) */
  uint tri[SW];  /* lane l's triangle, where textured                               */
#if PMR_TRILINEAR
  /* trilinear: the edge functions' derivatives per output pixel in x and y (lanes_edge_derivatives) */
  float ex[3][SW], ey[3][SW];
#endif
} LaneWinners;

/* No lanes yet; idle lanes keep finite values so that the vector arithmetic stays cheap. */
inline void lanes_clear(LaneWinners* L) {
  const sfloat zero = 0.0f, one = 1.0f;
  L->act = L->back = L->smooth = L->unlit = (sint)(0);
  L->e = s3(one, one, one);
  L->face = s3(zero, zero, one);
  for (int k = 0; k < 3; ++k) {
    L->inv_w[k] = one, L->bary[k][0] = L->bary[k][1] = zero;
    L->n[k] = L->face, L->c[k] = s3(one, one, one), L->p[k] = s3(zero, zero, zero);
  }
  L->factor = s3(zero, zero, zero);
  L->blended = (sint)(0); /* the alpha inputs are set when the first BLEND lane comes */
  L->metallic = L->roughness = L->f0d = zero;
  L->emissive = s3(zero, zero, zero);
  L->glass = (sint)(0);  /* the transmission inputs are set when the first glass lane comes */
  L->coated = (sint)(0); /* ... and the clear coat's when the first coated lane comes */
  L->specular = L->aniso = L->irid = L->sheen = (sint)(0);
  L->textured = 0u;
#if PMR_TRILINEAR
  for (int k = 0; k < 3; ++k) vstore_s(zero, 0, L->ex[k]), vstore_s(zero, 0, L->ey[k]);
#endif
}

inline sfloat blend(sfloat a, float b, sint take) { return select(a, (sfloat)(b), take); }
inline sfloat3 blend3(sfloat3 a, float3 b, sint take) { return s3_select(a, s3_splat(b), take); }

/* The transmission inputs of material `mat` (triangle t) into lanes `take`. */
inline void lanes_add_transmission(LaneWinners* L, const ShadeInputs* in, global const PmrMaterial* mat,
                                   const PmrTriangle* t, sint take) {
  if (!any(L->glass)) { /* the opaque lanes' values */
    L->transmission = L->thickness = (sfloat)(0.0f), L->ior = 1.5f, L->att_dist = INFINITY;
    L->att_color = s3((sfloat)(1.0f), (sfloat)(1.0f), (sfloat)(1.0f));
  }
  L->glass |= take;
  L->transmission = blend(L->transmission, mat->transmission, take);
  L->ior = blend(L->ior, mat->ior, take);
  L->thickness = blend(L->thickness, mat->thickness * in->attrs[t->v[0]].scale, take);
  L->att_dist = blend(L->att_dist, mat->attenuation_distance, take);
  L->att_color = blend3(L->att_color, vload3(0, mat->attenuation_color), take);
}

/* The clear coat factors of material `mat` into lanes `take`. */
inline void lanes_add_coat(LaneWinners* L, global const PmrMaterial* mat, sint take) {
  if (!any(L->coated)) L->coat = L->coat_roughness = (sfloat)(0.0f);
  L->coated |= take;
  L->coat = blend(L->coat, mat->clearcoat, take);
  L->coat_roughness = blend(L->coat_roughness, mat->clearcoat_roughness, take);
}

/* The specular factors of material `mat` into lanes `take`. */
inline void lanes_add_specular(LaneWinners* L, global const PmrMaterial* mat, sint take) {
  if (!any(L->specular)) L->spec_weight = (sfloat)(1.0f), L->spec_color = s3_splat((float3)(1.0f));
  L->specular |= take;
  L->spec_weight = blend(L->spec_weight, mat->specular, take);
  L->spec_color = blend3(L->spec_color, vload3(0, mat->specular_color), take);
}

/* The anisotropy factors of material `mat` into lanes `take`. */
inline void lanes_add_anisotropy(LaneWinners* L, global const PmrMaterial* mat, sint take) {
  if (!any(L->aniso)) L->aniso_strength = L->aniso_sin = (sfloat)(0.0f), L->aniso_cos = (sfloat)(1.0f);
  L->aniso |= take;
  L->aniso_strength = blend(L->aniso_strength, mat->anisotropy[0], take);
  L->aniso_cos = blend(L->aniso_cos, mat->anisotropy[1], take);
  L->aniso_sin = blend(L->aniso_sin, mat->anisotropy[2], take);
}

/* The iridescence factors of material `mat` into lanes `take`. */
inline void lanes_add_iridescence(LaneWinners* L, global const PmrMaterial* mat, sint take) {
  if (!any(L->irid)) L->irid_factor = L->irid_min = L->irid_max = (sfloat)(0.0f), L->irid_ior = (sfloat)(1.3f);
  L->irid |= take;
  L->irid_factor = blend(L->irid_factor, mat->iridescence[0], take);
  L->irid_ior = blend(L->irid_ior, mat->iridescence[1], take);
  L->irid_min = blend(L->irid_min, mat->iridescence[2], take);
  L->irid_max = blend(L->irid_max, mat->iridescence[3], take);
}

/* The sheen factors of material `mat` into lanes `take`. */
inline void lanes_add_sheen(LaneWinners* L, global const PmrMaterial* mat, sint take) {
  if (!any(L->sheen)) L->sheen_color = s3_splat((float3)(0.0f)), L->sheen_roughness = (sfloat)(1.0f);
  L->sheen |= take;
  L->sheen_color = blend3(L->sheen_color, vload3(0, mat->sheen), take);
  L->sheen_roughness = blend(L->sheen_roughness, mat->sheen[3], take);
}

/* Lanes `take` (bits: the same as bits) are won by MTA m: its values blended into them (the edge
 * functions are set apart: lanes_gather in fine_core.h). */
inline void lanes_add(LaneWinners* L, const ShadeInputs* in, const PmrMta* m, sint take, uint bits, bool pbr) {
  L->act |= take;
  if (m->flags & PMR_MTA_BACK) L->back |= take;
  for (int k = 0; k < 3; ++k) {
    L->inv_w[k] = blend(L->inv_w[k], m->inv_w[k], take);
    L->bary[k][0] = blend(L->bary[k][0], m->bary[k][0], take);
    L->bary[k][1] = blend(L->bary[k][1], m->bary[k][1], take);
  }
  const PmrTriangle t = in->tris[m->tri];
  L->face = blend3(L->face, vload3(0, t.face_normal), take);
  if (t.has_normals) L->smooth |= take;
  global const PmrMaterial* mat = &in->materials[t.material];
  for (int k = 0; k < 3; ++k) {
    global const PmrVertexAttr* a = &in->attrs[t.v[k]];
    if (t.has_normals) L->n[k] = blend3(L->n[k], vload3(0, a->normal), take);
    L->c[k] = blend3(L->c[k], vload3(0, a->color), take);
    if (pbr) L->p[k] = blend3(L->p[k], vload3(t.v[k], in->positions), take);
  }
  L->factor = blend3(L->factor, vload3(0, mat->base_color), take);
  if (PMR_WITH_BLEND && (m->flags & PMR_MTA_BLEND)) {
    if (!any(L->blended))
      for (int k = 0; k < 4; ++k) L->alpha[k] = (sfloat)(1.0f);
    L->blended |= take;
    L->alpha[0] = blend(L->alpha[0], mat->base_color[3], take);
    for (int k = 0; k < 3; ++k) L->alpha[k + 1] = blend(L->alpha[k + 1], in->attrs[t.v[k]].color[3], take);
  }
  /* lambert reads the base colour map alone, pbr every map */
  bool textured = mat->maps[PMR_MAP_BASE_COLOR].texture >= 0;
  if (pbr) {
    L->metallic = blend(L->metallic, mat->metallic, take);
    L->roughness = blend(L->roughness, mat->roughness, take);
    L->f0d = blend(L->f0d, mat->f0_dielectric, take);
    L->emissive = blend3(L->emissive, vload3(0, mat->emissive), take);
    if (mat->unlit) L->unlit |= take;
    if (mat->transmission > 0.0f) lanes_add_transmission(L, in, mat, &t, take);
    if (mat->clearcoat > 0.0f) lanes_add_coat(L, mat, take);
    if (mat->flags & PMR_MATERIAL_SPECULAR) lanes_add_specular(L, mat, take);
    if (mat->flags & PMR_MATERIAL_ANISOTROPY) lanes_add_anisotropy(L, mat, take);
    if (mat->flags & PMR_MATERIAL_IRIDESCENCE) lanes_add_iridescence(L, mat, take);
    if (mat->flags & PMR_MATERIAL_SHEEN) lanes_add_sheen(L, mat, take);
    textured = (mat->flags & (PMR_MATERIAL_MAPS | PMR_MATERIAL_ANISOTROPY)) != 0;
  }
  if (textured) {
    L->textured |= bits;
    for (uint b = bits; b != 0u; b &= b - 1u) L->tri[31 - (int)clz(b & (0u - b))] = m->tri;
  }
}

/* The edge functions of lanes `take` along a row: E (exact, 64-bit, sign-corrected) at lane `first`
 * plus (l - first) step. Summed in doubles, exact below 2^53, so rounding to float rounds the exact
 * value, as for a lane evaluated on its own; beyond that, lane by lane in 64 bits. */
inline void lanes_step_edges(LaneWinners* L, sint take, int first, const long* E, const long* step) {
  const sint lane = vload_s(0, lane_index);
  sfloat e[3];
  for (int k = 0; k < 3; ++k) {
    const long far_end = (E[k] < 0 ? -E[k] : E[k]) + (long)SW * (step[k] < 0 ? -step[k] : step[k]);
    if (far_end < (1L << 53)) {
      e[k] = convert_float8((double8)((double)E[k]) + convert_double8(lane - first) * (double)step[k]);
    } else {
      float el[SW];
      for (int l = 0; l < SW; ++l) el[l] = (float)(E[k] + (long)(l - first) * step[k]);
      e[k] = vload_s(0, el);
    }
  }
  L->e = s3_select(L->e, s3(e[0], e[1], e[2]), take);
}

/* The lanes of vector `take` as bits. */
inline uint lane_bits(sint take) {
  const sint bits = select((sint)(0), (sint)(1) << vload_s(0, lane_index), take);
  const int4 b4 = bits.lo | bits.hi;
  const int2 b2 = b4.lo | b4.hi;
  return (uint)(b2.x | b2.y);
}

/* The exact sign-corrected edge functions of MTA m at raster point (X, Y) (16.16 / 24.8) of the view
 * with view coordinate i. */
inline void mta_edges_at(const PmrMta* m, long X, long Y, long i, long* E) {
  E[0] = (long)m->sign * mta_edge(m, 1, 2, X, Y, i);
  E[1] = (long)m->sign * mta_edge(m, 2, 0, X, Y, i);
  E[2] = (long)m->sign * mta_edge(m, 0, 1, X, Y, i);
}

/* Their change per pixel column. */
inline void mta_edge_steps(const PmrMta* m, long* step) {
  step[0] = (long)m->sign * (long)(m->y[2] - m->y[1]) * PMR_X_ONE;
  step[1] = (long)m->sign * (long)(m->y[0] - m->y[2]) * PMR_X_ONE;
  step[2] = (long)m->sign * (long)(m->y[1] - m->y[0]) * PMR_X_ONE;
}

/* The sign-corrected edge functions' derivatives in the view with view coordinate f, per output pixel:
 * one view pixel times PmrParams.lod_scale_x/y (the display pixel's footprint for subpixel sampling).
 * x: (y_b - y_a) per 16.16 unit; y: -(x_b - x_a) per 24.8 unit. */
inline void mta_edge_derivatives(global const PmrParams* P, const PmrMta* m, long f, float3* ex, float3* ey) {
  long step[3];
  mta_edge_steps(m, step);
  float dy[3];
  const int a[3] = {1, 2, 0}, b[3] = {2, 0, 1};
  for (int k = 0; k < 3; ++k) {
    const long xa = (long)m->x0[a[k]] + f * (long)m->dx[a[k]], xb = (long)m->x0[b[k]] + f * (long)m->dx[b[k]];
    dy[k] = (float)(-(long)m->sign * (xb - xa) * PMR_Y_ONE);
  }
  *ex = (float3)((float)step[0], (float)step[1], (float)step[2]) * P->lod_scale_x;
  *ey = (float3)(dy[0], dy[1], dy[2]) * P->lod_scale_y;
}

#if PMR_TRILINEAR
/* Trilinear filtering: lanes `bits`, won by MTA m in the view with view coordinate f, get its edge
 * functions' derivatives. */
inline void lanes_edge_derivatives(LaneWinners* L, global const PmrParams* P, const PmrMta* m, long f, uint bits) {
  float3 ex, ey;
  mta_edge_derivatives(P, m, f, &ex, &ey);
  for (uint b = bits; b != 0u; b &= b - 1u) {
    const int l = 31 - (int)clz(b & (0u - b));
    L->ex[0][l] = ex.x, L->ex[1][l] = ex.y, L->ex[2][l] = ex.z;
    L->ey[0][l] = ey.x, L->ey[1][l] = ey.y, L->ey[2][l] = ey.z;
  }
}
#endif

/* Barycentrics in the SOURCE triangle, perspective-correct, of every lane. */
inline sfloat3 lane_barycentrics(const LaneWinners* L) {
  const sfloat pa = L->e.x * L->inv_w[0], pb = L->e.y * L->inv_w[1], pc = L->e.z * L->inv_w[2];
  const sfloat inv = 1.0f / (pa + pb + pc);
  const sfloat la = pa * inv, lb = pb * inv, lc = pc * inv;
  const sfloat b1 = la * L->bary[0][0] + lb * L->bary[1][0] + lc * L->bary[2][0];
  const sfloat b2 = la * L->bary[0][1] + lb * L->bary[1][1] + lc * L->bary[2][1];
  return s3(1.0f - b1 - b2, b1, b2);
}

inline sfloat3 s3_interp_lanes(sfloat3 b, const sfloat3* a) {
  return s3_add(s3_add(s3_scale(a[0], b.x), s3_scale(a[1], b.y)), s3_scale(a[2], b.z));
}

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

/* The screen-space derivatives of SW lanes' source barycentrics, per output pixel in x and in y. */
typedef struct {
  sfloat3 dx, dy;
} LaneBaryGrad;

/* Perspective-correct barycentrics are l_k = p_k / S with p_k = e_k / w_k (e_k the edge functions,
 * linear in screen x and y) and S = sum p_k, so by the quotient rule dl_k = (dp_k - l_k dS) / S; the
 * source barycentrics (b1, b2) = sum_k l_k bary_k are linear in l. e: the edge functions at the sample;
 * ex, ey: their derivatives; iw: 1 / w; s1, s2: the vertices' source barycentrics b1 and b2 (component
 * k: MTA vertex k). */
inline LaneBaryGrad bary_gradient_lanes(sfloat3 e, sfloat3 ex, sfloat3 ey, sfloat3 iw, sfloat3 s1, sfloat3 s2) {
  const sfloat3 p = s3_mul(e, iw), px = s3_mul(ex, iw), py = s3_mul(ey, iw);
  const sfloat S = p.x + p.y + p.z;
  const sfloat3 l = s3(p.x / S, p.y / S, p.z / S);
  const sfloat sx = px.x + px.y + px.z, sy = py.x + py.y + py.z;
  const sfloat3 lx = s3((px.x - l.x * sx) / S, (px.y - l.y * sx) / S, (px.z - l.z * sx) / S);
  const sfloat3 ly = s3((py.x - l.x * sy) / S, (py.y - l.y * sy) / S, (py.z - l.z * sy) / S);
  const sfloat b1x = s3_dot(lx, s1), b2x = s3_dot(lx, s2), b1y = s3_dot(ly, s1), b2y = s3_dot(ly, s2);
  LaneBaryGrad g = {s3(-b1x - b2x, b1x, b2x), s3(-b1y - b2y, b1y, b2y)};
  return g;
}

#if PMR_TRILINEAR
/* Every lane's barycentric derivatives (idle lanes: finite values of no use). */
inline LaneBaryGrad lane_bary_gradient(const LaneWinners* L) {
  return bary_gradient_lanes(L->e, LANE3(L->ex), LANE3(L->ey), s3(L->inv_w[0], L->inv_w[1], L->inv_w[2]),
                             s3(L->bary[0][0], L->bary[1][0], L->bary[2][0]),
                             s3(L->bary[0][1], L->bary[1][1], L->bary[2][1]));
}
#endif

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

/* The split-sum table's bilinear lookup for every lane, as pmr::split_sum (host/shading/environment.cpp)
 * does it: the index arithmetic
 * in vectors, the four taps gathered lane by lane. */
inline void split_sum_lanes(global const float2* t, sfloat nv, sfloat r, sfloat* A, sfloat* B) {
  const int n = PMR_SPLIT_SUM_N;
  const sfloat x = sqrt(clamp(nv, 0.0f, 1.0f)) * (float)(n - 1), y = clamp(r, 0.0f, 1.0f) * (float)(n - 1);
  const sint x0 = min(convert_int8(x), n - 2), y0 = min(convert_int8(y), n - 2);
  const sfloat fx = x - convert_float8(x0), fy = y - convert_float8(y0);
  int at[SW];
  vstore_s(y0 * n + x0, 0, at);
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
    const sfloat top = a + (b - a) * fx, bottom = c + (d - c) * fx;
    const sfloat v = top + (bottom - top) * fy;
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
  const sint x0 = min(convert_int8(x), n - 2), y0 = min(convert_int8(y), n - 2);
  const sfloat fx = x - convert_float8(x0), fy = y - convert_float8(y0);
  int at[SW];
  vstore_s(y0 * n + x0, 0, at);
  float tap[4][SW];
  for (int l = 0; l < SW; ++l) {
    const float2 top = vload2(0, t + at[l]), bottom = vload2(0, t + at[l] + n);
    tap[0][l] = top.x, tap[1][l] = top.y, tap[2][l] = bottom.x, tap[3][l] = bottom.y;
  }
  const sfloat a = vload_s(0, tap[0]), b = vload_s(0, tap[1]), c = vload_s(0, tap[2]), d = vload_s(0, tap[3]);
  const sfloat top = a + (b - a) * fx, bottom = c + (d - c) * fx;
  return top + (bottom - top) * fy;
}

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

#include "transmission.h" /* reads the inputs and lanes above */

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

/* What the lobes read of each lane's surface, filled once per batch of lanes (pbr_surface): the one
 * place a material input is combined with its texture. */
typedef struct {
  sfloat3 p, v;    /* world position, unit direction toward the view's camera                      */
  sfloat3 n, base; /* unit shading normal (normal map applied, back faces flipped), base colour     */
  sfloat3 f0, emissive;
  sfloat f90;                     /* the Fresnel term's F0 and F90 (pbr_f0, pbr_f90)                          */
  sfloat metallic, r, ao;         /* r: the clamped, widened roughness                                        */
  sfloat transmission, thickness; /* glass lanes (0 elsewhere)                                        */
  sfloat coat, coat_r;            /* KHR_materials_clearcoat (coated lanes): intensity, roughness  */
  sfloat3 coat_n;                 /* ... the coat's unit normal (its own normal map, or the geometric one) */
  Anisotropy aniso;               /* KHR_materials_anisotropy (lanes aniso.on)                       */
  Iridescence irid;               /* KHR_materials_iridescence (w 0 in lanes without)                */
  Sheen sheen;                    /* KHR_materials_sheen (lanes sheen.on)                            */
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

/* KHR_materials_sheen's layer over the surface S (n and v set): colour and roughness times their maps,
 * and what every light and the environment read of it at the view (Lambda(n.v), E(n.v)). */
inline void surface_sheen(Surface* S, const ShadeInputs* in, const LaneWinners* L, const LaneTextures* T,
                          bool textured) {
  sfloat3 c = L->sheen_color;
  sfloat r = L->sheen_roughness;
  if (textured) c = s3_mul(c, LANE3(T->sheen_color)), r *= vload_s(0, T->sheen_roughness);
  const sfloat nv = clamp(s3_dot(S->n, S->v), PMR_SHEEN_MIN_COS, 1.0f);
  S->sheen.on = L->sheen;
  S->sheen.color = c;
  S->sheen.r = clamp(r, PMR_SHEEN_MIN_ROUGHNESS, 1.0f);
  S->sheen.m = fmax(fmax(c.x, c.y), c.z);
  S->sheen.lambda_v = sheen_lambda(nv, S->sheen.r * S->sheen.r);
  S->sheen.e_v = sheen_albedo_lanes(in->sheen_albedo, nv, S->sheen.r);
}

/* The surface of the lanes seen from view `view`: n and coat_n are unit normals, flipped for back faces;
 * spread and coat_spread the specular antialiasing increments of the two lobes. */
inline Surface pbr_surface(const ShadeInputs* in, const LaneWinners* L, const LaneTextures* T, bool textured, sfloat3 b,
                           sfloat3 n, sfloat3 coat_n, sfloat3 aniso_t, sfloat3 base, sfloat spread, sfloat coat_spread,
                           int view) {
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
  const sfloat3 to_eye = s3_sub(s3_splat(in->eyes[view + (int)in->P->view_base].xyz), S.p);
  S.v = s3_scale(to_eye, 1.0f / sqrt(s3_dot(to_eye, to_eye)));
  S.n = n, S.base = base, S.emissive = emissive;
  S.metallic = metallic, S.ao = ao, S.transmission = transmission, S.thickness = thickness;
  S.r = widened_roughness(pbr_roughness(roughness), spread);
  surface_fresnel(&S, L, T, textured);
  S.coat = coat, S.coat_n = coat_n;
  S.coat_r = coated ? widened_roughness(pbr_roughness(coat_roughness), coat_spread) : (sfloat)(1.0f);
  if (any(L->aniso)) surface_anisotropy(&S, L, T, aniso_t);
  if (any(L->irid)) surface_iridescence(&S, L, T, textured);
  if (any(L->sheen)) surface_sheen(&S, in, L, T, textured);
  return S;
}

/* KHR_materials_clearcoat's layering (its specification's fresnel_coat): the material's colour `under`
 * seen through a coat of intensity c and ior 1.5, mix(under, coat lobe, c Fc), Fc = 0.04 + 0.96
 * (1 - |coat_n . v|)^5; the coat lobe is `lights` (the GGX lobe about coat_n of roughness coat_r with no
 * Fresnel of its own, summed over the lights) plus ao (A + B) P(reflect(-v, coat_n), coat_r). Lanes
 * without a coat keep `under` bit for bit. */
inline sfloat3 coated_lanes(const ShadeInputs* in, const LaneWinners* L, const Surface* S, sfloat3 under,
                            sfloat3 lights) {
  const sfloat nv = s3_dot(S->coat_n, S->v);
  const sfloat k = 1.0f - fmin(fabs(nv), 1.0f), k2 = k * k;
  const sfloat w = S->coat * (0.04f + 0.96f * (k2 * k2 * k));
  sfloat A, B;
  split_sum_lanes(in->split_sum, nv, S->coat_r, &A, &B);
  const sint act = L->act & L->coated;
  const sfloat3 env = environment_along(in, s3_sub(s3_scale(S->coat_n, 2.0f * nv), S->v), S->coat_r, act);
  const sfloat3 coat = s3_add(lights, s3_scale(env, S->ao * (A + B)));
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
 * (sheen_view_scaled), plus the sheen's environment term ao c E(n.v) S(reflect(-v, n), r) (the
 * Charlie-prefiltered levels; the uniform default's radiance without an image). */
inline sfloat3 sheen_over_environment(const ShadeInputs* in, const LaneWinners* L, const Surface* S, sfloat3 under) {
  const Sheen* s = &S->sheen;
  sfloat3 light = s3_splat((float3)(in->P->env_radiance));
  if (in->env->level_count != 0) {
    sfloat u, v;
    environment_uv(in, s3_sub(s3_scale(S->n, 2.0f * s3_dot(S->n, S->v)), S->v), L->act, &u, &v);
    light = env_sheen(in->env, in->env_data, u, v, s->r);
  }
  return s3_add(sheen_view_scaled(s, under), s3_scale(s3_mul(s->color, light), S->ao * s->e_v));
}

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

/* glTF metallic-roughness of the lanes' surfaces S seen from view `view`'s camera: the sum over the
 * light table of f E n.l (the file's punctual lights, or the default light, or none), the environment
 * times the occlusion, plus the emissive term, under the sheen and then the clear coat where there are
 * ones; an unlit material is its base colour. */
inline sfloat3 shade_pbr(const ShadeInputs* in, const LaneWinners* L, const Surface* S, int view) {
  global const PmrParams* P = in->P;
  const bool glass = any(L->glass), coated = any(L->coated); /* their terms cost nothing to other lanes */
  const Anisotropy* aniso = any(L->aniso) ? &S->aniso : 0;
  const Iridescence* irid = any(L->irid) ? &S->irid : 0;
  const Sheen* sheen = any(L->sheen) ? &S->sheen : 0;
  const sfloat3 n = S->n, v = S->v, base = S->base, f0 = S->f0;
  const sfloat f90 = S->f90;
  const sfloat metallic = S->metallic, r = S->r, transmission = S->transmission;
  const sfloat coat_a2 = coated ? (S->coat_r * S->coat_r) * (S->coat_r * S->coat_r) : 0.0f;
  sfloat3 direct = s3_splat((float3)(0.0f)), lights_through = direct, coat_lights = direct;
  const uint num_lights = P->num_lights;
  for (uint i = 0; i < num_lights; ++i) {
    global const PmrLight* light = &in->lights[i];
    sfloat3 l;
    const sfloat3 E =
        light_irradiance((int)light->type, vload3(0, light->color), vload3(0, light->position),
                         vload3(0, light->direction), light->range, light->cos_inner, light->cos_outer, S->p, &l);
    sfloat3 f = glass ? brdf_cos_transmissive(base, metallic, f0, f90, r, n, v, l, transmission, aniso, irid)
                      : brdf_cos(base, metallic, f0, f90, r, n, v, l, aniso, irid);
    if (sheen) f = sheen_over_light(in, sheen, f, n, v, l);
    direct = s3_add(direct, s3_mul(f, E));
    if (glass) lights_through = s3_add(lights_through, s3_mul(btdf_light(f0, f90, r, L->ior, n, v, l), E));
    if (coated) coat_lights = s3_add(coat_lights, s3_scale(E, ggx_lobe_cos(S->coat_n, v, l, coat_a2)));
  }
  const sfloat nv = s3_dot(n, v);
  sfloat A, B;
  split_sum_lanes(in->split_sum, nv, r, &A, &B);
  sfloat3 irradiance, prefiltered;
  environment_lanes(in, n, reflected_direction(S, L, nv), metallic, r, L->act, &irradiance, &prefiltered);
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
    const sfloat3 through = transmitted_lanes(in, L, S->p, n, v, r, S->thickness, view, &attenuation);
    ambient = s3_add(ambient, s3_mul(btdf_weight(ao * w, R, base), through));
    sfloat3 lights_in = s3_mul(s3_scale(s3_mul(base, attenuation), w), lights_through);
    if (sheen) lights_in = sheen_view_scaled(sheen, lights_in);
    direct = s3_add(direct, lights_in);
  }
  sfloat3 lit = s3_add(s3_add(direct, ambient), S->emissive);
  if (sheen) /* the sheen between the view and the rest (the lights' layering is in f) */
    lit = s3_select(lit, s3_add(direct, sheen_over_environment(in, L, S, s3_add(ambient, S->emissive))), sheen->on);
  if (coated) lit = coated_lanes(in, L, S, lit, coat_lights);
  return s3_select(lit, base, L->unlit);
}

/* Base colours (RGB): baseColorFactor x COLOR_0 x the base colour texture. */
inline sfloat3 lane_base_color(const LaneWinners* L, const LaneTextures* T, bool textured, sfloat3 b) {
  const sfloat3 c = s3_mul(L->factor, s3_interp_lanes(b, L->c));
  return textured ? s3_mul(c, LANE3(T->base)) : c;
}

/* Colours are stored as halves, whose largest finite value is 65504: a brighter value (the peak of a
 * mirror-like highlight under a strong light) saturates there instead of becoming infinite. */
inline sfloat3 s3_half_range(sfloat3 c) {
  const sfloat m = (sfloat)(65504.0f);
  return s3(fmin(c.x, m), fmin(c.y, m), fmin(c.z, m));
}

/* The opacity of each lane: 1, or for alphaMode BLEND baseColorFactor alpha x COLOR_0 alpha x the base
 * colour texture's alpha, clamped to [0, 1] (the MASK test's alpha, mta_alpha_lanes). */
inline sfloat lane_alpha(const LaneWinners* L, const LaneTextures* T, bool textured, sfloat3 b) {
  if (!PMR_WITH_BLEND || !any(L->blended)) return (sfloat)(1.0f);
  sfloat a = L->alpha[0] * (b.x * L->alpha[1] + b.y * L->alpha[2] + b.z * L->alpha[3]);
  if (textured) a *= vload_s(0, T->base_alpha);
  return select((sfloat)(1.0f), clamp(a, 0.0f, 1.0f), L->blended);
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
    const Surface S = pbr_surface(in, L, &T, textured, b, n, coat_n, aniso_t, base, spread, coat_spread, view);
    return s3_half_range(s3_scale(shade_pbr(in, L, &S, view), exposure));
  }
  n = s3_select(n, s3_neg(n), L->back);
  const sfloat lambert = 0.2f + 0.8f * max(s3_dot(n, s3_splat(light)), 0.0f);
  return s3_half_range(s3(base.x * lambert * exposure, base.y * lambert * exposure, base.z * lambert * exposure));
}

/* alphaMode MASK: whether the base colour alpha of MTA m at raster points (X[j], Y[j]), j < n <= SW, of
 * view `view` passes the cutoff (pass[j]). Each point is one lane of the lanes' base colour (the factor,
 * COLOR_0 and the base colour map through sample_map_lanes; lanes are independent), so how the raster
 * batches its candidate voxels changes no outcome. Lanes from n on copy lane 0 (finite, unused). */
inline void mta_alpha_lanes(const ShadeInputs* in, const PmrMta* m, const long* X, const long* Y, int n, int view,
                            float cutoff, int* pass) {
  const long f = view_coord(in->P, view);
  const PmrTriangle t = in->tris[m->tri];
  global const PmrMaterial* mat = &in->materials[t.material];
  const float ca[3] = {in->attrs[t.v[0]].color[3], in->attrs[t.v[1]].color[3], in->attrs[t.v[2]].color[3]};
  float alpha[SW], b[3][SW], e[3][SW];
  uint tri[SW];
  for (int j = 0; j < SW; ++j) {
    tri[j] = m->tri;
    if (j >= n) { /* idle: a copy of lane 0, evaluated once */
      alpha[j] = alpha[0];
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
    alpha[j] = mat->base_color[3] * (b[0][j] * ca[0] + b[1][j] * ca[1] + b[2][j] * ca[2]);
    for (int i = 0; i < 3; ++i) e[i][j] = (float)ej[i];
  }
  if (mat->maps[PMR_MAP_BASE_COLOR].texture >= 0) {
    LaneBaryGrad g;
    const bool trilinear = PMR_USE_TRILINEAR(in->P);
    if (trilinear) {
      float3 ex, ey;
      mta_edge_derivatives(in->P, m, f, &ex, &ey);
      g = bary_gradient_lanes(LANE3(e), s3_splat(ex), s3_splat(ey),
                              s3_splat((float3)(m->inv_w[0], m->inv_w[1], m->inv_w[2])),
                              s3_splat((float3)(m->bary[0][0], m->bary[1][0], m->bary[2][0])),
                              s3_splat((float3)(m->bary[0][1], m->bary[1][1], m->bary[2][1])));
    }
    LaneTexcoords C;
    C.set = PMR_NO_KEY;
    sfloat c[4];
    sample_map_lanes(in, &mat->maps[PMR_MAP_BASE_COLOR], tri, (1u << n) - 1u, vload_s(0, lane_index) < (sint)(n),
                     LANE3(b), trilinear ? &g : 0, true, &C, c);
    float a[SW];
    vstore_s(c[3], 0, a);
    for (int j = 0; j < n; ++j) alpha[j] *= a[j];
  }
  for (int j = 0; j < n; ++j) pass[j] = alpha[j] >= cutoff;
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
