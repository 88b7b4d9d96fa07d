#include "reference/area_light_reference.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace pmr::ref {

namespace {

constexpr double kPi = 3.14159265358979323846;

// An integrand over the light's parameter square [0, 1]^2 with two components (specular: the lobe and
// its Fresnel-weighted part; form factor: n.l twice). Without a light, the square maps to the
// hemisphere about n = +z: l.z = s, azimuth 2 pi t.
struct Integrand {
  const AreaLight* light;
  glm::dvec3 p, n, v;
  double a2 = 0.0;
  bool specular = true;

  // the light's point at (s, t) and the area it stands for per unit of s and t
  glm::dvec3 point(double s, double t, double& area) const {
    const double uv = glm::length(glm::cross(light->u, light->v));
    if (!light->disk) {
      area = 4.0 * uv;
      return light->center + (2.0 * s - 1.0) * light->u + (2.0 * t - 1.0) * light->v;
    }
    const double phi = 2.0 * kPi * t;  // polar: radius s, angle phi
    area = 2.0 * kPi * s * uv;
    return light->center + s * (std::cos(phi) * light->u + std::sin(phi) * light->v);
  }

  // the direction at (s, t) and the solid angle it stands for per unit of s and t (0: no light there)
  glm::dvec3 direction(double s, double t, double& jacobian) const {
    if (!light) {
      const double r = std::sqrt(std::max(0.0, 1.0 - s * s)), phi = 2.0 * kPi * t;
      jacobian = 2.0 * kPi;
      return {r * std::cos(phi), r * std::sin(phi), s};
    }
    double area = 0.0;
    const glm::dvec3 w = point(s, t, area) - p;
    const double d2 = glm::dot(w, w);
    const glm::dvec3 l = w / std::sqrt(d2);
    const double cos_light = -glm::dot(glm::normalize(glm::cross(light->u, light->v)), l);
    jacobian = cos_light > 0.0 ? area * cos_light / d2 : 0.0;  // dω = cos_light dA / d^2
    return l;
  }

