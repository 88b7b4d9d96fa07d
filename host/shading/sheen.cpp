// KHR_materials_sheen's lobe and its directional albedo (see the header).
#include "shading/sheen.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The extension's fit l(x) of log Lambda for x in [0, 1/2], alpha = r^2.
double lambda_fit(double x, double alpha) {
  const double o = (1.0 - alpha) * (1.0 - alpha);
  const double a = 21.5473 + (25.3245 - 21.5473) * o, b = 3.82987 + (3.32435 - 3.82987) * o;
  const double c = 0.19823 + (0.16801 - 0.19823) * o, d = -1.97760 + (-1.27393 + 1.97760) * o;
  const double e = -4.32054 + (-4.85967 + 4.32054) * o;
  return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}

double sheen_lambda(double cos_theta, double alpha) {
  return cos_theta < 0.5 ? std::exp(lambda_fit(cos_theta, alpha))
                         : std::exp(2.0 * lambda_fit(0.5, alpha) - lambda_fit(1.0 - cos_theta, alpha));
}

}  // namespace

double sheen_roughness(double r) { return std::isfinite(r) ? std::clamp(r, kSheenMinRoughness, 1.0) : 1.0; }

double sheen_lobe_cos(double nv, double nl, double nh, double r) {
  if (nl <= 0.0) return 0.0;
  nv = std::max(nv, kSheenMinCos);
  const double alpha = r * r, sin2h = std::max(0.0, 1.0 - nh * nh);
  const double D = (2.0 + 1.0 / alpha) * std::pow(sin2h, 0.5 / alpha) / (2.0 * kPi);
  // V n.l with V at most 1 (as the Sample Viewer clamps it): bounded at grazing views
  const double s = (1.0 + sheen_lambda(nv, alpha) + sheen_lambda(nl, alpha)) * 4.0 * nv;
  return D * std::min(1.0 / s, nl);
}

double sheen_albedo_integral(double nv, double r) {
  r = sheen_roughness(r);
  nv = std::clamp(nv, kSheenMinCos, 1.0);
  const double vx = std::sqrt(1.0 - nv * nv);
  // h = (sin t cos p, sin t sin p, cos t), p in [0, pi] (the integrand is even in p), l = 2 (v.h) h - v,
  // dl = 4 (v.h) dh, dh = sin t dt dp
  const int nt = 512, np = 256;
  const double dt = 0.5 * kPi / nt, dp = kPi / np;
  double sum = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) * dp;
      const double vh = vx * st * std::cos(p) + nv * ct;
      const double lz = 2.0 * vh * ct - nv;
      if (vh <= 0.0 || lz <= 0.0) continue;
      sum += sheen_lobe_cos(nv, lz, ct, r) * 4.0 * vh * st;
    }
  }
  return 2.0 * sum * dt * dp;
}

std::vector<float> compute_sheen_albedo_table() {
  const int N = kSheenAlbedoSize;
  std::vector<float> t(size_t(N) * size_t(N));
  std::atomic<int> next{0};
  auto rows = [&] {
    for (int j; (j = next.fetch_add(1)) < N;)
      for (int i = 0; i < N; ++i) {
        const double s = double(i) / (N - 1);
        const double r = kSheenMinRoughness + (1.0 - kSheenMinRoughness) * j / (N - 1);
        t[size_t(j * N + i)] = float(sheen_albedo_integral(s * s, r));
      }
  };
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < std::max(1u, std::min(16u, std::thread::hardware_concurrency())); ++k)
    pool.emplace_back(rows);
  rows();
  for (std::thread& th : pool) th.join();
  return t;
}

}  // namespace pmr
