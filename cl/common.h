/* Device helpers shared by the stage kernels: fixed-point snapping and the exact multi-view edge
 * functions (DESIGN sections 2 and 3). Every stage includes this; it includes the host/kernel
 * shared structs. */
#ifndef PMR_CL_COMMON_H
#define PMR_CL_COMMON_H

#include "pmr/shared.h"

/* The C++ references round exactly like this code only if no multiply-add is fused. A function defined
 * before this line would be contracted: every header includes common.h (or lanes.h) first. */
#pragma OPENCL FP_CONTRACT OFF
#pragma OPENCL EXTENSION cl_khr_fp64 : enable

/* The kernels are built for one filter (-DPMR_TRILINEAR, the host's --texture-filter), as for one
 * sample count: built with 0 they carry no per-lane derivatives and no level-of-detail code, so
 * bilinear filtering costs what it did before mips. A build without the define serves both filters,
 * chosen by PmrParams.texture_filter (cl/texture.h). Defined here, before any header tests it. */
#ifndef PMR_TRILINEAR
#define PMR_TRILINEAR 1
#endif

/* This work-item's item in a launch over N items (ClRuntime::launch). The host folds long launches
 * into rows of fewer than 65535 work-items, so no grid dimension reaches PoCL's "small grid" limit and
 * PoCL compiles exactly one work-group function per (kernel, local size). */
inline uint pmr_item_id(void) { return (uint)(get_global_id(1) * get_global_size(0) + get_global_id(0)); }

/* For a helper that runs in a kernel's per-voxel, per-sample or per-MTA loop: PoCL's inliner leaves large
 * functions out of line even when they have one caller, and a call there costs its arguments' trips
 * through memory (structs and arrays cannot stay in registers across it). */
#define PMR_HOT inline __attribute__((always_inline))

#define PMR_HALF_X (PMR_X_ONE / 2)
#define PMR_HALF_Y (PMR_Y_ONE / 2)

