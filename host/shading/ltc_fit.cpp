// The fit of the LTC table (shading/ltc.h), run at build time by pmr_ltc_gen. Every node is fitted on
// its own (no continuation from a neighbour, no random numbers), so the table depends neither on the
// order of the nodes nor on the number of threads.
//
// For each node (n.v, r) and each of the two lobes (D Vis n.l, and (1 - v.h)^5 D Vis n.l), in double:
// 1. The amplitude: the lobe's hemispherical integral (lobe_amplitudes, Gauss-Legendre over half vectors).
// 2. The lobe's frame and spread: its mean direction Z (in the xz-plane, as the LTC's axis) and the
//    98% quantiles of its angle from Z along X and along y, from 32 x 32 GGX-distributed half vectors.
// 3. A comparison grid: the plane tangent to the sphere at Z, 24 x 24 cells of 2 x 2 Gauss points,
//    evenly spaced in angle after a sinh grading (cells near Z about 5x finer than at the edges), out to
//    1.5x the quantiles (at most 86 degrees from Z). The lobe's share of every block of 1, 2 and 4 cells
//    (blocks overlapping by half) is the reference; blocks below 10% of the largest of their size are left
//    out (the tails, where an LTC cannot follow GGX anyway and which barely show).
// 4. The LTC: M^-1 = S (X; y; Z) with S = (s0 0 s1; 0 1 0; s2 0 s3), the 4 numbers s found by
//    Levenberg-Marquardt on the logs of the ratios LTC share / lobe share over those blocks, weighted
//    equally per block size. Start: the lobe's spreads as an elliptic cosine (s = (wy / wx, 0, 0, wy));
//    the Fresnel-weighted lobe starts from the lobe's fit. At n.v = 1 both are isotropic by symmetry:
//    s = (1, 0, 0, d), d by golden-section search.
// Why: measured while developing, over 32,000 lights at 121 (n.v, r) (a larger set than the test's) with
// the RMS relative error of tests/test_area_ltc.cpp (metal; T = 10%, T = 1%), fitting the pointwise L3
// distance of the densities (as Heitz et al. do, by Nelder-Mead) gave 7.5% and 57%, the log ratio of the
// densities 6.8% and 33%, of the block shares 6.6% and 30%: the tails come out far better. Least squares
// with an analytic Jacobian also takes about 50 evaluations a lobe where Nelder-Mead took 550.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "shading/ltc.h"

