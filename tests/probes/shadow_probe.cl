/* Test-only kernel: cl/lights.h's shadow_visibility_lanes at given points, which tests/test_shadows.cpp
 * compares with ray-cast visibility. Not part of the rendering program. */
#include "lights.h"

/* in: per point its position and its face normal (6 floats); out: the visibility. */
kernel void shadow_probe(global const PmrShadowMap* maps, global const uint* depth, global const PmrLight* light,
                         global const float* in, global float* out, uint n) {
  const uint i = pmr_item_id();
  if (i >= n) return;
  /* every lane at the one point, seen on the side of its normal */
  const sfloat3 p = s3_splat(vload3(2 * i, in)), ng = s3_splat(vload3(2 * i + 1, in));
  out[i] = shadow_visibility_lanes(maps, depth, light, p, ng, ng, (sint)(-1)).s0;
}
