/* Area lights (EXT_lights_area rect and disk; DESIGN section 4d), part of the one shading module
 * (cl/shade.h): what a Lambertian emitter of luminance L sends through the lobes, integrated over its
 * shape instead of taken from one direction.
 * - The diffuse lobe integrates the shape exactly: Lambert's formula over the polygon clipped to the
 *   surface's horizon gives the cosine-weighted solid angle, the integral of n.l dw.
 * - The GGX lobe is a pair of linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt 2016) fitted
 *   at build time to D Vis n.l and (1 - v.h)^5 D Vis n.l at (n.v, r) (host/shading/ltc.h): the polygon
 *   taken through each inverse matrix, its cosine integral times the lobe's integral over the
 *   hemisphere; F0 weights the first less the second, F90 the second. The clear coat: the first.
 * - The terms that take one direction (the Fresnel weight of the diffuse lobe, anisotropy, sheen,
 *   transmission) take the shape's vector irradiance: the direction of the integral of w dw over it,
 *   and the irradiance |that integral| L on a surface facing it (for a small light, a point at its
 *   centre of intensity L A cos).
 * A disk is the regular PMR_DISK_SIDES-gon of its area. Points behind the emitting side get nothing.
 * The lanes run together where the polygon lies above the horizon it is integrated over (the common
 * case: no clipping), and one at a time where it must be clipped. */
#ifndef PMR_CL_AREA_LIGHTS_H
#define PMR_CL_AREA_LIGHTS_H

#include "brdf.h"
#include "surface.h"

#define PMR_DISK_SIDES 16
/* the polygon clipped by one plane: a convex polygon gains at most one vertex */
#define PMR_AREA_MAX_VERTICES (PMR_DISK_SIDES + 1)

/* theta / sin(theta) for cos(theta) = x in (-1, 1]: at y = |x| the degree-6 polynomial (interpolated at
 * Chebyshev nodes of [0, 1], relative error below 3e-6) of acos(y) / sqrt(1 - y^2); for x < 0,
 * theta = pi - acos(y) gives pi / sin(theta) less it. The same expression for one lane and for SW. */
#define PMR_THETA_OVER_SIN(x, y, poly)                                                                                \
  ((poly) = 1.5707917f +                                                                                              \
            (y) * (-0.999542399f +                                                                                    \
                   (y) * (0.777722417f +                                                                              \
                          (y) * (-0.616057222f + (y) * (0.417915612f + (y) * (-0.192474865f + (y)*0.0416471676f))))), \
   select(PMR_PI_F * rsqrt(fmax(1.0f - (x) * (x), 1e-7f)) - (poly), (poly), (x) >= 0.0f))

/* theta n / sin(theta) for unit a, b, n = a x b, theta the angle between them: an edge's term of
 * Lambert's formula. */
inline float3 edge_term(float3 a, float3 b) {
  const float x = dot(a, b), y = fabs(x);
  float poly;
  return cross(a, b) * PMR_THETA_OVER_SIN(x, y, poly);
}

/* Twice the integral of max(w.n, 0) dw over the spherical polygon of the directions q[0, count) (one
 * lane; n unit): the polygon clipped to the half space w.n >= 0 (Sutherland-Hodgman), then Lambert's
 * formula, the sum over its edges of edge_term. */
inline float clipped_cosine_integral(const float3* q, int count, float3 n) {
  float3 c[PMR_AREA_MAX_VERTICES];
  int m = 0;
  for (int i = 0; i < count; ++i) {
    const float3 a = q[i], b = q[i + 1 == count ? 0 : i + 1];
    const float za = dot(a, n), zb = dot(b, n);
    if (za >= 0.0f) c[m++] = a;
    if ((za >= 0.0f) != (zb >= 0.0f)) c[m++] = a + (b - a) * (za / (za - zb));
  }
  if (m < 3) return 0.0f;
  float3 sum = (float3)(0.0f);
  for (int i = 0; i < m; ++i) sum += edge_term(normalize(c[i]), normalize(c[i + 1 == m ? 0 : i + 1]));
  return fabs(dot(sum, n));
}

/* The light's shape about the lanes' points p: its vertices minus p in q (the rect's 4; a disk's
 * PMR_DISK_SIDES on the circle of radius r sqrt(2 pi / (n sin(2 pi / n))), the polygon of the disk's
 * area; a distant light's vertices as they are, the same for every p), counted, and the lanes in front
 * of its emitting side (*front). */