namespace pmr {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kGrid = 24;            // comparison cells per axis
constexpr int kMoments = 32;         // half-vector samples per axis for the frame and spreads
constexpr double kBlockFloor = 0.1;  // blocks below this share of their size's largest are left out

// One lobe at one node: the view, roughness, the lobe's amplitude and frame, the comparison grid's
// points (with their solid angles and the cell each belongs to) and the reference blocks.
struct Lobe {
  double nv = 1.0, a2 = 1.0, amplitude = 1.0;
  bool fresnel = false;
  glm::dvec3 v{0.0, 0.0, 1.0}, X{1.0, 0.0, 0.0}, Z{0.0, 0.0, 1.0};
  double spread_x = 1.0, spread_y = 1.0;        // 98% quantiles of the angle from Z along X and y
  std::vector<double> px, py, pz, solid_angle;  // the grid's points (unit directions) and solid angles
  std::vector<int> cell;
  struct Block {
    int i0, j0, size;
    double reference, weight;
  };
  std::vector<Block> blocks;
};

// The n-point Gauss-Legendre rule on [0, 1]: nodes (Newton on P_n from Chebyshev guesses) and weights.
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.resize(size_t(n)), w.resize(size_t(n));
  for (int k = 0; k < n; ++k) {
    double t = std::cos(kPi * (k + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = t;  // P_n(t) by the three-term recurrence, P_n' from P_n and P_{n-1}
      for (int j = 2; j <= n; ++j) std::swap(p0, p1), p1 = ((2.0 * j - 1.0) * t * p0 - (j - 1.0) * p1) / j;
      dp = n * (t * p1 - p0) / (t * t - 1.0);
      const double step = p1 / dp;
      t -= step;
      if (std::abs(step) < 1e-15) break;
    }
    x[size_t(k)] = 0.5 * (1.0 - t), w[size_t(k)] = 1.0 / ((1.0 - t * t) * dp * dp);
  }
}

// Step 1: (norm, fresnel), the integrals of D Vis n.l and of (1 - v.h)^5 D Vis n.l over l.z > 0. Over
// GGX-distributed half vectors (cos^2 theta_h = (1 - u) / (1 + (a2 - 1) u), azimuth phi from v's plane),
// d(omega_l) = 4 v.h du dphi / (2 pi D n.h): the integrand 4 v.h Vis n.l / (2 pi n.h) is smooth. l is
// above the horizon for cos phi > c0 = -n.v cos(2 theta_h) / (sin theta_v sin(2 theta_h)): for every phi
// up to theta_1 = (pi / 2 - theta_v) / 2, for none beyond theta_2 = (pi / 2 + theta_v) / 2, in between for
// |phi| < acos(c0). Gauss-Legendre in w = -log(1 - u) (in u, the lobe's tail past a few alpha is squeezed
// next to u = 1), on [w(theta_1), w(theta_2)] spread by a cosine for the square-root ends, and in phi.
// Within 1e-5 of the lobe; split_sum_integral's 8192 Hammersley points were up to 0.8% off at grazing views.
glm::dvec2 lobe_amplitudes(double nv, double r) {
  static const std::vector<double>* rule = [] {
    static std::vector<double> xw[2];
    gauss_legendre(32, xw[0], xw[1]);
    return xw;
  }();
  const std::vector<double>&x = rule[0], &w = rule[1];
  const double a2 = r * r * r * r, theta_v = std::acos(std::min(1.0, nv)), sv = std::sin(theta_v);
  auto w_of = [&](double theta) {  // -log(1 - u) = log(1 + tan^2 theta / a2)
    const double t = std::tan(std::min(theta, 0.5 * kPi - 1e-7));
    return std::log1p(t * t / a2);
  };
  const double w1 = w_of(0.5 * (0.5 * kPi - theta_v)), w2 = w_of(0.5 * (0.5 * kPi + theta_v));
  glm::dvec2 sum(0.0);
  for (int panel = 0; panel < 2; ++panel)
    for (size_t a = 0; a < x.size(); ++a) {
      const double t = kPi * x[a];  // panel 1: w = w1 + (w2 - w1) (1 - cos t) / 2
      const double wv = panel == 0 ? w1 * x[a] : w1 + (w2 - w1) * 0.5 * (1.0 - std::cos(t));
      const double dw = panel == 0 ? w1 * w[a] : (w2 - w1) * 0.5 * std::sin(t) * kPi * w[a];
      const double u = -std::expm1(-wv), du = std::exp(-wv) * dw;
      const double c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u), ch = std::sqrt(c2), sh = std::sqrt(1.0 - c2);
      const double c0 = panel == 0 ? -1.0 : -nv * (2.0 * c2 - 1.0) / (sv * 2.0 * sh * ch);
      const double phi_max = std::acos(std::max(-1.0, std::min(1.0, c0)));
      for (size_t b = 0; b < x.size(); ++b) {
        const double phi = phi_max * x[b], vh = sv * sh * std::cos(phi) + nv * ch, lz = 2.0 * vh * ch - nv;
        if (lz <= 0.0) continue;
        const double vis =
            0.5 / (lz * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(lz * lz * (1.0 - a2) + a2));
        const double f = 4.0 * vh * vis * lz / (2.0 * kPi * ch) * 2.0 * phi_max * w[b] * du;  // phi in [-max, max]
        const double k = 1.0 - vh, k2 = k * k;
        sum += glm::dvec2(f, k2 * k2 * k * f);
      }
    }
  return sum;
}

// D Vis n.l for n = +z (the glTF GGX lobe of docs/SHADING.md), 0 below the horizon; times (1 - v.h)^5
// for the Fresnel-weighted lobe.
double lobe_value(const Lobe& lobe, const glm::dvec3& l) {
  if (l.z <= 0.0) return 0.0;
  const glm::dvec3 h = glm::normalize(l + lobe.v);
  const double a2 = lobe.a2, nv = lobe.nv;
  const double dd = h.z * h.z * (a2 - 1.0) + 1.0, D = a2 / (kPi * dd * dd);
  const double s = l.z * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(l.z * l.z * (1.0 - a2) + a2);
  const double f = D * 0.5 / s * l.z;
  if (!lobe.fresnel) return f;
  const double c = 1.0 - std::max(0.0, glm::dot(lobe.v, h)), c2 = c * c;
  return c2 * c2 * c * f;
}

