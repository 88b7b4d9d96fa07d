// The LTC lookup and polygon integrals (see the header): plain scalar float code, so that the kernels'
// OpenCL C can mirror it line by line.
#include "shading/ltc.h"

#include <algorithm>
#include <cmath>

namespace pmr {

namespace {

constexpr float kPiF = 3.14159265f;

// Sutherland-Hodgman against z >= 0: a convex polygon of n vertices keeps at most n + 1. The new
// vertices lie exactly on z = 0.
int clip_to_upper_hemisphere(const float* x, const float* y, const float* z, int n, float* ox, float* oy, float* oz) {
  int m = 0;
  for (int k = 0; k < n; ++k) {
    const int l = k + 1 == n ? 0 : k + 1;
    const bool in_k = z[k] >= 0.0f, in_l = z[l] >= 0.0f;
    if (in_k) ox[m] = x[k], oy[m] = y[k], oz[m] = z[k], ++m;
    if (in_k != in_l) {
      const float t = z[k] / (z[k] - z[l]);
      ox[m] = x[k] + t * (x[l] - x[k]), oy[m] = y[k] + t * (y[l] - y[k]), oz[m] = 0.0f, ++m;
    }
  }
  return m;
}

// The tangent t of the frame (t, cross(n, t), n): v's direction in the surface's plane; at normal
// incidence (where the isotropic table does not care) any direction perpendicular to n.
glm::vec3 view_tangent(const glm::vec3& n, const glm::vec3& v) {
  glm::vec3 t = v - n * glm::dot(n, v);
  float t2 = glm::dot(t, t);
  if (t2 < 1e-12f) {
    t = std::fabs(n.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    t = t - n * glm::dot(n, t);
    t2 = glm::dot(t, t);
  }
  return t * (1.0f / std::sqrt(t2));
}

}  // namespace

float ltc_theta_over_sin(float d) {
  // acos(y) / sqrt(1 - y^2) on [0, 1] as (2, 2) rational fitted for the least maximum relative error
  // (5.6e-7 against the double function); for d < 0, acos(d) = pi - acos(-d).
  const float y = std::fabs(d);
  const float f =
      (1.57079545f + (0.905808336f + 0.0260317397f * y) * y) / (1.0f + (1.21323557f + 0.289398566f * y) * y);
  return d >= 0.0f ? f : kPiF / std::sqrt(std::fmax(1.0f - d * d, 1e-7f)) - f;
}

float ltc_form_factor(float* x, float* y, float* z, int count) {
  for (int k = 0; k < count; ++k) {
    const float s = 1.0f / std::sqrt(x[k] * x[k] + y[k] * y[k] + z[k] * z[k]);
    x[k] *= s, y[k] *= s, z[k] *= s;
  }
  float sum = 0.0f;
  for (int k = 0; k < count; ++k) {
    const int l = k + 1 == count ? 0 : k + 1;
    const float d = x[k] * x[l] + y[k] * y[l] + z[k] * z[l];
    sum += ltc_theta_over_sin(d) * (x[k] * y[l] - y[k] * x[l]);  // acos(d) normalize(a x b).z
  }
  return sum * (1.0f / (2.0f * kPiF));
}

float ltc_polygon_integral(const LtcInverse& minv, const float* x, const float* y, const float* z, int count) {
  float tx[kLtcMaxVertices], ty[kLtcMaxVertices], tz[kLtcMaxVertices];
  for (int k = 0; k < count; ++k) {
    tx[k] = minv.m00 * x[k] + minv.m02 * z[k];
    ty[k] = y[k];
    tz[k] = minv.m20 * x[k] + minv.m22 * z[k];
  }
  float cx[kLtcMaxVertices + 1], cy[kLtcMaxVertices + 1], cz[kLtcMaxVertices + 1];
  const int m = clip_to_upper_hemisphere(tx, ty, tz, count, cx, cy, cz);
  return m < 3 ? 0.0f : ltc_form_factor(cx, cy, cz, m);
}

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

glm::vec3 ltc_specular(const glm::vec3& n, const glm::vec3& v, const glm::vec3* polygon, int count, float r,
                       const glm::vec3& f0, float f90) {
  const glm::vec3 t = view_tangent(n, v), b = glm::cross(n, t);
  float x[kLtcMaxVertices], y[kLtcMaxVertices], z[kLtcMaxVertices];
  for (int k = 0; k < count; ++k)
    x[k] = glm::dot(t, polygon[k]), y[k] = glm::dot(b, polygon[k]), z[k] = glm::dot(n, polygon[k]);
  const LtcCoefficients c = ltc_lookup(glm::dot(n, v), r);
  const float lobe = c.norm * std::fmax(ltc_polygon_integral(c.lobe, x, y, z, count), 0.0f);
  const float fresnel = c.fresnel * std::fmax(ltc_polygon_integral(c.fresnel_lobe, x, y, z, count), 0.0f);
  return f0 * (lobe - fresnel) + f90 * fresnel;
}

float polygon_irradiance(const glm::vec3& n, const glm::vec3* polygon, int count) {
  const glm::vec3 t = view_tangent(n, n), b = glm::cross(n, t);
  float x[kLtcMaxVertices], y[kLtcMaxVertices], z[kLtcMaxVertices];
  for (int k = 0; k < count; ++k)
    x[k] = glm::dot(t, polygon[k]), y[k] = glm::dot(b, polygon[k]), z[k] = glm::dot(n, polygon[k]);
  float cx[kLtcMaxVertices + 1], cy[kLtcMaxVertices + 1], cz[kLtcMaxVertices + 1];
  const int m = clip_to_upper_hemisphere(x, y, z, count, cx, cy, cz);
  return m < 3 ? 0.0f : std::fmax(ltc_form_factor(cx, cy, cz, m), 0.0f);
}

int rect_light_polygon(const glm::vec3& center, const glm::vec3& u, const glm::vec3& v, glm::vec3* out) {
  out[0] = center - u - v, out[1] = center - u + v, out[2] = center + u + v, out[3] = center + u - v;
  return 4;
}

int disk_light_polygon(const glm::vec3& center, const glm::vec3& u, const glm::vec3& v, int sides, glm::vec3* out) {
  const float step = 2.0f * kPiF / float(sides), scale = std::sqrt(step / std::sin(step));  // equal area
  for (int k = 0; k < sides; ++k) {
    const float a = -step * float(k);  // clockwise from u toward -v, as the rectangle's corners
    out[k] = center + scale * (std::cos(a) * u + std::sin(a) * v);
  }
  return sides;
}

}  // namespace pmr