inline int area_polygon_lanes(global const PmrLight* light, sfloat3 p, sfloat3* q, sint* front) {
  /* a distant light's shape lies at distance 1 toward `position` from every point alike */
  const sfloat3 at = s3_splat(vload3(0, light->position)), c = light->distant ? at : s3_sub(at, p);
  const float3 u = vload3(0, light->half_width), w = vload3(0, light->half_height);
  *front = s3_dot(c, s3_splat(vload3(0, light->direction))) < 0.0f;
  if (light->type == PMR_LIGHT_RECT) {
    q[0] = s3_add(c, s3_splat(-u - w)), q[1] = s3_add(c, s3_splat(u - w));
    q[2] = s3_add(c, s3_splat(u + w)), q[3] = s3_add(c, s3_splat(w - u));
    return 4;
  }
  const float k = 1.0130016f; /* sqrt(2 pi / (16 sin(pi / 8))) */
  const float step = 2.0f * PMR_PI_F / (float)PMR_DISK_SIDES;
  for (int i = 0; i < PMR_DISK_SIDES; ++i) {
    const float a = step * (float)i;
    q[i] = s3_add(c, s3_splat((k * cos(a)) * u + (k * sin(a)) * w));
  }
  return PMR_DISK_SIDES;
}

/* Twice the integral of w dw over the spherical polygon q[0, count) of each lane, unclipped: the sum
 * over its edges of edge_term, the vertices made unit once. */
inline sfloat3 edge_sum_lanes(const sfloat3* q, int count) {
  sfloat3 unit[PMR_DISK_SIDES];
  for (int i = 0; i < count; ++i) unit[i] = s3_scale(q[i], rsqrt(s3_dot(q[i], q[i])));
  sfloat3 sum = s3_splat((float3)(0.0f));
  for (int i = 0; i < count; ++i) {
    const sfloat3 a = unit[i], b = unit[i + 1 == count ? 0 : i + 1];
    const sfloat x = s3_dot(a, b), y = fabs(x);
    sfloat poly;
    sum = s3_add(sum, s3_scale(s3_cross(a, b), PMR_THETA_OVER_SIN(x, y, poly)));
  }
  return sum;
}

/* Twice the cosine integral about n of the lanes' polygons q[0, count) (unit n): |sum . n| from the
 * unclipped edge sum where every vertex is above the horizon, clipped lane by lane elsewhere. Lanes
 * outside `act`: 0. */
inline sfloat cosine_integral_lanes(const sfloat3* q, int count, sfloat3 n, sfloat3 sum, sint act) {
  sint below = (sint)(0);
  for (int i = 0; i < count; ++i) below |= s3_dot(q[i], n) < 0.0f;
  sfloat result = select((sfloat)(0.0f), fabs(s3_dot(sum, n)), act);
  below &= act;
  if (!any(below)) return result;
  float x[PMR_DISK_SIDES][SW], y[PMR_DISK_SIDES][SW], z[PMR_DISK_SIDES][SW], nx[SW], ny[SW], nz[SW], r[SW];
  int clip[SW];
  for (int i = 0; i < count; ++i) s3_store(q[i], x[i], y[i], z[i]);
  s3_store(n, nx, ny, nz), vstore_s(below, 0, clip), vstore_s(result, 0, r);
  for (int j = 0; j < SW; ++j) {
    if (!clip[j]) continue;
    float3 one[PMR_DISK_SIDES];
    for (int i = 0; i < count; ++i) one[i] = (float3)(x[i][j], y[i][j], z[i][j]);
    r[j] = clipped_cosine_integral(one, count, (float3)(nx[j], ny[j], nz[j]));
  }
  return vload_s(0, r);
}

/* The LTC fit at (n.v, r) (host/shading/ltc.h, fitted at build time): the inverse matrices of the lobe
 * D Vis n.l (m[0..3]) and of the Fresnel-weighted lobe (1 - v.h)^5 D Vis n.l (m[4..7]) as (m00, m02,
 * m20, m22) (m11 = 1, the rest 0) in the frame of n and v (x along v's tangent part), and their
 * integrals over the hemisphere (m[8], m[9]); bilinear between the PMR_LTC_N^2 nodes, node (i, j) at
 * PMR_LTC_NODE_FLOATS (j N + i) for n.v = 1 - (i / (N - 1))^2 and sqrt(r) = s0 + (1 - s0) j / (N - 1),
 * s0 = sqrt(0.03), clamped at the table's edges. */