// The weighted q-quantile of the values.
double quantile(std::vector<std::pair<double, double>> values, double q) {
  std::sort(values.begin(), values.end());
  double total = 0.0, sum = 0.0;
  for (const auto& value : values) total += value.second;
  for (const auto& value : values)
    if ((sum += value.second) >= q * total) return value.first;
  return values.empty() ? 1.0 : values.back().first;
}

// Step 2: the mean direction and the spreads, from GGX-distributed half vectors (each l weighted by
// lobe / pdf, so that the weights sum to the lobe's integral).
void lobe_frame(Lobe& lobe) {
  std::vector<glm::dvec3> ls;
  std::vector<double> ws;
  glm::dvec3 mean(0.0);
  for (int a = 0; a < kMoments; ++a)
    for (int b = 0; b < kMoments; ++b) {
      const double u = (a + 0.5) / kMoments, phi = 2.0 * kPi * (b + 0.5) / kMoments;
      const double c2 = (1.0 - u) / (1.0 + (lobe.a2 - 1.0) * u), ch = std::sqrt(c2), sh = std::sqrt(1.0 - c2);
      const glm::dvec3 h(sh * std::cos(phi), sh * std::sin(phi), ch);
      const double vh = glm::dot(lobe.v, h);
      const glm::dvec3 l = 2.0 * vh * h - lobe.v;
      if (vh <= 0.0 || l.z <= 0.0) continue;
      const double dd = c2 * (lobe.a2 - 1.0) + 1.0, pdf = lobe.a2 / (kPi * dd * dd) * ch / (4.0 * vh);
      ls.push_back(l), ws.push_back(lobe_value(lobe, l) / pdf);
      mean += ws.back() * l;
    }
  lobe.Z = lobe.nv >= 1.0 ? glm::dvec3(0.0, 0.0, 1.0) : glm::normalize(glm::dvec3(mean.x, 0.0, mean.z));
  lobe.X = {lobe.Z.z, 0.0, -lobe.Z.x};
  std::vector<std::pair<double, double>> ax, ay;
  for (size_t k = 0; k < ls.size(); ++k) {
    const double z = glm::dot(ls[k], lobe.Z);
    ax.push_back({std::abs(std::atan2(glm::dot(ls[k], lobe.X), z)), ws[k]});
    ay.push_back({std::abs(std::atan2(ls[k].y, z)), ws[k]});
  }
  lobe.spread_x = quantile(ax, 0.98), lobe.spread_y = quantile(ay, 0.98);
}

// The 2-D prefix sums of per-cell values (cells of one lobe's grid) into P: P[j (kGrid + 1) + i] is the
// sum over cells below j and left of i.
void cell_prefix_sums(const Lobe& lobe, const std::vector<double>& point_values, std::vector<double>& P) {
  double cells[kGrid * kGrid] = {};
  for (size_t k = 0; k < point_values.size(); ++k) cells[lobe.cell[k]] += point_values[k];
  P.assign((kGrid + 1) * (kGrid + 1), 0.0);
  const int W = kGrid + 1;
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i)
      P[(j + 1) * W + i + 1] = cells[j * kGrid + i] + P[j * W + i + 1] + P[(j + 1) * W + i] - P[j * W + i];
}

double block_sum(const std::vector<double>& P, const Lobe::Block& b) {
  const int W = kGrid + 1, i1 = b.i0 + b.size, j1 = b.j0 + b.size;
  return P[j1 * W + i1] - P[b.j0 * W + i1] - P[j1 * W + b.i0] + P[b.j0 * W + b.i0];
}

// The points in cells that no block covers change no residual: they are dropped.
void drop_unused_points(Lobe& lobe) {
  bool used[kGrid * kGrid] = {};
  for (const Lobe::Block& b : lobe.blocks)
    for (int j = b.j0; j < b.j0 + b.size; ++j)
      for (int i = b.i0; i < b.i0 + b.size; ++i) used[j * kGrid + i] = true;
  size_t n = 0;
  for (size_t k = 0; k < lobe.cell.size(); ++k)
    if (used[lobe.cell[k]])
      lobe.px[n] = lobe.px[k], lobe.py[n] = lobe.py[k], lobe.pz[n] = lobe.pz[k],
      lobe.solid_angle[n] = lobe.solid_angle[k], lobe.cell[n] = lobe.cell[k], ++n;
  for (std::vector<double>* v : {&lobe.px, &lobe.py, &lobe.pz, &lobe.solid_angle}) v->resize(n);
  lobe.cell.resize(n);
}

