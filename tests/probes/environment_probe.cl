/* Test-only kernel: evaluates cl/environment.h's lookups for arrays of directions, which
 * tests/test_pbr.cpp compares with the host's (Environment::irradiance, prefiltered). Not part of the
 * rendering program. */
#include "common.h"
#include "environment.h"

/* in: 4 floats per case (direction xyz, roughness); out: I(d) rgb, P(d, r) rgb */
kernel void environment_probe(global const PmrEnvironment* e, global const float4* data, global const float* in,
                              global float* out, uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const float3 d = vload3(0, in + 4 * i);
  const float4 uv = env_uv(e, d, d);
  vstore3(env_irradiance(e, data, uv.xy), 0, out + 6 * i);
  vstore3(env_prefiltered(e, data, uv.zw, in[4 * i + 3]), 0, out + 6 * i + 3);
}