inline void ltc_lookup(global const float* ltc, float nv, float r, float* m) {
  const float last = (float)(PMR_LTC_N - 1), s0 = 0.17320508f;
  const float x = clamp(sqrt(1.0f - clamp(nv, 0.0f, 1.0f)) * last, 0.0f, last);
  const float y = clamp((sqrt(r) - s0) / (1.0f - s0) * last, 0.0f, last);
  const int i = min((int)x, PMR_LTC_N - 2), j = min((int)y, PMR_LTC_N - 2);
  const float fx = x - (float)i, fy = y - (float)j;
  global const float* a = ltc + PMR_LTC_NODE_FLOATS * (j * PMR_LTC_N + i);
  global const float* b = a + PMR_LTC_NODE_FLOATS * PMR_LTC_N;
  for (int k = 0; k < PMR_LTC_NODE_FLOATS; ++k) {
    const float top = (1.0f - fx) * a[k] + fx * a[PMR_LTC_NODE_FLOATS + k];
    const float bottom = (1.0f - fx) * b[k] + fx * b[PMR_LTC_NODE_FLOATS + k];
    m[k] = (1.0f - fy) * top + fy * bottom;
  }
}

/* The share of each lane's LTC (inverse m[0..3], lane by lane) that its polygon q[0, count), given in
 * the frame (t1, t2, n), covers: the cosine integral about +z of its image through m, over pi. */
inline sfloat ltc_share_lanes(const sfloat* m, const sfloat3* q, int count, sint act) {
  sfloat3 image[PMR_DISK_SIDES];
  for (int i = 0; i < count; ++i) image[i] = s3(m[0] * q[i].x + m[1] * q[i].z, q[i].y, m[2] * q[i].x + m[3] * q[i].z);
  const sfloat3 z = s3_splat((float3)(0.0f, 0.0f, 1.0f));
  return cosine_integral_lanes(image, count, z, edge_sum_lanes(image, count), act) * (0.5f / PMR_PI_F);
}

/* The GGX lobe of (n, v, r) over the lanes' polygons q[0, count) (minus the point): *lobe the integral of
 * D Vis n.l over it, *schlick (unless 0) that of (1 - v.h)^5 D Vis n.l, each its LTC's share times the
 * lobe's integral over the hemisphere. Lanes outside `act`: 0. */
inline void ltc_lobe_lanes(global const float* ltc, const sfloat3* q, int count, sfloat3 n, sfloat3 v, sfloat r,
                           sint act, sfloat* lobe, sfloat* schlick) {
  const sfloat nv = s3_dot(n, v);
  float nvs[SW], rs[SW], table[PMR_LTC_NODE_FLOATS][SW];
  vstore_s(nv, 0, nvs), vstore_s(r, 0, rs);
  for (int j = 0; j < SW; ++j) {
    float m[PMR_LTC_NODE_FLOATS];
    ltc_lookup(ltc, nvs[j], rs[j], m);
    for (int k = 0; k < PMR_LTC_NODE_FLOATS; ++k) table[k][j] = m[k];
  }
  sfloat m[PMR_LTC_NODE_FLOATS];
  for (int k = 0; k < PMR_LTC_NODE_FLOATS; ++k) m[k] = vload_s(0, table[k]);
  /* x along v's part in the tangent plane (any tangent where v = n) */
  const sfloat3 t = s3_sub(v, s3_scale(n, nv));
  const sfloat len = sqrt(s3_dot(t, t));
  const sfloat3 other =
      s3_select(s3_splat((float3)(1.0f, 0.0f, 0.0f)), s3_splat((float3)(0.0f, 1.0f, 0.0f)), fabs(n.x) >= 0.9f);
  const sfloat3 side = s3_cross(n, other);
  const sfloat3 t1 = s3_select(s3_scale(side, rsqrt(s3_dot(side, side))), s3_scale(t, 1.0f / len), len > 1e-6f);
  const sfloat3 t2 = s3_cross(n, t1);
  sfloat3 frame[PMR_DISK_SIDES];
  for (int i = 0; i < count; ++i) frame[i] = s3(s3_dot(q[i], t1), s3_dot(q[i], t2), s3_dot(q[i], n));
  *lobe = m[8] * ltc_share_lanes(m, frame, count, act);
  if (schlick) *schlick = m[9] * ltc_share_lanes(m + 4, frame, count, act);
}