// Step 3: the grid's points and the reference blocks.
void lobe_grid(Lobe& lobe) {
  const double g = 0.5 / std::sqrt(3.0), grading = 2.5;
  const double tx = std::min(1.5, 1.5 * lobe.spread_x), ty = std::min(1.5, 1.5 * lobe.spread_y);
  std::vector<double> x, wx, y, wy;  // per axis: tan of the Gauss points' angles, weight x sec^2
  for (int i = 0; i < kGrid; ++i) {
    const double u0 = std::sinh(grading * (2.0 * i / kGrid - 1.0)) / std::sinh(grading);
    const double u1 = std::sinh(grading * (2.0 * (i + 1) / kGrid - 1.0)) / std::sinh(grading);
    for (double t : {0.5 - g, 0.5 + g}) {
      const double a = tx * (u0 + (u1 - u0) * t), b = ty * (u0 + (u1 - u0) * t);
      x.push_back(std::tan(a)), wx.push_back(0.5 * tx * (u1 - u0) * (1.0 + x.back() * x.back()));
      y.push_back(std::tan(b)), wy.push_back(0.5 * ty * (u1 - u0) * (1.0 + y.back() * y.back()));
    }
  }
  std::vector<double> reference, P;
  for (size_t b = 0; b < y.size(); ++b)
    for (size_t a = 0; a < x.size(); ++a) {
      const double g2 = 1.0 + x[a] * x[a] + y[b] * y[b];
      const glm::dvec3 l = (x[a] * lobe.X + glm::dvec3(0.0, y[b], 0.0) + lobe.Z) / std::sqrt(g2);
      lobe.px.push_back(l.x), lobe.py.push_back(l.y), lobe.pz.push_back(l.z);
      lobe.solid_angle.push_back(wx[a] * wy[b] / (g2 * std::sqrt(g2)));  // d(omega) = dx dy / g^3
      lobe.cell.push_back(int(b / 2) * kGrid + int(a / 2));
      reference.push_back(lobe_value(lobe, l) / lobe.amplitude * lobe.solid_angle.back());
    }
  cell_prefix_sums(lobe, reference, P);
  for (int size = 1; size <= 4; size *= 2) {
    std::vector<Lobe::Block> blocks;
    double largest = 0.0;
    for (int j = 0; j + size <= kGrid; j += std::max(1, size / 2))
      for (int i = 0; i + size <= kGrid; i += std::max(1, size / 2)) {
        blocks.push_back({i, j, size, 0.0, 0.0});
        blocks.back().reference = block_sum(P, blocks.back());
        largest = std::max(largest, blocks.back().reference);
      }
    blocks.erase(std::remove_if(blocks.begin(), blocks.end(),
                                [&](const Lobe::Block& b) {
                                  return !(b.reference >= kBlockFloor * largest && b.reference > 0.0);
                                }),
                 blocks.end());
    for (Lobe::Block& b : blocks) b.weight = 1.0 / double(blocks.size()), lobe.blocks.push_back(b);
  }
  drop_unused_points(lobe);
}

// M^-1 in the node's frame (rows (m00 0 m02), (0 1 0), (m20 0 m22)) from the shape s in the lobe's frame.
void inverse_matrix(const Lobe& lobe, const double* s, double* m) {
  m[0] = s[0] * lobe.X.x + s[1] * lobe.Z.x, m[1] = s[0] * lobe.X.z + s[1] * lobe.Z.z;
  m[2] = s[2] * lobe.X.x + s[3] * lobe.Z.x, m[3] = s[2] * lobe.X.z + s[3] * lobe.Z.z;
}

