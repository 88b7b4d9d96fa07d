/* Test-only kernel: cl/lights.h's shadow_visibility at given points, which tests/test_shadows.cpp
 * compares with ray-cast visibility. Not part of the rendering program. */
#include "lights.h"

/* in: per point its position and its face normal (6 floats); out: the visibility. */
kernel void shadow_probe(global const PmrShadowMap* maps, global const uint* depth, global const PmrLight* light,
                         global const float* in, global float* out, uint n) {
  const uint i = pmr_item_id();
  if (i < n) out[i] = shadow_visibility(maps, depth, light, vload3(2 * i, in), vload3(2 * i + 1, in));
}
