/* Test-only kernel: evaluates cl/environment.h's lookups for arrays of directions, which
 * tests/test_pbr.cpp compares with the host's (Environment::irradiance, prefiltered). Not part of the
 * rendering program. */
#include "common.h"
#include "environment.h"

/* in: 4 floats per case (direction xyz, roughness); out: I(d) rgb, P(d, r) rgb, the sheen's S(d, r) rgb.
 * Work-item i takes cases
 * SW i to SW i + SW - 1, one per lane (n a multiple of SW). */
kernel void environment_probe(global const PmrEnvironment* e, global const float4* data, global const float* in,
                              global float* out, uint n) {
  const uint i = get_global_id(0);
  if (SW * i >= n) return;
  float x[SW], y[SW], z[SW], r[SW], c[9][SW];
  for (int l = 0; l < SW; ++l) {
    const float4 q = vload4(0, in + 4 * (SW * i + l));
    x[l] = q.x, y[l] = q.y, z[l] = q.z, r[l] = q.w;
  }
  sfloat u, v;
  env_uv(e, s3(vload_s(0, x), vload_s(0, y), vload_s(0, z)), &u, &v);
  s3_store(env_irradiance(e, data, u, v), c[0], c[1], c[2]);
  s3_store(env_prefiltered(e, data, u, v, vload_s(0, r)), c[3], c[4], c[5]);
  s3_store(env_sheen(e, data, u, v, vload_s(0, r)), c[6], c[7], c[8]);
  for (int l = 0; l < SW; ++l)
    for (int k = 0; k < 9; ++k) out[9 * (SW * i + l) + k] = c[k][l];
}
