/* Shading lanes: the winners of a row are shaded PMR_SW at a time, one lane per voxel (or sample), in
 * explicit OpenCL vectors (PoCL compiles vector types to SIMD but does not vectorize a work-item's loops;
 * see the fine raster). A vector of 3D values is three vectors, one per component (structure of arrays),
 * so a lane's arithmetic is the scalar arithmetic, operation for operation. */
#ifndef PMR_CL_LANES_H
#define PMR_CL_LANES_H

#include "common.h" /* first: its FP_CONTRACT pragma must precede every function */

#define SW 8 /* one AVX2 register of floats; wider machines split it in halves less often than they gain */
typedef float8 sfloat;
typedef int8 sint;
#define vload_s vload8
#define vstore_s vstore8
#define convert_sfloat convert_float8

typedef struct {
  sfloat x, y, z;
} sfloat3;

inline sfloat3 s3(sfloat x, sfloat y, sfloat z) {
  sfloat3 r = {x, y, z};
  return r;
}
inline sfloat3 s3_splat(float3 a) { return s3((sfloat)(a.x), (sfloat)(a.y), (sfloat)(a.z)); }
inline sfloat3 s3_add(sfloat3 a, sfloat3 b) { return s3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline sfloat3 s3_sub(sfloat3 a, sfloat3 b) { return s3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline sfloat3 s3_mul(sfloat3 a, sfloat3 b) { return s3(a.x * b.x, a.y * b.y, a.z * b.z); }
inline sfloat3 s3_scale(sfloat3 a, sfloat s) { return s3(a.x * s, a.y * s, a.z * s); }
inline sfloat3 s3_neg(sfloat3 a) { return s3(-a.x, -a.y, -a.z); }
inline sfloat s3_dot(sfloat3 a, sfloat3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline sfloat3 s3_cross(sfloat3 a, sfloat3 b) {
  return s3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/* where `take`: b, else a */
inline sfloat3 s3_select(sfloat3 a, sfloat3 b, sint take) {
  return s3(select(a.x, b.x, take), select(a.y, b.y, take), select(a.z, b.z, take));
}

/* A vector of 3D values stored per lane (arrays of SW). */
inline void s3_store(sfloat3 a, float* x, float* y, float* z) {
  vstore_s(a.x, 0, x);
  vstore_s(a.y, 0, y);
  vstore_s(a.z, 0, z);
}

/* 2^x and log2(x) (x > 0, normal), to about 2e-7 relative (Cephes's exp2f and logf polynomials), SW
 * lanes at once: the builtins' vector calls cost several times more (the environment's geometric blend,
 * the sheen's Charlie lobe). */
inline sfloat exp2_lanes(sfloat x) {
  x = clamp(x, -126.0f, 126.0f);
  const sfloat k = rint(x), f = x - k; /* f in [-1/2, 1/2] */
  sfloat p = (sfloat)(1.535336188319500e-4f);
  p = p * f + 1.339887440266574e-3f;
  p = p * f + 9.618437357674640e-3f;
  p = p * f + 5.550332471162809e-2f;
  p = p * f + 2.402264791363012e-1f;
  p = p * f + 6.931472028550421e-1f;
  const sfloat m = 1.0f + f * p;
  return as_float8(as_int8(m) + (convert_int8(k) << 23));
}

inline sfloat log2_lanes(sfloat x) {
  const sint bits = as_int8(x);
  sint e = ((bits >> 23) & 0xff) - 127;
  sfloat m = as_float8((bits & 0x007fffff) | 0x3f800000); /* [1, 2) */
  const sint big = m > (sfloat)(1.41421356f);
  m = select(m, m * 0.5f, big);
  e -= big;                              /* -1 where true: e + 1 */
  const sfloat z = m - 1.0f, z2 = z * z; /* z in [-0.29, 0.42): ln(1 + z) */
  sfloat p = (sfloat)(7.0376836292e-2f);
  p = p * z - 1.1514610310e-1f;
  p = p * z + 1.1676998740e-1f;
  p = p * z - 1.2420140846e-1f;
  p = p * z + 1.4249322787e-1f;
  p = p * z - 1.6668057665e-1f;
  p = p * z + 2.0000714765e-1f;
  p = p * z - 2.4999993993e-1f;
  p = p * z + 3.3333331174e-1f;
  const sfloat ln = z - 0.5f * z2 + z * z2 * p;
  return ln * 1.44269504089f + convert_float8(e);
}

/* x^y for x >= 0 (0 for x = 0, y > 0), by exp2_lanes and log2_lanes. */
inline sfloat pow_lanes(sfloat x, sfloat y) { return select(exp2_lanes(y * log2_lanes(x)), (sfloat)(0.0f), x <= 0.0f); }

#endif
