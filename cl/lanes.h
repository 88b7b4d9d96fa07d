/* Shading lanes: the winners of a row are shaded PMR_SW at a time, one lane per voxel (or sample), in
 * explicit OpenCL vectors (PoCL compiles vector types to SIMD but does not vectorize a work-item's loops;
 * see the fine raster). A vector of 3D values is three vectors, one per component (structure of arrays),
 * so a lane's arithmetic is the scalar arithmetic, operation for operation. */
#ifndef PMR_CL_LANES_H
#define PMR_CL_LANES_H

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

#endif