inline long floor_div_l(long a, long b) { /* b > 0 */
  long q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

/* Outcodes and snapped raster data of a point given in center-camera view space. Every vertex of
 * the scene goes through this exactly once (vertex stage), and every vertex created by clipping goes
 * through it too (setup stage), so a vertex's snapped position in view i depends on its data and i
 * alone. */
inline void project_vertex(global const PmrParams* P, double xv, double yv, double zv, PmrVertex* out) {
  const double w = -zv;
  const double kk = P->disparity_k / (double)P->view_w;        /* NDC disparity per unit (1 - D/w) / 2 */
  const double xc = P->ndc_scale_x * xv + P->ndc_offset_x * w; /* x_ndc(center) * w */
  const double xfirst = xc - kk * (w - P->focal);              /* x_ndc(view 0) * w */
  const double xlast = xc + kk * (w - P->focal);               /* x_ndc(view N-1) * w */
  const double yc = P->ndc_scale_y * yv;                       /* y_ndc * w */
  const double gx = P->guard_ndc_x * w, gy = P->guard_ndc_y * w;
  uint oc = 0;
  if (w < P->near_eff) oc |= PMR_CLIP_NEAR | PMR_CULL_NEAR;
  if (w > P->far) oc |= PMR_CLIP_FAR | PMR_CULL_FAR;
  if (xfirst > gx) oc |= 1u << 2;
  if (xfirst < -gx) oc |= 1u << 3;
  if (xlast > gx) oc |= 1u << 4;
  if (xlast < -gx) oc |= 1u << 5;
  if (yc > gy) oc |= 1u << 6;
  if (yc < -gy) oc |= 1u << 7;
  if (xfirst < -w && xlast < -w) oc |= PMR_CULL_LEFT;
  if (xfirst > w && xlast > w) oc |= PMR_CULL_RIGHT;
  if (yc < -w) oc |= PMR_CULL_BOTTOM;
  if (yc > w) oc |= PMR_CULL_TOP;
  out->pos_view[0] = xv;
  out->pos_view[1] = yv;
  out->pos_view[2] = zv;
  out->pad = 0.0;
  out->outcode = oc;
  out->x0 = 0;
  out->dx = 0;
  out->y = 0;
  out->z = 0.0f;
  out->inv_w = 0.0f;
  /* Vertices outside the guard band are clipped before their snapped data is used; vertices created
   * by clipping lie on a plane up to rounding, so snapping must not depend on the outcode. The clamp
   * only keeps the conversion defined for far-away vertices whose data is never used. */
  if (!(w > 0.0)) return;
  const double half_w = 0.5 * (double)P->view_w, half_h = 0.5 * (double)P->view_h;
  const double x_center = (xc / w + 1.0) * half_w;
  double x_first = x_center, d = 0.0;
  if (P->views > 1) {
    /* x at view coordinate 0 (view 0 if linear: anchor -1/2; the center camera if angular: anchor 0)
     * and the disparity per view coordinate unit */
    const double delta = P->disparity_k * (1.0 - P->focal / w); /* Delta(w), px */
    x_first = x_center + P->view_anchor * delta;
    d = delta / P->view_scale;
  }
  const double y = (1.0 - yc / w) * half_h;
  out->x0 = (int)clamp(floor(x_first * (double)PMR_X_ONE + 0.5), -2.0e9, 2.0e9);
  out->dx = (int)clamp(floor(d * (double)PMR_X_ONE + 0.5), -2.0e9, 2.0e9);
  out->y = (int)clamp(floor(y * (double)PMR_Y_ONE + 0.5), -2.0e9, 2.0e9);
  out->z = (float)(P->far * (w - P->near_eff) / ((P->far - P->near_eff) * w));
  out->inv_w = (float)(1.0 / w);
}

/* The view coordinate F_i of view i (pmr/shared.h): x_i = x0 + F_i dx. F_i = i with linear spacing. */
inline long view_coord(global const PmrParams* P, int i) { return (long)P->view_coord[i]; }

inline long min3l(long a, long b, long c) { return min(a, min(b, c)); }
inline long max3l(long a, long b, long c) { return max(a, max(b, c)); }

/* The MTA's x extent [lo, hi] in the view with view coordinate f. */
inline void mta_x_extent(const PmrMta* m, long f, long* lo, long* hi) {
  const long xa = (long)m->x0[0] + f * m->dx[0], xb = (long)m->x0[1] + f * m->dx[1];
  const long xc = (long)m->x0[2] + f * m->dx[2];
  *lo = min3l(xa, xb, xc);
  *hi = max3l(xa, xb, xc);
}

/* The view coordinates of views ib .. ib + 15 relative to view ib's, lanes from `count` on clamped to
 * the span of the first `count` (the table has slack past the last view, so the load stays inside). */
inline int16 view_coord_lanes(global const PmrParams* P, int ib, int count, long* span) {
  const int16 f = vload16(0, P->view_coord + ib) - (int16)(P->view_coord[ib]);
  *span = (long)P->view_coord[ib + count - 1] - (long)P->view_coord[ib];
  return min(f, (int16)((int)*span)); /* lanes past `count` never exceed the span */
}

/* Lane l holds l: the lane numbers of a vector of up to 16 lanes (vload from here). */
constant int lane_index[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};

/* Bit l set where lane l of `mask` is true (a comparison's -1). */
inline uint mask_bits16(int16 mask) {
  const int16 bits = select((int16)(0), (int16)(1) << vload16(0, lane_index), mask);
  const int8 a = bits.lo | bits.hi;
  const int4 b = a.lo | a.hi;
  const int2 c = b.lo | b.hi;
  return (uint)(c.x | c.y);
}

/* Each vertex's raster x relative to X0 in views ib + l (l < 16; lanes from `count` on repeat the last
 * view's, view_coord_lanes), exact in 32 bits, when that provably fits: base, disparity over the views
 * and their sum each below 2^29 in magnitude. Else false (the caller falls back to 64-bit work). */
inline bool view_x_lanes(global const PmrParams* P, const PmrMta* m, int ib, int count, long X0, int16* x) {
  long span;
  const int16 l = view_coord_lanes(P, ib, count, &span);
  const long fib = view_coord(P, ib);
  for (int k = 0; k < 3; ++k) {
    const long base = (long)m->x0[k] + fib * m->dx[k] - X0;
    if (base <= -(1L << 29) || base >= (1L << 29) || (long)abs(m->dx[k]) * span >= (1L << 29)) return false;
    x[k] = (int16)((int)base) + l * m->dx[k];
  }
  return true;
}

/* Edge function of edge (a -> b) of an MTA at raster point (X, Y) (16.16 / 24.8) in the view with view
 * coordinate f:
 *   E = (yb - ya) (X - xa(f)) - (xb(f) - xa(f)) (Y - ya),   xa(f) = x0a + f * dxa.
 * Units are 2^-24 px^2. Multilinear in (X, Y, f); the view coordinate grows with the view index, so
 * over a range of views E's extremes are at the range's end views. */
inline long mta_edge(const PmrMta* m, int a, int b, long X, long Y, long f) {
  const long xa = (long)m->x0[a] + f * (long)m->dx[a];
  const long xb = (long)m->x0[b] + f * (long)m->dx[b];
  return (long)(m->y[b] - m->y[a]) * (X - xa) - (xb - xa) * (Y - (long)m->y[a]);
}

/* Top-left fill rule. With the edge functions multiplied by m->sign the inside is >= 0; an edge owns
 * the pixel centers lying exactly on it only if it is a top or a left edge, so the test is
 * sign * E >= bias with bias 0 for top/left edges and 1 otherwise. Within one MTA the orientation is
 * constant, so the classification (evaluated at view_lo, view coordinate f_lo) holds for all its views. */
inline long mta_edge_bias(const PmrMta* m, int a, int b, long f_lo) {
  const long dy = (long)(m->y[b] - m->y[a]) * m->sign;
  const long i = f_lo;
  const long dx = ((long)m->x0[b] + i * (long)m->dx[b] - (long)m->x0[a] - i * (long)m->dx[a]) * m->sign;
  /* inside is where sign*E >= 0, i.e. the interior normal is (dy, -dx): a left edge has dy > 0,
   * a top edge (raster y grows downwards) is horizontal with dx < 0. */
  return (dy > 0 || (dy == 0 && dx < 0)) ? 0 : 1;
}

/* Depth plane of an MTA in view i (given by its view coordinate). Depth is linear in screen space (DESIGN
 * section 3). One formula serves every sample, pixel center or not: the plane is anchored at the center
 * (Xr, Yr) of vertex 0's pixel (pr, qr), and at raster point (X, Y) (16.16 / 24.8)
 *   depth(X, Y) = (float)(zr + gy * (double)(Y - Yr) / Y_ONE) + gx * ((float)(X - Xr) / X_ONE)
 * At pixel centers (Y - Yr) / Y_ONE and (X - Xr) / X_ONE are the integers py - qr and
 * px - pr, so a row of voxels costs one float multiply-add per voxel after one double evaluation per row
 * (the fine raster's form, bit for bit the same value). The value depends on the MTA, the view and the
 * sample alone (never on the tile or chunk that computes it). The gradients come from the exact
 * integer vertex positions of view i (twice the signed area A is non-zero in every view of an MTA). The
 * C++ reference (tests/reference) evaluates the same expression in the same order. */
typedef struct {
  double zr;  /* depth at the center of pixel (pr, qr) */
  double gy;  /* depth per pixel row */
  float gx;   /* depth per pixel column */
  int pr, qr; /* vertex 0's pixel */
} DepthPlane;

inline DepthPlane depth_plane(const PmrMta* m, long i) { /* i: the view's view coordinate */
  const long x0 = (long)m->x0[0] + (long)i * m->dx[0];
  const long x1 = (long)m->x0[1] + (long)i * m->dx[1];
  const long x2 = (long)m->x0[2] + (long)i * m->dx[2];
  const long y0 = m->y[0], y1 = m->y[1], y2 = m->y[2];
  const long area = (y1 - y0) * (x2 - x0) - (x1 - x0) * (y2 - y0);
  const double inv = 1.0 / (double)area;
  const double dz1 = (double)m->z[1] - (double)m->z[0], dz2 = (double)m->z[2] - (double)m->z[0];
  const double gx = (dz1 * (double)(y0 - y2) + dz2 * (double)(y1 - y0)) * (double)PMR_X_ONE * inv;
  const double gy = (dz1 * (double)(x2 - x0) - dz2 * (double)(x1 - x0)) * (double)PMR_Y_ONE * inv;
  DepthPlane d;
  d.pr = (int)(x0 >> PMR_X_FRAC_BITS); /* arithmetic shifts: floor division */
  d.qr = (int)(y0 >> PMR_Y_FRAC_BITS);
  const double ox = (double)((long)d.pr * PMR_X_ONE + PMR_HALF_X - x0) / (double)PMR_X_ONE;
  const double oy = (double)((long)d.qr * PMR_Y_ONE + PMR_HALF_Y - y0) / (double)PMR_Y_ONE;
  d.zr = (double)m->z[0] + gx * ox + gy * oy;
  d.gy = gy;
  d.gx = (float)gx;
  return d;
}

/* The view shown by a display subpixel (DESIGN section 5), exact and division-free from the
 * per-column and per-row encoder tables (see PmrEncodeColumn). */
inline int encode_view(int views, int reversed, const PmrEncodeColumn* col, const PmrEncodeRow* row) {
  int v = col->a_mod_n - row->q_mod_n - (col->b < row->s ? 1 : 0);
  v = v < 0 ? v + views : v;
  return reversed ? views - 1 - v : v;
}

/* encode_view of 8 subpixels at once, from their columns' a_mod_n and b (vectors loaded from the column
 * tables' planes): the same map in vector arithmetic, which PoCL compiles to SIMD. */
inline int8 encode_view8(int views, int reversed, int8 a_mod_n, int8 b, const PmrEncodeRow* row) {
  int8 v = a_mod_n - (int8)(row->q_mod_n) + (b < (int8)(row->s)); /* a true comparison is -1 */
  v = select(v, v + (int8)(views), v < (int8)(0));
  return reversed ? (int8)(views - 1) - v : v;
}

/* The column table of display row i: with subpixel cells, one block of 3 W_d columns per row class. */
inline global const PmrEncodeColumn* row_columns(global const PmrEncodeParams* E, global const PmrEncodeColumn* columns,
                                                 int i) {
  const int cls = E->cell_rows > 1 ? (E->display_h - 1 - i) % E->cell_rows : 0;
  return columns + (size_t)cls * 3 * (size_t)E->display_w;
}

/* A display pixel from the half-RGBA bits of the view pixels its three subpixels sample: channel k
 * from subpixel k, alpha the mean coverage (the mean of three equal halves is that half exactly, the
 * common case). */
inline ushort4 encode_pixel(ushort4 s0, ushort4 s1, ushort4 s2) {
  ushort alpha = s0.w;
  if (s1.w != s0.w || s2.w != s0.w) {
    const ushort a[3] = {s0.w, s1.w, s2.w};
    const float mean =
        (vload_half(0, (const half*)a) + vload_half(1, (const half*)a) + vload_half(2, (const half*)a)) / 3.0f;
    vstore_half(mean, 0, (half*)&alpha);
  }
  return (ushort4)(s0.x, s1.y, s2.z, alpha);
}

/* Each subpixel's own alpha, beside the display image: sub_alpha[3 * pixel + k] holds subpixel k's
 * (half bits), stored as the EXR channels AR, AG, AB (docs/OUTPUTS.md). */
inline void store_sub_alpha(global ushort* sub_alpha, size_t pixel, ushort4 s0, ushort4 s1, ushort4 s2) {
  vstore3((ushort3)(s0.w, s1.w, s2.w), pixel, sub_alpha);
}

#endif
