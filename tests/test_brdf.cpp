// The kernels' BRDF and punctual lights (cl/brdf.h, float) against the double-precision reference of the
// shading model (tests/reference/pbr_reference.cpp), and the reference against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "reference/pbr_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<float> run_probe(const char* kernel, const std::vector<float>& in, size_t per_case, size_t out_per_case) {
  const ClRuntime& rt = test::runtime();
  const ClProgram program = rt.build_program({"brdf_probe.cl"}, "-cl-std=CL1.2", &test_kernel_sources());
  const size_t n = in.size() / per_case;
  std::vector<float> out(n * out_per_case);
  {
    ClKernel k(program, kernel);
    ClBuffer a = rt.upload(in, "probe in"), b = rt.buffer(out.size() * 4, "probe out");
    k.args(a, b, cl_uint(n));
    clReleaseEvent(rt.launch(k, n, 64));
    rt.read(b, out.data(), out.size() * 4);
  }
  return out;
}

glm::dvec3 random_unit(std::mt19937& g) {
  std::normal_distribution<double> N;
  for (;;) {
    const glm::dvec3 v(N(g), N(g), N(g));
    if (glm::length(v) > 1e-3) return glm::normalize(v);
  }
}

glm::dvec3 as_float(const glm::dvec3& v) { return glm::dvec3(glm::vec3(v)); }

// Random inputs, mostly lit, two thirds with a KHR_materials_specular weight and colour; float kernel
// within 1e-3 relative (+1e-5 absolute) of the double reference evaluated on the same float inputs, for
// roughness >= 0.2 (the model's accuracy bound starts there).
TEST(Brdf, KernelMatchesTheReference) {
  std::mt19937 g(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<float> in;
  struct Case {
    glm::dvec3 base, n, v, l, specular_color{1.0};
    double metallic, r, specular = 1.0;
  };
  std::vector<Case> cases;
  for (int i = 0; i < 4000; ++i) {
    Case c;
    c.base = as_float(glm::dvec3(U(g), U(g), U(g)));
    c.metallic = float(i % 5 == 0 ? 1.0 : i % 5 == 1 ? 0.0 : U(g));
    c.r = float(0.2 + 0.8 * U(g));
    c.n = as_float(random_unit(g));
    glm::dvec3 v = random_unit(g), l = random_unit(g);
    if (i % 8 != 0) {  // most cases in front of the surface
      if (glm::dot(v, c.n) < 0) v = -v;
      if (glm::dot(l, c.n) < 0) l = -l;
    }
    if (i % 50 == 0) l = glm::reflect(-v, c.n);  // the specular peak
    c.v = as_float(v), c.l = as_float(l);
    if (i % 3 != 0) {  // KHR_materials_specular: a weight, a colour (up to 30, where min(0.04 c, 1) clips)
      c.specular = float(U(g));
      c.specular_color = as_float(glm::dvec3(U(g), U(g), U(g)) * (i % 3 == 1 ? 2.0 : 30.0));
    }
    cases.push_back(c);
    for (double x : {c.base.x, c.base.y, c.base.z, c.metallic, c.r, c.n.x, c.n.y, c.n.z, c.v.x, c.v.y, c.v.z, c.l.x,
                     c.l.y, c.l.z, c.specular, c.specular_color.x, c.specular_color.y, c.specular_color.z})
      in.push_back(float(x));
  }
  const std::vector<float> out = run_probe("brdf_probe", in, 18, 3);
  int lit = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const glm::dvec3 want =
        ref::brdf_cos(c.base, c.metallic, c.r, c.n, c.v, c.l, 1.5, 0.0, c.specular, c.specular_color);
    lit += want.x + want.y + want.z > 0.0;
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(out[3 * i + k], want[k], 1e-3 * std::fabs(want[k]) + 1e-5) << "case " << i << " channel " << k;
  }
  EXPECT_GT(lit, 3000);
}