  glm::dvec2 operator()(double s, double t) const {
    double jacobian = 0.0;
    const glm::dvec3 l = direction(s, t, jacobian);
    const double nl = glm::dot(n, l);
    if (jacobian <= 0.0 || nl <= 0.0) return glm::dvec2(0.0);
    if (!specular) return glm::dvec2(nl / kPi * jacobian);
    const glm::dvec3 h = glm::normalize(l + v);
    const double nh = std::min(1.0, glm::dot(n, h)), vh = std::max(0.0, glm::dot(v, h));
    const double nv = std::max(0.0, glm::dot(n, v));
    const double dd = nh * nh * (a2 - 1.0) + 1.0, D = a2 / (kPi * dd * dd);
    const double sv = nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
    const double lobe = D * 0.5 / sv * nl * jacobian;
    return {lobe, std::pow(1.0 - vh, 5.0) * lobe};
  }
};

// A cell of the cubature: its center, half widths, the degree-7 estimate, the error estimate (the
// difference to the embedded degree-5 rule) and the axis to split along.
struct Cell {
  double c[2], h[2];
  glm::dvec2 value, error;
  int axis = 0;
  double key = 0.0;
  bool operator<(const Cell& o) const { return key < o.key; }
};

// Genz and Malik's degree-7 rule on a 2-D cell (17 points) with its embedded degree-5 rule; the split
// axis is the one with the larger fourth difference.
Cell genz_malik(const Integrand& f, double cs, double ct, double hs, double ht) {
  const double l2 = std::sqrt(9.0 / 70.0), l4 = std::sqrt(9.0 / 10.0), l5 = std::sqrt(9.0 / 19.0);
  const double w1 = (12824.0 - 9120.0 * 2 + 400.0 * 4) / 19683.0, w2 = 980.0 / 6561.0;
  const double w3 = (1820.0 - 400.0 * 2) / 19683.0, w4 = 200.0 / 19683.0, w5 = 6859.0 / 19683.0 / 4.0;
  const double e1 = (729.0 - 950.0 * 2 + 50.0 * 4) / 729.0, e2 = 245.0 / 486.0;
  const double e3 = (265.0 - 100.0 * 2) / 1458.0, e4 = 25.0 / 729.0;
  const double c[2] = {cs, ct}, h[2] = {hs, ht};
  auto at = [&](double a, double b) { return f(cs + a * hs, ct + b * ht); };
  const glm::dvec2 f0 = at(0, 0);
  glm::dvec2 s2(0.0), s3(0.0), s4(0.0), s5(0.0);
  double diff[2];
  for (int k = 0; k < 2; ++k) {
    const double a = k == 0 ? 1.0 : 0.0, b = 1.0 - a;
    const glm::dvec2 p2 = at(l2 * a, l2 * b) + at(-l2 * a, -l2 * b);
    const glm::dvec2 p3 = at(l4 * a, l4 * b) + at(-l4 * a, -l4 * b);
    s2 += p2, s3 += p3;
    const glm::dvec2 d = p2 - 2.0 * f0 - (9.0 / 70.0) / (9.0 / 10.0) * (p3 - 2.0 * f0);
    diff[k] = std::abs(d.x) + std::abs(d.y);
  }
  for (double a : {-1.0, 1.0})
    for (double b : {-1.0, 1.0}) s4 += at(l4 * a, l4 * b), s5 += at(l5 * a, l5 * b);
  const double vol = 4.0 * hs * ht;
  Cell cell{{c[0], c[1]}, {h[0], h[1]}, {}, {}, diff[1] > diff[0] ? 1 : 0, 0.0};
  cell.value = vol * (w1 * f0 + w2 * s2 + w3 * s3 + w4 * s4 + w5 * s5);
  cell.error = glm::abs(cell.value - vol * (e1 * f0 + e2 * s2 + e3 * s3 + e4 * s4));
  return cell;
}

// Breakpoints along one axis of [0, 1]: a uniform eighth grid plus cells shrinking 4x toward x (down to
// 1e-4), so that a highlight narrower than any uniform grid is met by the rule's points.
std::vector<double> graded_breaks(double x) {
  std::vector<double> b = {0.0, 1.0, x};
  for (int k = 1; k < 8; ++k) b.push_back(k / 8.0);
  for (double step = 1e-4; step < 1.0; step *= 4.0) b.push_back(x - step), b.push_back(x + step);
  b.erase(std::remove_if(b.begin(), b.end(), [](double y) { return y < 0.0 || y > 1.0; }), b.end());
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end(), [](double a, double c) { return c - a < 1e-12; }), b.end());
  return b;
}

// Where on [0, 1]^2 the lobe's integrand peaks: the best of a 33 x 33 scan, refined by a pattern
// search down to 1e-7 (a highlight can be much narrower than the scan's step).
glm::dvec2 peak(const Integrand& f) {
  glm::dvec2 best(0.5);
  double fb = -1.0;
  for (int i = 0; i <= 32; ++i)
    for (int j = 0; j <= 32; ++j)
      if (const double y = f(i / 32.0, j / 32.0).x; y > fb) fb = y, best = {i / 32.0, j / 32.0};
  for (double step = 1.0 / 32.0; step > 1e-7;) {
    bool moved = false;
    for (const glm::dvec2 d : {glm::dvec2(1, 0), glm::dvec2(-1, 0), glm::dvec2(0, 1), glm::dvec2(0, -1)}) {
      const glm::dvec2 q = glm::clamp(best + step * d, 0.0, 1.0);
      if (const double y = f(q.x, q.y).x; y > fb) fb = y, best = q, moved = true;
    }
    if (!moved) step *= 0.5;
  }
  return best;
}