// The residuals of step 4: sqrt(weight) log(LTC share / lobe share) per block, and if `jacobian` is
// given their derivatives with respect to s (jacobian[k][block]). The LTC's density at l is
// D_o(M^-1 l / |M^-1 l|) |det M^-1| / |M^-1 l|^3 with D_o = max(z, 0) / pi, so with u = M^-1 l and
// q = |u|^2: D = max(u.z, 0) |det| / (pi q^2), and d log D = d u.z / u.z + d det / det - 2 d q / q.
void residuals(const Lobe& lobe, const double* s, std::vector<double>& res, std::vector<double>* jacobian) {
  thread_local std::vector<double> values[5], P[5];  // scratch: D per point, then its 4 derivatives
  double m[4];
  inverse_matrix(lobe, s, m);
  const double det = m[0] * m[3] - m[1] * m[2], scale = std::abs(det) / kPi;
  const glm::dvec3 &X = lobe.X, &Z = lobe.Z;
  const int outputs = jacobian ? 5 : 1;
  for (int o = 0; o < outputs; ++o) values[o].assign(lobe.px.size(), 0.0);
  for (size_t k = 0; k < lobe.px.size(); ++k) {
    const double px = lobe.px[k], pz = lobe.pz[k], y = lobe.py[k];
    const double x = m[0] * px + m[1] * pz, z = m[2] * px + m[3] * pz, q = x * x + y * y + z * z;
    const double w = scale * lobe.solid_angle[k] / (q * q), D = std::max(z, 0.0) * w;
    values[0][k] = D;
    if (!jacobian || z <= 0.0) continue;
    const double c = 4.0 / q;  // dm: the derivatives of D with respect to m00, m02, m20, m22
    const double dm0 = D * (m[3] / det - c * x * px), dm1 = D * (-m[2] / det - c * x * pz);
    const double dm2 = w * px + D * (-m[1] / det - c * z * px), dm3 = w * pz + D * (m[0] / det - c * z * pz);
    values[1][k] = dm0 * X.x + dm1 * X.z, values[2][k] = dm0 * Z.x + dm1 * Z.z;  // m = s (X; y; Z)
    values[3][k] = dm2 * X.x + dm3 * X.z, values[4][k] = dm2 * Z.x + dm3 * Z.z;
  }
  for (int o = 0; o < outputs; ++o) cell_prefix_sums(lobe, values[o], P[o]);
  res.resize(lobe.blocks.size());
  for (int o = 1; o < outputs; ++o) jacobian[o - 1].resize(lobe.blocks.size());
  for (size_t b = 0; b < lobe.blocks.size(); ++b) {
    const Lobe::Block& block = lobe.blocks[b];
    const double share = std::max(block_sum(P[0], block), 1e-300), w = std::sqrt(block.weight);
    // a flipped M (det <= 0) is pushed back by a large residual
    res[b] = w * (std::log(share / block.reference) + (det > 0.0 ? 0.0 : 1e3));
    for (int o = 1; o < outputs; ++o) jacobian[o - 1][b] = w * block_sum(P[o], block) / share;
  }
}

double sum_of_squares(const std::vector<double>& r) {
  double e = 0.0;
  for (double x : r) e += x * x;
  return e;
}

// Solves the 4 x 4 system A d = b in place (Gaussian elimination with partial pivoting); false if singular.
bool solve4(double A[4][4], double* b) {
  for (int i = 0; i < 4; ++i) {
    int p = i;
    for (int k = i + 1; k < 4; ++k)
      if (std::abs(A[k][i]) > std::abs(A[p][i])) p = k;
    std::swap(A[i], A[p]), std::swap(b[i], b[p]);
    if (A[i][i] == 0.0) return false;
    for (int k = i + 1; k < 4; ++k) {
      const double f = A[k][i] / A[i][i];
      for (int c = i; c < 4; ++c) A[k][c] -= f * A[i][c];
      b[k] -= f * b[i];
    }
  }
  for (int i = 3; i >= 0; --i) {
    for (int c = i + 1; c < 4; ++c) b[i] -= A[i][c] * b[c];
    b[i] /= A[i][i];
  }
  return true;
}

// Levenberg-Marquardt until a step gains less than 1e-8 of the error or none is found (30 steps at most).
void levenberg_marquardt(const Lobe& lobe, double* s) {
  std::vector<double> r0, r1, J[4];
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 30; ++iteration) {
    residuals(lobe, s, r0, J);
    double e0 = sum_of_squares(r0);
    double JtJ[4][4], g[4];
    for (int a = 0; a < 4; ++a) {
      g[a] = 0.0;
      for (size_t q = 0; q < r0.size(); ++q) g[a] += J[a][q] * r0[q];
      for (int b = 0; b < 4; ++b) {
        JtJ[a][b] = 0.0;
        for (size_t q = 0; q < r0.size(); ++q) JtJ[a][b] += J[a][q] * J[b][q];
      }
    }
    bool improved = false, converged = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      double A[4][4], d[4];
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) A[a][b] = JtJ[a][b] * (a == b ? 1.0 + lambda : 1.0);
        d[a] = -g[a];
      }
      const bool solved = solve4(A, d);
      const double sn[4] = {s[0] + d[0], s[1] + d[1], s[2] + d[2], s[3] + d[3]};
      if (solved) residuals(lobe, sn, r1, nullptr);
      const double e1 = solved ? sum_of_squares(r1) : e0;
      if (e1 < e0) {
        converged = e0 - e1 < 1e-8 * e0;
        std::copy(sn, sn + 4, s), e0 = e1, improved = true, lambda *= 0.3;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved || converged) break;
  }
}

