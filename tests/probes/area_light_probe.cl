/* Test-only kernel: cl/area_lights.h's area_light_lanes at given points, SW of them an item (the lanes
 * of one light together), which tests/test_area_lights.cpp and tests/test_area_ltc.cpp compare with
 * the double-precision reference. Not part of the rendering program. */
#include "area_lights.h"

/* in: per point its light (an index into lights), position, shading normal and direction toward the
 * view (9 floats), roughness and clear coat roughness (the coat's normal the shading normal; < 0: no
 * coat): 12 floats; out: per point l (3), e, cosine, lobe, schlick, coat (8 floats). */
kernel void area_light_probe(global const float* ltc, global const PmrLight* lights, global const float* in,
                             global float* out, uint n) {
  const uint first = pmr_item_id() * SW;
  if (first >= n) return;
  float v[12][SW];
  int act[SW], coated[SW], light[SW];
  for (int j = 0; j < SW; ++j) {
    const uint i = min(first + (uint)j, n - 1);
    for (int k = 0; k < 12; ++k) v[k][j] = in[12 * i + k];
    light[j] = (int)v[0][j];
    act[j] = first + (uint)j < n ? -1 : 0, coated[j] = v[11][j] >= 0.0f ? -1 : 0; /* vector truth: all bits */
  }
  const sfloat3 p = s3(vload_s(0, v[1]), vload_s(0, v[2]), vload_s(0, v[3]));
  const sfloat3 nrm = s3(vload_s(0, v[4]), vload_s(0, v[5]), vload_s(0, v[6]));
  const sfloat3 view = s3(vload_s(0, v[7]), vload_s(0, v[8]), vload_s(0, v[9]));
  const sint lanes = vload_s(0, light);
  sint todo = vload_s(0, act);
  float o[8][SW];
  while (any(todo)) { /* the lanes of one light at a time */
    int t[SW], k = -1;
    vstore_s(todo, 0, t);
    for (int j = 0; j < SW && k < 0; ++j)
      if (t[j]) k = light[j];
    const sint these = todo & (lanes == k);
    const AreaLanes a = area_light_lanes(ltc, &lights[k], p, nrm, view, vload_s(0, v[10]), nrm, vload_s(0, v[11]),
                                         these, vload_s(0, coated));
    float r[8][SW];
    s3_store(a.l, r[0], r[1], r[2]);
    vstore_s(a.e, 0, r[3]), vstore_s(a.cosine, 0, r[4]), vstore_s(a.lobe, 0, r[5]), vstore_s(a.schlick, 0, r[6]);
    vstore_s(a.coat, 0, r[7]);
    int take[SW];
    vstore_s(these, 0, take);
    for (int j = 0; j < SW; ++j)
      for (int c = 0; c < 8; ++c)
        if (take[j]) o[c][j] = r[c][j];
    todo &= ~these;
  }
  for (int j = 0; j < SW && first + (uint)j < n; ++j)
    for (int c = 0; c < 8; ++c) out[8 * (first + (uint)j) + c] = o[c][j];
}