/* What an area light sends to the lanes' points, per unit luminance (area_light_lanes). */
typedef struct {
  sfloat3 l;            /* the direction of the shape's vector irradiance (0: nothing arrives) */
  sfloat e;             /* |that vector|: the irradiance on a surface facing l                */
  sfloat cosine;        /* the cosine-weighted solid angle over n's horizon (the diffuse lobe) */
  sfloat lobe, schlick; /* the GGX lobe's D Vis n.l and (1 - v.h)^5 D Vis n.l over the shape  */
  sfloat coat;          /* the clear coat's D Vis n.l over the shape                         */
} AreaLanes;

/* Light `light` at the lanes' points p of shading normals n seen from v, roughness r, and in the
 * `coated` lanes the clear coat's normal and roughness; lanes outside `act` get nothing. */
inline AreaLanes area_light_lanes(global const float* ltc, global const PmrLight* light, sfloat3 p, sfloat3 n,
                                  sfloat3 v, sfloat r, sfloat3 coat_n, sfloat coat_r, sint act, sint coated) {
  const sfloat zero = 0.0f;
  AreaLanes A = {s3_splat((float3)(0.0f)), zero, zero, zero, zero, zero};
  sfloat3 q[PMR_DISK_SIDES];
  sint front;
  const int count = area_polygon_lanes(light, p, q, &front);
  if (!any(front & act)) return A;
  const sfloat3 sum = edge_sum_lanes(q, count);
  const sfloat len = sqrt(s3_dot(sum, sum));
  const sint lit = front & act & (len > 0.0f);
  const sfloat toward = select((sfloat)(1.0f), (sfloat)(-1.0f), s3_dot(sum, q[0]) < 0.0f);
  A.l = s3_select(A.l, s3_scale(sum, toward / len), lit), A.e = select(zero, 0.5f * len, lit);
  A.cosine = 0.5f * cosine_integral_lanes(q, count, n, sum, lit);
  const sint seen = lit & (s3_dot(n, v) > 0.0f);
  if (any(seen)) ltc_lobe_lanes(ltc, q, count, n, v, r, seen, &A.lobe, &A.schlick);
  const sint coat_seen = lit & coated & (s3_dot(coat_n, v) > 0.0f);
  if (any(coat_seen)) ltc_lobe_lanes(ltc, q, count, coat_n, v, coat_r, coat_seen, &A.coat, 0);
  return A;
}

/* The lobes over the area light A per unit irradiance A.e (so that times E = colour x L x A.e they give
 * the radiance): the diffuse lobe's (1 - F) c_diff / pi over the shape's cosine integral, F at the
 * vector irradiance's direction (the thin film's F mixed in as brdf_cos does), plus the GGX lobe
 * F0 (lobe - schlick) + F90 schlick (with a thin film: mixed toward F_film lobe). `transmission` as
 * brdf_cos_transmissive takes it. 0 where nothing arrives. */
inline sfloat3 area_brdf(const Surface* S, const AreaLanes* A, sfloat transmission, const Iridescence* irid) {
  const sfloat3 hv = s3_add(A->l, S->v);
  const sfloat hl = sqrt(s3_dot(hv, hv));
  const sfloat3 h = s3_select(S->n, s3_scale(hv, 1.0f / hl), hl > 0.0f);
  const sfloat vh = clamp(s3_dot(S->v, h), 0.0f, 1.0f);
  sfloat3 F = fresnel_schlick(S->f0, S->f90, vh);
  if (irid) F = s3_add(F, s3_scale(s3_sub(irid->F, F), irid->w));
  const sfloat kd = (1.0f - S->metallic) * (1.0f - transmission) * (1.0f / PMR_PI_F) * A->cosine;
  const sfloat plain = A->lobe - A->schlick, schlick = A->schlick;
  sfloat3 G =
      s3(S->f0.x * plain + S->f90 * schlick, S->f0.y * plain + S->f90 * schlick, S->f0.z * plain + S->f90 * schlick);
  if (irid) G = s3_add(G, s3_scale(s3_sub(s3_scale(irid->F, A->lobe), G), irid->w));
  const sfloat3 f =
      s3((1.0f - F.x) * S->base.x * kd + G.x, (1.0f - F.y) * S->base.y * kd + G.y, (1.0f - F.z) * S->base.z * kd + G.z);
  return s3_scale(f, select((sfloat)(0.0f), 1.0f / A->e, A->e > 0.0f));
}

#endif