// The isotropic fit at n.v = 1: s = (1, 0, 0, d), d by golden-section search on log d in [1e-4, 20].
void fit_isotropic(const Lobe& lobe, double* s) {
  std::vector<double> res;
  auto error = [&](double log_d) {
    const double t[4] = {1.0, 0.0, 0.0, std::exp(log_d)};
    residuals(lobe, t, res, nullptr);
    return sum_of_squares(res);
  };
  double lo = std::log(1e-4), hi = std::log(20.0);
  for (int k = 0; k < 60; ++k) {
    const double a = lo + 0.381966 * (hi - lo), b = lo + 0.618034 * (hi - lo);
    if (error(a) < error(b)) hi = b;
    else lo = a;
  }
  s[0] = 1.0, s[1] = 0.0, s[2] = 0.0, s[3] = std::exp(0.5 * (lo + hi));
}

Lobe make_lobe(double nv, double r, bool fresnel, const glm::dvec2& amplitudes) {
  Lobe lobe;
  lobe.nv = nv, lobe.a2 = r * r * r * r, lobe.fresnel = fresnel;
  lobe.amplitude = std::max(fresnel ? amplitudes.y : amplitudes.x, 1e-300);  // fresnel ~ 1e-17 at n.v = 1, r = 0.03
  lobe.v = {std::sqrt(std::max(0.0, 1.0 - nv * nv)), 0.0, nv};
  lobe_frame(lobe);
  lobe_grid(lobe);
  return lobe;
}

}  // namespace

void fit_ltc_node(int i, int j, float* out) {
  const double u = double(i) / (kLtcSize - 1), s0 = std::sqrt(0.03);
  const double nv = 1.0 - u * u, sr = s0 + (1.0 - s0) * double(j) / (kLtcSize - 1), r = sr * sr;
  const glm::dvec2 amplitudes = lobe_amplitudes(nv, r);
  double m[4] = {1.0, 0.0, 0.0, 1.0};
  for (const bool fresnel : {false, true}) {
    const Lobe lobe = make_lobe(nv, r, fresnel, amplitudes);
    double s[4];
    if (i == 0) {
      fit_isotropic(lobe, s);
    } else if (fresnel) {  // the lobe's M^-1 (m) seen in this lobe's frame
      s[0] = m[0] * lobe.X.x + m[1] * lobe.X.z, s[1] = m[0] * lobe.Z.x + m[1] * lobe.Z.z;
      s[2] = m[2] * lobe.X.x + m[3] * lobe.X.z, s[3] = m[2] * lobe.Z.x + m[3] * lobe.Z.z;
      levenberg_marquardt(lobe, s);
    } else {  // an elliptic cosine as wide as the lobe: forward M ~ diag(wx, wy, 1), w = 0.4 tan(spread)
      const double wx = 0.4 * std::tan(std::min(1.4, lobe.spread_x)), wy = 0.4 * std::tan(std::min(1.4, lobe.spread_y));
      s[0] = wy / wx, s[1] = 0.0, s[2] = 0.0, s[3] = wy;
      levenberg_marquardt(lobe, s);
    }
    inverse_matrix(lobe, s, m);
    for (int k = 0; k < 4; ++k) out[(fresnel ? 4 : 0) + k] = float(m[k]);
  }
  out[8] = float(amplitudes.x), out[9] = float(amplitudes.y);
}

std::vector<float> compute_ltc_table(int threads) {
  std::vector<float> table(size_t(kLtcNodeFloats) * kLtcSize * kLtcSize);
  std::atomic<int> next_row{0};
  auto work = [&] {
    for (int j; (j = next_row++) < kLtcSize;)
      for (int i = 0; i < kLtcSize; ++i) fit_ltc_node(i, j, &table[size_t(kLtcNodeFloats) * (j * kLtcSize + i)]);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::max(1, threads); ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  return table;
}

}  // namespace pmr