// Adaptive cubature of f over [0, 1]^2: a grid graded about the peak, then the cell with the largest
// relative error is halved until the summed error is below tol of the total (or 400000 cells).
glm::dvec2 cubature(const Integrand& f, double tol) {
  const glm::dvec2 at = peak(f);
  const std::vector<double> bs = graded_breaks(at.x), bt = graded_breaks(at.y);
  std::vector<Cell> cells;
  glm::dvec2 total(0.0), error(0.0);
  for (size_t i = 0; i + 1 < bs.size(); ++i)
    for (size_t j = 0; j + 1 < bt.size(); ++j) {
      const Cell c = genz_malik(f, 0.5 * (bs[i] + bs[i + 1]), 0.5 * (bt[j] + bt[j + 1]), 0.5 * (bs[i + 1] - bs[i]),
                                0.5 * (bt[j + 1] - bt[j]));
      cells.push_back(c), total += c.value, error += c.error;
    }
  // the relative errors of both components count, the Fresnel part's down to 1% of the lobe (below,
  // it is negligible even for a dielectric's F0 = 0.04)
  const double x = std::max(std::abs(total.x), 1e-300);
  const glm::dvec2 scale(1.0 / x, 1.0 / std::max(std::abs(total.y), 0.01 * x));
  std::priority_queue<Cell> queue;
  for (Cell& c : cells) c.key = glm::dot(c.error, scale), queue.push(c);
  for (int n = 0; n < 400000 && glm::dot(error, scale) > tol; ++n) {
    const Cell c = queue.top();
    queue.pop();
    total -= c.value, error -= c.error;
    for (double side : {-0.5, 0.5}) {
      double cc[2] = {c.c[0], c.c[1]}, hh[2] = {c.h[0], c.h[1]};
      hh[c.axis] *= 0.5, cc[c.axis] += side * c.h[c.axis];
      Cell child = genz_malik(f, cc[0], cc[1], hh[0], hh[1]);
      child.key = glm::dot(child.error, scale);
      total += child.value, error += child.error;
      queue.push(child);
    }
  }
  return total;
}

}  // namespace

glm::dvec2 area_specular(const AreaLight& light, const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v,
                         double r, double tol) {
  const double alpha = r * r;
  return cubature(Integrand{&light, p, n, v, alpha * alpha, true}, tol);
}

glm::dvec2 hemisphere_specular(double n_dot_v, double r, double tol) {
  const double alpha = r * r;
  const glm::dvec3 v(std::sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
  return cubature(Integrand{nullptr, glm::dvec3(0.0), glm::dvec3(0.0, 0.0, 1.0), v, alpha * alpha, true}, tol);
}

double area_form_factor(const AreaLight& light, const glm::dvec3& p, const glm::dvec3& n, double tol) {
  return cubature(Integrand{&light, p, n, n, 0.0, false}, tol).x;
}

double polygon_form_factor(const std::vector<glm::dvec3>& poly, const glm::dvec3& n) {
  std::vector<glm::dvec3> clipped;  // Sutherland-Hodgman against the plane n.x = 0
  for (size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec3 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double za = glm::dot(n, a), zb = glm::dot(n, b);
    if (za >= 0.0) clipped.push_back(a);
    if ((za >= 0.0) != (zb >= 0.0)) clipped.push_back(a + za / (za - zb) * (b - a));
  }
  double sum = 0.0;
  for (size_t i = 0; i < clipped.size(); ++i) {
    const glm::dvec3 a = glm::normalize(clipped[i]), b = glm::normalize(clipped[(i + 1) % clipped.size()]);
    const glm::dvec3 c = glm::cross(a, b);
    const double s = glm::length(c);
    if (s > 0.0) sum += std::atan2(s, glm::dot(a, b)) * glm::dot(c, n) / s;
  }
  return std::max(0.0, sum / (2.0 * kPi));
}

std::vector<glm::dvec3> area_light_polygon(const AreaLight& rect, const glm::dvec3& p) {
  const glm::dvec3 c = rect.center - p;
  return {c - rect.u - rect.v, c - rect.u + rect.v, c + rect.u + rect.v, c + rect.u - rect.v};
}

}  // namespace pmr::ref
