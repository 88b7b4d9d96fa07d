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

/* cl/lights.h's environment_visibility_lanes at given points: in, per point its position, its face
 * normal (the shading normal too) and the reflected direction (9 floats); out, per point the diffuse and
 * the specular visibility at lobe sharpness `sharpness`. */
kernel void environment_occlusion_probe(global const PmrShadowMap* maps, global const uint* depth,
                                        global const PmrLight* occ, global const float* in, global float* out, uint n,
                                        float sharpness) {
  const uint i = pmr_item_id();
  if (i >= n) return;
  const sfloat3 p = s3_splat(vload3(3 * i, in)), ng = s3_splat(vload3(3 * i + 1, in)),
                r = s3_splat(vload3(3 * i + 2, in));
  sfloat vd, vs;
  environment_visibility_lanes(maps, depth, occ, p, ng, ng, r, (sfloat)(sharpness), (sint)(-1), &vd, &vs);
  out[2 * i] = vd.s0, out[2 * i + 1] = vs.s0;
}
