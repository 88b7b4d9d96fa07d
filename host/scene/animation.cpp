#include "scene/animation.h"

#include <algorithm>
#include <cmath>

#include "pmr/error.h"

namespace pmr {

Interpolation parse_interpolation(const std::string& name) {
  if (name == "LINEAR") return Interpolation::Linear;
  if (name == "STEP") return Interpolation::Step;
  if (name == "CUBICSPLINE") return Interpolation::CubicSpline;
  throw Error("unknown animation interpolation '" + name + "' (LINEAR, STEP or CUBICSPLINE)");
}

namespace {

// Spherical interpolation of unit quaternions on the shorter arc (q and -q are the same rotation).
void slerp(const float* a, const float* b, double u, float* out) {
  double d = 0.0;
  for (int c = 0; c < 4; ++c) d += double(a[c]) * b[c];
  const double sign = d < 0.0 ? -1.0 : 1.0;
  d = std::min(1.0, std::abs(d));
  double wa = 1.0 - u, wb = u;
  if (d < 1.0 - 1e-9) {  // otherwise nearly parallel: linear weights are exact enough
    const double angle = std::acos(d), s = std::sin(angle);
    wa = std::sin((1.0 - u) * angle) / s;
    wb = std::sin(u * angle) / s;
  }
  double n = 0.0;
  double q[4];
  for (int c = 0; c < 4; ++c) {
    q[c] = wa * a[c] + wb * sign * b[c];
    n += q[c] * q[c];
  }
  n = n > 0.0 ? 1.0 / std::sqrt(n) : 0.0;
  for (int c = 0; c < 4; ++c) out[c] = float(q[c] * n);
}

void normalize4(float* q) {
  double n = 0.0;
  for (int c = 0; c < 4; ++c) n += double(q[c]) * q[c];
  if (!(n > 0.0)) return;
  n = 1.0 / std::sqrt(n);
  for (int c = 0; c < 4; ++c) q[c] = float(q[c] * n);
}

}  // namespace

std::vector<float> sample(const AnimationSampler& s, double t) {
  const size_t keys = s.times.size(), w = size_t(s.width);
  const size_t per_key = s.interpolation == Interpolation::CubicSpline ? 3 * w : w;
  if (keys == 0 || w == 0 || s.values.size() != keys * per_key || (s.rotation && w != 4))
    throw Error("malformed animation sampler: " + std::to_string(keys) + " keys, " + std::to_string(s.values.size()) +
                " values of width " + std::to_string(w));
  // the value of key k (for CUBICSPLINE the middle of its three elements)
  auto value = [&](size_t k) { return &s.values[k * per_key + (per_key == w ? 0 : w)]; };
  std::vector<float> out(w);
  if (t <= s.times.front() || keys == 1) {
    std::copy_n(value(0), w, out.begin());
    return out;
  }
  if (t >= s.times.back()) {
    std::copy_n(value(keys - 1), w, out.begin());
    return out;
  }
  // the interval [t_k, t_k+1) holding t
  // (compared in double: t just below the last key may round to it as a float, which would put k on
  // the last key and read past the end)
  const size_t k =
      size_t(std::upper_bound(s.times.begin(), s.times.end(), t, [](double a, float b) { return a < double(b); }) -
             s.times.begin()) -
      1;
  const double t0 = s.times[k], t1 = s.times[k + 1], dt = t1 - t0, u = (t - t0) / dt;
  const float *v0 = value(k), *v1 = value(k + 1);
  switch (s.interpolation) {
    case Interpolation::Step:
      std::copy_n(v0, w, out.begin());
      break;
    case Interpolation::Linear:
      if (s.rotation) slerp(v0, v1, u, out.data());
      else
        for (size_t c = 0; c < w; ++c) out[c] = float((1.0 - u) * v0[c] + u * v1[c]);
      break;
    case Interpolation::CubicSpline: {
      // p(u) = (2u^3 - 3u^2 + 1) v0 + (u^3 - 2u^2 + u) dt b0 + (-2u^3 + 3u^2) v1 + (u^3 - u^2) dt a1,
      // b0 = out-tangent of key k, a1 = in-tangent of key k + 1
      const float* b0 = &s.values[k * per_key + 2 * w];
      const float* a1 = &s.values[(k + 1) * per_key];
      const double u2 = u * u, u3 = u2 * u;
      const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
      for (size_t c = 0; c < w; ++c) out[c] = float(h00 * v0[c] + h10 * dt * b0[c] + h01 * v1[c] + h11 * dt * a1[c]);
      if (s.rotation) normalize4(out.data());
      break;
    }
  }
  return out;
}

}  // namespace pmr
