/* The lanes' winners (part of the one shading module, cl/shade.h): what shading reads of each lane's
 * winning MTA, its triangle, vertices and material, blended lane by lane into vectors; the lanes' edge
 * functions, perspective-correct barycentrics and their screen-space derivatives. Nothing here depends
 * on the view beyond the edge functions the caller hands in. */
#ifndef PMR_CL_LANE_WINNERS_H
#define PMR_CL_LANE_WINNERS_H

#include "shade_inputs.h"

/* SW winners to shade, one per lane (a row of 8 voxels of a real model holds a few small triangles):
 * what shading reads of each lane's MTA, triangle, vertices and material, as vectors. The caller fills
 * it one MTA at a time (lanes_add): each value is loaded once per MTA and blended into the lanes the
 * MTA won, in registers (a lane-by-lane gather through memory costs what the vector arithmetic saves). */
typedef struct {
  sint act;           /* -1: a winner to shade                                           */
  sint back;          /* -1: seen from behind                                            */
  sint smooth;        /* -1: vertex normals (else the face normal)                       */
  sint unlit;         /* pbr: KHR_materials_unlit                                        */
  sint catcher;       /* the ground catcher (--ground shadow): its alpha is the shadow on it */
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
  L->act = L->back = L->smooth = L->unlit = L->catcher = (sint)(0);
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
  if (mat->flags & PMR_MATERIAL_SHADOW_CATCHER) L->catcher |= take;
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

#endif