// Closed forms of the reference: a metal at its specular peak seen head-on, a dielectric's diffuse
// part, and energy: the specular lobe of a white metal reflects at most what arrives, nearly all of it
// when smooth, less as it gets rougher (single scattering loses energy).
TEST(Brdf, ReferenceClosedForms) {
  const glm::dvec3 n(0, 0, 1);
  // head-on at the peak: f cos = F0 D(1) Vis(1, 1), D(1) = 1 / (pi alpha^2), Vis(1, 1) = 0.5 / 2
  for (double r : {0.2, 0.5, 1.0}) {
    const double alpha = r * r, a2 = alpha * alpha;
    const glm::dvec3 got = ref::brdf_cos(glm::dvec3(0.5, 0.7, 0.9), 1.0, r, n, n, n);
    EXPECT_NEAR(got.y, 0.7 / (kPi * a2) * 0.25, 1e-9 * got.y) << r;
  }
  // a white dielectric head-on, alpha 1: (1 - 0.04) / pi + 0.04 D(1) Vis(1, 1), D(1) = 1 / pi
  const glm::dvec3 d = ref::brdf_cos(glm::dvec3(1.0), 0.0, 1.0, n, n, n);
  EXPECT_NEAR(d.x, 0.96 / kPi + 0.04 / kPi * 0.25, 1e-12);
  double previous = 2.0;
  for (double r : {0.3, 0.6, 1.0}) {
    const glm::dvec3 v = glm::normalize(glm::dvec3(0.3, 0.0, 1.0));
    double sum = 0.0;
    const int M = 400;
    for (int a = 0; a < M; ++a)
      for (int b = 0; b < 2 * M; ++b) {
        const double theta = (a + 0.5) / M * kPi / 2, phi = (b + 0.5) / (2 * M) * 2 * kPi;
        const glm::dvec3 l(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        sum += ref::brdf_cos(glm::dvec3(1.0), 1.0, r, n, v, l).x * std::sin(theta) * (kPi / 2 / M) * (kPi / M);
      }
    EXPECT_LE(sum, 1.0 + 1e-3) << r;
    EXPECT_LT(sum, previous) << r;
    if (r < 0.5) {
      EXPECT_GT(sum, 0.9) << r;
    }
    previous = sum;
  }
}

// Lights: the kernel against the reference, and the reference against the stated falloffs.
TEST(Brdf, PunctualLights) {
  std::mt19937 g(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<ref::PunctualLight> lights;
  std::vector<glm::dvec3> points;
  std::vector<float> in;
  for (int i = 0; i < 600; ++i) {
    ref::PunctualLight L;
    L.type = ref::LightType(i % 3);
    L.color_intensity = as_float(glm::dvec3(U(g), U(g), U(g)) * 100.0);
    L.position = as_float(glm::dvec3(U(g), U(g), U(g)) * 4.0 - 2.0);
    L.direction = as_float(random_unit(g));
    L.range = float(i % 2 ? 0.0 : 1.0 + 5.0 * U(g));
    const double outer = 0.2 + 1.2 * U(g), inner = outer * U(g);
    L.cos_inner = float(std::cos(inner)), L.cos_outer = float(std::cos(outer));
    const glm::dvec3 p = as_float(L.position + L.direction * (0.5 + 2.0 * U(g)) + random_unit(g) * 0.7);
    lights.push_back(L);
    points.push_back(p);
    for (double x : {double(i % 3), L.color_intensity.x, L.color_intensity.y, L.color_intensity.z, L.position.x,
                     L.position.y, L.position.z, L.direction.x, L.direction.y, L.direction.z, L.range, L.cos_inner,
                     L.cos_outer, p.x, p.y, p.z, 0.0, 0.0})
      in.push_back(float(x));
  }
  const std::vector<float> out = run_probe("light_probe", in, 18, 6);
  for (size_t i = 0; i < lights.size(); ++i) {
    glm::dvec3 l;
    const glm::dvec3 E = ref::light_irradiance(lights[i], points[i], l);
    for (int k = 0; k < 3; ++k) {
      // the spot's cone factor is a difference of cosines: allow for float rounding there
      ASSERT_NEAR(out[6 * i + k], E[k], 2e-3 * std::fabs(E[k]) + 1e-4) << "light " << i;
      ASSERT_NEAR(out[6 * i + 3 + k], l[k], 1e-5) << "light " << i;
    }
  }
  // stated falloffs
  ref::PunctualLight point;
  point.type = ref::LightType::Point;
  point.color_intensity = glm::dvec3(10.0);
  glm::dvec3 l;
  EXPECT_NEAR(ref::light_irradiance(point, glm::dvec3(0, 0, -2), l).x, 10.0 / 4.0, 1e-12);
  EXPECT_NEAR(l.z, 1.0, 1e-12);
  point.range = 4.0;  // window 1 - (2/4)^4 = 15/16
  EXPECT_NEAR(ref::light_irradiance(point, glm::dvec3(0, 0, -2), l).x, 10.0 / 4.0 * 15.0 / 16.0, 1e-12);
  EXPECT_EQ(ref::light_irradiance(point, glm::dvec3(0, 0, -5), l).x, 0.0);
  ref::PunctualLight spot = point;
  spot.type = ref::LightType::Spot;
  spot.range = 0.0;
  spot.direction = glm::dvec3(0, 0, -1);
  spot.cos_inner = std::cos(0.2), spot.cos_outer = std::cos(0.4);
  EXPECT_NEAR(ref::light_irradiance(spot, glm::dvec3(0, 0, -2), l).x, 2.5, 1e-12);  // on the axis: full
  const glm::dvec3 outside(2 * std::sin(0.5), 0, -2 * std::cos(0.5));
  EXPECT_EQ(ref::light_irradiance(spot, outside, l).x, 0.0);
  const double a = 0.3;  // between the cones: ((cos a - cos outer) / (cos inner - cos outer))^2
  const double s = (std::cos(a) - spot.cos_outer) / (spot.cos_inner - spot.cos_outer);
  EXPECT_NEAR(ref::light_irradiance(spot, glm::dvec3(std::sin(a), 0, -std::cos(a)), l).x, 10.0 * s * s, 1e-9);
}

}  // namespace
}  // namespace pmr
