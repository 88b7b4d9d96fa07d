/* Test-only kernels: evaluate cl/brdf.h for arrays of inputs, which tests/test_brdf.cpp compares with
 * the double-precision reference. Not part of the rendering program. brdf_probe evaluates SW cases
 * per work-item, one per lane (past n, lanes repeat the last case); work-items past n / SW return. */
#include "common.h"
#include "brdf.h"
#include "lights.h"

/* Case (first + l) of lane l, as a lane's index into the inputs. */
inline int probe_case(uint first, int l, uint n) { return (int)min(first + (uint)l, n - 1u); }

/* in: 18 floats per case (base rgb, metallic, roughness, n xyz, v xyz, l xyz, KHR_materials_specular's
 * weight and colour rgb, ior 1.5); out: f * dot(n, l), rgb */
kernel void brdf_probe(global const float* in, global float* out, uint n) {
  const uint first = get_global_id(0) * SW;
  if (first >= n) return;
  float c[18][SW];
  for (int l = 0; l < SW; ++l)
    for (int k = 0; k < 18; ++k) c[k][l] = in[18 * probe_case(first, l, n) + k];
#define LANES(k) vload_s(0, c[k])
#define LANES3(k) s3(LANES(k), LANES(k + 1), LANES(k + 2))
  const sfloat3 f0 = pbr_f0(LANES3(0), LANES(3), specular_f0((sfloat)(0.04f), LANES3(15), LANES(14)));
  const sfloat3 r = brdf_cos(LANES3(0), LANES(3), f0, pbr_f90(LANES(14), LANES(3)), pbr_roughness(LANES(4)), LANES3(5),
                             LANES3(8), LANES3(11), 0, 0);
  float o[3][SW];
  vstore_s(r.x, 0, o[0]), vstore_s(r.y, 0, o[1]), vstore_s(r.z, 0, o[2]);
  for (int l = 0; l < SW && first + (uint)l < n; ++l)
    for (int k = 0; k < 3; ++k) out[3 * (first + (uint)l) + k] = o[k][l];
}

/* in: 18 floats per case (type, colour x intensity xyz, position xyz, direction xyz, range, cos_inner,
 * cos_outer, p xyz, unused); out: E rgb, l xyz. The light is uniform across lanes (as in rendering), so
 * each work-item takes one case in every lane and writes lane 0. */
kernel void light_probe(global const float* in, global float* out, uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  global const float* c = in + 18 * i;
  sfloat3 l;
  const sfloat3 e = light_irradiance((int)c[0], vload3(0, c + 1), vload3(0, c + 4), vload3(0, c + 7), c[10], c[11],
                                     c[12], s3_splat(vload3(0, c + 13)), &l);
  vstore3((float3)(e.x.s0, e.y.s0, e.z.s0), 0, out + 6 * i);
  vstore3((float3)(l.x.s0, l.y.s0, l.z.s0), 0, out + 6 * i + 3);
}
