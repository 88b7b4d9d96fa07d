// The split-sum integrals, computed at build time into the table every pbr frame reads (see the header).
#include "shading/split_sum_integral.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "shading/environment.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

inline double smith_vis(double nl, double nv, double a2) {
  const double s = nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  return s > 0.0 ? 0.5 / s : 0.0;
}

double radical_inverse(uint32_t b) {
  b = (b << 16u) | (b >> 16u);
  b = ((b & 0x55555555u) << 1u) | ((b & 0xAAAAAAAAu) >> 1u);
  b = ((b & 0x33333333u) << 2u) | ((b & 0xCCCCCCCCu) >> 2u);
  b = ((b & 0x0F0F0F0Fu) << 4u) | ((b & 0xF0F0F0F0u) >> 4u);
  b = ((b & 0x00FF00FFu) << 8u) | ((b & 0xFF00FF00u) >> 8u);
  return double(b) * 2.3283064365386963e-10;
}

// The 8192 Hammersley points (x1, cos phi, sin phi), shared by every node.
struct Hammersley {
  std::vector<double> x1, c, s;
};
const Hammersley& hammersley() {
  static const Hammersley h = [] {
    Hammersley t;
    const int n = 8192;
    for (int i = 0; i < n; ++i) {
      const double phi = 2.0 * kPi * radical_inverse(uint32_t(i));
      t.x1.push_back((i + 0.5) / n), t.c.push_back(std::cos(phi)), t.s.push_back(std::sin(phi));
    }
    return t;
  }();
  return h;
}

}  // namespace

glm::dvec2 split_sum_integral(double nv, double r) {
  if (r <= 0.0) {
    const double f = std::pow(1.0 - nv, 5.0);
    return {1.0 - f, f};
  }
  const double a2 = r * r * r * r;
  const double vx = std::sqrt(std::max(0.0, 1.0 - nv * nv));
  const Hammersley& hs = hammersley();
  const size_t n = hs.x1.size();
  double A = 0.0, B = 0.0;
  for (size_t s = 0; s < n; ++s) {
    const double x1 = hs.x1[s];
    const double c2 = (1.0 - x1) / (1.0 + (a2 - 1.0) * x1);
    const double ch = std::sqrt(c2), sh = std::sqrt(std::max(0.0, 1.0 - c2));
    const double hx = sh * hs.c[s];
    const double vh = vx * hx + nv * ch;
    const double lz = 2.0 * vh * ch - nv;  // l = 2 (v.h) h - v
    if (lz <= 0.0 || vh <= 0.0) continue;
    // pdf(l) = D n.h / (4 v.h): D Vis n.l / pdf = Vis n.l 4 v.h / n.h
    const double g = smith_vis(lz, nv, a2) * lz * 4.0 * vh / ch;
    const double m = 1.0 - vh, m2 = m * m, fc = m2 * m2 * m;
    A += (1.0 - fc) * g;
    B += fc * g;
  }
  return {A / double(n), B / double(n)};
}

std::vector<float> compute_split_sum_table() {
  const int N = kEnvSplitSumSize;
  std::vector<float> t(size_t(2 * N * N));
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const double s = double(i) / (N - 1);
      const glm::dvec2 ab = split_sum_integral(s * s, double(j) / (N - 1));
      t[size_t(2 * (j * N + i))] = float(ab.x);
      t[size_t(2 * (j * N + i) + 1)] = float(ab.y);
    }
  return t;
}

}  // namespace pmr
