// The LTC table's lookup (see the header), as the kernels compute it (cl/area_lights.h ltc_lookup).
#include "shading/ltc.h"

#include <algorithm>
#include <cmath>

namespace pmr {

LtcCoefficients ltc_lookup(float n_dot_v, float r) {
  const int N = kLtcSize;
  const float nv = std::fmin(std::fmax(n_dot_v, 0.0f), 1.0f);
  const float x = std::fmin(std::fmax(std::sqrt(1.0f - nv) * float(N - 1), 0.0f), float(N - 1));
  const float y =
      std::fmin(std::fmax((std::sqrt(r) - kLtcSqrtRMin) / (1.0f - kLtcSqrtRMin) * float(N - 1), 0.0f), float(N - 1));
  const int i = std::min(int(x), N - 2), j = std::min(int(y), N - 2);
  const float fx = x - float(i), fy = y - float(j);
  const float* t00 = kLtcTable + kLtcNodeFloats * (j * N + i);
  const float* t10 = t00 + kLtcNodeFloats;
  const float* t01 = t00 + kLtcNodeFloats * N;
  const float* t11 = t01 + kLtcNodeFloats;
  float f[kLtcNodeFloats];
  for (int k = 0; k < kLtcNodeFloats; ++k)
    f[k] = (1.0f - fy) * ((1.0f - fx) * t00[k] + fx * t10[k]) + fy * ((1.0f - fx) * t01[k] + fx * t11[k]);
  return {{f[0], f[1], f[2], f[3]}, {f[4], f[5], f[6], f[7]}, f[8], f[9]};
}

const std::vector<float>& ltc_table() {
  static const std::vector<float> table(kLtcTable, kLtcTable + size_t(kLtcSize) * kLtcSize * kLtcNodeFloats);
  return table;
}

}  // namespace pmr
