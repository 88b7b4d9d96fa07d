/* Test-only kernels: evaluate cl/brdf.h for arrays of inputs, which tests/test_brdf.cpp compares with
 * the double-precision reference. Not part of the rendering program. */
#include "common.h"
#include "brdf.h"

/* in: 14 floats per case (base rgb, metallic, roughness, n xyz, v xyz, l xyz); out: f * dot(n, l), rgb */
kernel void brdf_probe(global const float* in, global float* out, uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  global const float* c = in + 14 * i;
  const float3 r = brdf_cos(vload3(0, c), c[3], pbr_roughness(c[4]), vload3(0, c + 5), vload3(0, c + 8), vload3(0, c + 11));
  vstore3(r, 0, out + 3 * i);
}

/* in: 18 floats per case (type, colour x intensity xyz, position xyz, direction xyz, range, cos_inner,
 * cos_outer, p xyz, unused); out: E rgb, l xyz */
kernel void light_probe(global const float* in, global float* out, uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  global const float* c = in + 18 * i;
  float3 l;
  const float3 e = light_irradiance((int)c[0], vload3(0, c + 1), vload3(0, c + 4), vload3(0, c + 7), c[10], c[11], c[12],
                                    vload3(0, c + 13), &l);
  vstore3(e, 0, out + 6 * i);
  vstore3(l, 0, out + 6 * i + 3);
}
