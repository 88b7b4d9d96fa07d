/* Stage 2, primitive setup: one work-item per triangle. Culls conservatively against the union of the
 * N frusta, clips ONCE for all views (near, far and the guard band; all are linear in view space, so a
 * clipped vertex keeps an affine disparity), splits the view range by orientation (twice the signed
 * area is affine in the view coordinate, which grows with the view index, so it flips at most once), and appends one MTA per (fan triangle,
 * orientation) to the global MTA queue. A full queue is counted, not written: the host compares the
 * counter with the capacity, grows the queue and runs the frame again. */
#include "common.h"

#define CULL_BITS (PMR_CULL_LEFT | PMR_CULL_RIGHT | PMR_CULL_BOTTOM | PMR_CULL_TOP | PMR_CULL_NEAR | PMR_CULL_FAR)
#define CLIP_BITS (PMR_CLIP_NEAR | PMR_CLIP_FAR | PMR_CLIP_GUARD)

/* The first view whose view coordinate is at least f (n if none): the coordinates increase with the
 * view index. */
inline int first_view_from(global const PmrParams* P, long f) {
  int lo = 0, hi = P->views; /* the answer lies in [lo, hi] */
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (view_coord(P, mid) >= f) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

/* Views v with a0 + F_v a1 > 0 (F_v the view coordinate), as [*lo, *hi] (empty when *lo > *hi): the
 * coordinates where the affine function is positive form one interval, and so do its views. */
inline void positive_views(global const PmrParams* P, long a0, long a1, int* lo, int* hi) {
  const int n = P->views;
  *lo = 0;
  *hi = n - 1;
  if (a1 == 0) {
    if (a0 <= 0) *lo = n;
  } else if (a1 > 0) {
    *lo = first_view_from(P, floor_div_l(-a0, a1) + 1);
  } else {
    const long b = -a1;                         /* a0 - f b > 0  <=>  f < a0 / b */
    const long last = -floor_div_l(-a0, b) - 1; /* ceil(a0 / b) - 1 */
    *hi = first_view_from(P, last + 1) - 1;
  }
}

inline void emit_mta(global const PmrParams* P, global PmrMta* mtas, volatile global uint* counter, PmrMta* m, int lo,
                     int hi, int sign, uint flags) {
  if (lo > hi) return;
  m->sign = sign;
  m->flags = flags;
  if (P->setup_mode == PMR_SETUP_DUPLICATE) {
    /* baseline: the triangle duplicated once per view, each copy rasterized in its own view only */
    for (int v = lo; v <= hi; ++v) {
      m->view_lo = m->view_hi = v;
      const uint slot = atomic_inc(counter);
      if (slot < P->mta_capacity) mtas[slot] = *m;
    }
    return;
  }
  m->view_lo = lo;
  m->view_hi = hi;
  const uint slot = atomic_inc(counter);
  if (slot < P->mta_capacity) mtas[slot] = *m;
}

/* Whether a sample at offset c from its pixel's corner (fixed point, `one` a pixel) lies in [lo, hi]
 * for some pixel p in [0, n): the first p whose sample is at least lo decides. */
inline bool sample_in_range(long lo, long hi, long c, long one, int n) {
  const long p = max(0L, -floor_div_l(c - lo, one)); /* ceil((lo - c) / one) */
  return p < (long)n && p * one + c <= hi;
}

/* The samples s (bit s) whose rows cross the MTA's y extent, the same in every view. */
inline uint sample_rows_crossed(global const PmrParams* P, const PmrMta* m) {
  const long ylo = min3l(m->y[0], m->y[1], m->y[2]), yhi = max3l(m->y[0], m->y[1], m->y[2]);
  uint rows = 0u;
  for (uint s = 0; s < P->samples; ++s)
    if (sample_in_range(ylo, yhi, PMR_HALF_Y + P->sample_y[s], PMR_Y_ONE, P->view_h)) rows |= 1u << s;
  return rows;
}

/* Whether view v's x extent holds the column of a sample among `rows`. */
inline bool view_may_hold_sample(global const PmrParams* P, const PmrMta* m, int v, uint rows) {
  long lo, hi;
  mta_x_extent(m, view_coord(P, v), &lo, &hi);
  for (uint s = 0; s < P->samples; ++s)
    if (((rows >> s) & 1u) && sample_in_range(lo, hi, PMR_HALF_X + P->sample_x[s], PMR_X_ONE, P->view_w)) return true;
  return false;
}

/* Trims the views [*lo, *hi] at both ends to those whose box around the MTA holds a sample position
 * (around pixel centers: --sampling view; a subpixel's samples lie anywhere in its pixel, so those
 * ranges are kept). A view without one cannot be covered, so no image changes; a micro-triangle
 * between the sample rows, or between the columns in every view, makes no MTA at all. */
inline void trim_to_samples(global const PmrParams* P, const PmrMta* m, int* lo, int* hi) {
  if (P->sample_area != PMR_SAMPLES_CENTER || *lo > *hi) return;
  const uint rows = sample_rows_crossed(P, m);
  if (rows == 0u) {
    *lo = *hi + 1;
    return;
  }
  while (*lo <= *hi && !view_may_hold_sample(P, m, *lo, rows)) ++*lo;
  while (*hi > *lo && !view_may_hold_sample(P, m, *hi, rows)) --*hi;
}

/* One (possibly clipped) triangle: its orientation ranges become MTAs. */
inline void emit_triangle(global const PmrParams* P, global PmrMta* mtas, volatile global uint* counter,
                          const PmrVertex* a, const PmrVertex* b, const PmrVertex* c, const double* bary_a,
                          const double* bary_b, const double* bary_c, uint tri, uint sub, uint double_sided,
                          uint mflag) {
  PmrMta m;
  const PmrVertex* v[3] = {a, b, c};
  const double* bary[3] = {bary_a, bary_b, bary_c};
  for (int k = 0; k < 3; ++k) {
    m.x0[k] = v[k]->x0;
    m.dx[k] = v[k]->dx;
    m.y[k] = v[k]->y;
    m.z[k] = v[k]->z;
    m.inv_w[k] = v[k]->inv_w;
    m.bary[k][0] = (float)bary[k][0];
    m.bary[k][1] = (float)bary[k][1];
  }
  m.tri = tri;
  m.key = (tri << PMR_KEY_SUB_BITS) | sub;
  /* Twice the signed area at view coordinate f, A(f) = E_ab(c) = a0 + f a1; A > 0 is counter-clockwise
   * in NDC (raster y points down), i.e. front-facing. */
  const long ya = m.y[0], yb = m.y[1], yc = m.y[2];
  const long a0 = (yb - ya) * ((long)m.x0[2] - m.x0[0]) - ((long)m.x0[1] - m.x0[0]) * (yc - ya);
  const long a1 = (yb - ya) * ((long)m.dx[2] - m.dx[0]) - ((long)m.dx[1] - m.dx[0]) * (yc - ya);
  int lo, hi;
  positive_views(P, a0, a1, &lo, &hi);
  trim_to_samples(P, &m, &lo, &hi);
  emit_mta(P, mtas, counter, &m, lo, hi, 1, mflag);
  if (double_sided) {
    positive_views(P, -a0, -a1, &lo, &hi);
    trim_to_samples(P, &m, &lo, &hi);
    emit_mta(P, mtas, counter, &m, lo, hi, -1, mflag | PMR_MTA_BACK);
  }
}

/* Signed distance-like value of a view-space point to clip plane `k` (>= 0 inside). */
inline double plane_value(global const PmrParams* P, int k, const double* p) {
  const double w = -p[2];
  const double kk = P->disparity_k / (double)P->view_w;
  const double xc = P->ndc_scale_x * p[0] + P->ndc_offset_x * w;
  switch (k) {
    case 0:
      return w - P->near_eff;
    case 1:
      return P->far - w;
    case 2:
      return P->guard_ndc_x * w - (xc - kk * (w - P->focal));
    case 3:
      return P->guard_ndc_x * w + (xc - kk * (w - P->focal));
    case 4:
      return P->guard_ndc_x * w - (xc + kk * (w - P->focal));
    case 5:
      return P->guard_ndc_x * w + (xc + kk * (w - P->focal));
    case 6:
      return P->guard_ndc_y * w - P->ndc_scale_y * p[1];
    default:
      return P->guard_ndc_y * w + P->ndc_scale_y * p[1];
  }
}

/* True if point p sorts before q; clipping computes an edge's intersection from its first point, so
 * both triangles sharing the edge create bit-identical vertices. */
inline bool point_before(const double* p, const double* q) {
  if (p[0] != q[0]) return p[0] < q[0];
  if (p[1] != q[1]) return p[1] < q[1];
  return p[2] < q[2];
}

typedef struct {
  double p[3]; /* view space */
  double b[2]; /* barycentrics (b1, b2) in the source triangle */
  int src;     /* 0..2: an original vertex, -1: created by clipping */
} ClipVertex;

kernel void setup_triangles(global const PmrParams* P, global const PmrTriangle* tris, global const PmrVertex* verts,
                            global const PmrMaterial* materials, global PmrMta* mtas, volatile global uint* counter) {
  const uint t = pmr_item_id();
  if (t >= P->num_triangles) return;
  const PmrTriangle tri = tris[t];
  PmrVertex v[3] = {verts[tri.v[0]], verts[tri.v[1]], verts[tri.v[2]]};
  const uint oc_and = v[0].outcode & v[1].outcode & v[2].outcode;
  const uint oc_or = v[0].outcode | v[1].outcode | v[2].outcode;
  if (oc_and & CULL_BITS) return;
  const PmrMaterial mat = materials[tri.material];
  /* the material's MTA flags: alphaMode MASK; pbr transmission (left out of the opaque pass); alphaMode
   * BLEND, which a transmissive material leaves to its transmission (scene_blended, scene.cpp) */
  const uint ds = mat.double_sided;
  const bool glass = P->shading == PMR_SHADING_PBR && mat.transmission > 0.0f;
  const uint mflag = (mat.alpha_mode == PMR_ALPHA_MASK ? PMR_MTA_MASK : 0u) | (glass ? PMR_MTA_TRANSMISSIVE : 0u) |
                     (mat.alpha_mode == PMR_ALPHA_BLEND && !glass ? PMR_MTA_BLEND : 0u);
  const double ident[3][2] = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};

  if (!(oc_or & CLIP_BITS)) {
    emit_triangle(P, mtas, counter, &v[0], &v[1], &v[2], ident[0], ident[1], ident[2], t, 0, ds, mflag);
    return;
  }

  /* Sutherland-Hodgman against the planes some vertex is outside of. */
  ClipVertex poly[2][PMR_MAX_CLIP_VERTS];
  int n = 3, cur = 0;
  for (int k = 0; k < 3; ++k) {
    for (int c = 0; c < 3; ++c) poly[0][k].p[c] = v[k].pos_view[c];
    poly[0][k].b[0] = ident[k][0];
    poly[0][k].b[1] = ident[k][1];
    poly[0][k].src = k;
  }
  for (int plane = 0; plane < 8 && n >= 3; ++plane) {
    if (!(oc_or & (1u << plane))) continue;
    int m = 0;
    for (int k = 0; k < n; ++k) {
      const ClipVertex* A = &poly[cur][k];
      const ClipVertex* B = &poly[cur][(k + 1) % n];
      const double fa = plane_value(P, plane, A->p), fb = plane_value(P, plane, B->p);
      if (fa >= 0.0) poly[1 - cur][m++] = *A;
      if ((fa >= 0.0) != (fb >= 0.0)) {
        const bool a_first = point_before(A->p, B->p);
        const ClipVertex* F = a_first ? A : B;
        const ClipVertex* S = a_first ? B : A;
        const double ff = a_first ? fa : fb, fs = a_first ? fb : fa;
        const double s = ff / (ff - fs);
        ClipVertex* o = &poly[1 - cur][m++];
        for (int c = 0; c < 3; ++c) o->p[c] = F->p[c] + s * (S->p[c] - F->p[c]);
        for (int c = 0; c < 2; ++c) o->b[c] = F->b[c] + s * (S->b[c] - F->b[c]);
        o->src = -1;
      }
    }
    n = m;
    cur = 1 - cur;
  }
  if (n < 3) return;

  PmrVertex pv[PMR_MAX_CLIP_VERTS];
  for (int k = 0; k < n; ++k) {
    const ClipVertex* c = &poly[cur][k];
    if (c->src >= 0) pv[k] = v[c->src];
    else project_vertex(P, c->p[0], c->p[1], c->p[2], &pv[k]);
  }
  for (int k = 1; k + 1 < n; ++k)
    emit_triangle(P, mtas, counter, &pv[0], &pv[k], &pv[k + 1], poly[cur][0].b, poly[cur][k].b, poly[cur][k + 1].b, t,
                  (uint)(k - 1), ds, mflag);
}
