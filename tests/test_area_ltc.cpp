// Rectangle and disk lights by linearly transformed cosines (host/shading/ltc.h, cl/area_lights.h) against
// the double-precision reference (tests/reference/area_light_reference.h): the table is the build's fit
// bit for bit, its amplitudes are the hemispherical integrals, and the kernels' specular radiance over a
// fixed set of lights (tests/area_light_probe.h) is within stated RMS errors.
//
// Relative error, as measured here: for each (n.v, r) and material, over the lights of the set whose
// reference is at least a fraction T of the largest reference of that (n.v, r) and material,
// e = (LTC - reference) / reference; RMS of e over all of them. T = 10% ("the visible highlight") and
// T = 1% (down into the lobe's tails, where an LTC cannot follow GGX at grazing views). For scale: the
// best single LTC for each (n.v, r), fitted to this very set of lights by Nelder-Mead on this very
// measure, is 5.1% (T = 10%) and 12.9% (T = 1%) RMS for a metal; the table's, 6.6% and 24%.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "area_light_probe.h"
#include "reference/area_light_reference.h"
#include "shading/ltc.h"
#include "shading/split_sum_integral.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A fixed rotation of the whole scene, so that n, v and the lights are in no special position.
glm::dvec3 rotate(const glm::dvec3& x) {
  const glm::dvec3 a = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
  const double angle = 0.9;
  return x * std::cos(angle) + glm::cross(a, x) * std::sin(angle) + a * glm::dot(a, x) * (1.0 - std::cos(angle));
}

glm::dvec3 turn(const glm::dvec3& x, const glm::dvec3& axis, double angle) {
  const glm::dvec3 a = glm::normalize(axis);
  return x * std::cos(angle) + glm::cross(a, x) * std::sin(angle) + a * glm::dot(a, x) * (1.0 - std::cos(angle));
}

glm::dvec3 direction(double theta_deg, double phi_deg) {
  const double t = theta_deg * kPi / 180.0, p = phi_deg * kPi / 180.0;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// One light of the set, in the frame n = +z, v = (sqrt(1 - nv^2), 0, nv) before `rotate`.
struct Case {
  double nv, r;
  ref::AreaLight light;
  glm::dvec2 reference{0.0};  // (integral of D Vis n.l, of its Fresnel-weighted part) over the light
  glm::dvec2 kernel{0.0};     // the same by the kernels' LTCs (compute_kernels)
};

// The lights for one (n.v, r): 14 centers (the normal; 35 and 70 degrees from it at 4 azimuths; the
// mirror direction; 4 points one light radius away from it), 3 angular radii (0.06, 0.2, 0.45 rad) at
// distance 1 or 2.5, a rectangle (1 : 1 facing the point, or 1 : 2 turned 50 degrees away) and a disk:
// 84 lights. Some straddle the horizon; some lie below it (reference 0, left out).
std::vector<Case> light_set(double nv, double r) {
  const glm::dvec3 R(-std::sqrt(1.0 - nv * nv), 0.0, nv);
  std::vector<glm::dvec3> centers = {{0.0, 0.0, 1.0}, R};
  for (double theta : {35.0, 70.0})
    for (double phi : {20.0, 110.0, 200.0, 290.0}) centers.push_back(direction(theta, phi));
  std::vector<Case> cases;
  for (double rho : {0.06, 0.2, 0.45}) {
    std::vector<glm::dvec3> cs = centers;
    const glm::dvec3 across = glm::normalize(glm::cross(R, glm::dvec3(0.0, 1.0, 0.0)));
    for (const glm::dvec3& axis : {across, -across, glm::dvec3(0.0, 1.0, 0.0), glm::dvec3(0.0, -1.0, 0.0)})
      cs.push_back(turn(R, axis, rho));
    for (size_t k = 0; k < cs.size(); ++k)
      for (bool disk : {false, true}) {
        const glm::dvec3 d = glm::normalize(cs[k]);
        const double distance = k % 3 == 0 ? 2.5 : 1.0, extent = distance * std::tan(rho);
        glm::dvec3 a = glm::normalize(glm::cross(d, std::abs(d.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0)));
        a = turn(a, d, 0.3);
        glm::dvec3 b = glm::cross(a, d);  // (a, b) spans the plane facing the point: cross(a, b) = -d
        double ea = extent;
        if (k % 2 == 1) {  // turned 50 degrees about b, and a 1 : 2 rectangle
          a = turn(a, b, 50.0 * kPi / 180.0);
          if (!disk) ea *= 0.5;
        }
        ref::AreaLight light;
        light.disk = disk, light.center = rotate(distance * d), light.u = rotate(a * ea), light.v = rotate(b * extent);
        cases.push_back({nv, r, light});
      }
  }
  return cases;
}

// The references of all cases, on two threads.
void compute_references(std::vector<Case>& cases) {
  const glm::dvec3 n = rotate(glm::dvec3(0.0, 0.0, 1.0));
  auto work = [&](size_t first) {
    for (size_t k = first; k < cases.size(); k += 2) {
      const Case& c = cases[k];
      const glm::dvec3 v = rotate(glm::dvec3(std::sqrt(1.0 - c.nv * c.nv), 0.0, c.nv));
      cases[k].reference = ref::area_specular(c.light, glm::dvec3(0.0), n, v, c.r, 1e-4);
    }
  };
  std::thread other(work, 1);
  work(0);
  other.join();
}

// The kernels' (lobe, Fresnel part) for every case (cl/area_lights.h through tests/area_light_probe.h):
// the integrals over the light of D Vis n.l and of (1 - v.h)^5 D Vis n.l by the two LTCs.
void compute_kernels(std::vector<Case>& cases) {
  const glm::dvec3 n = rotate(glm::dvec3(0.0, 0.0, 1.0));
  std::vector<PmrLight> lights;
  std::vector<test::AreaProbePoint> at;
  for (const Case& c : cases) {
    PmrLight l{};
    l.type = c.light.disk ? PMR_LIGHT_DISK : PMR_LIGHT_RECT;
    const glm::dvec3 toward = glm::normalize(glm::cross(c.light.u, c.light.v));  // where it emits
    for (int k = 0; k < 3; ++k)
      l.position[k] = float(c.light.center[k]), l.direction[k] = float(toward[k]),
      l.half_width[k] = float(c.light.u[k]), l.half_height[k] = float(c.light.v[k]);
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    at.push_back(
        {int(lights.size()), glm::dvec3(0.0), n, rotate(glm::dvec3(std::sqrt(1.0 - c.nv * c.nv), 0.0, c.nv)), c.r});
    lights.push_back(l);
  }
  const std::vector<test::AreaProbeResult> got = test::probe_area_lights(lights, at);
  for (size_t k = 0; k < cases.size(); ++k) cases[k].kernel = {got[k].lobe, got[k].schlick};
}

// RMS relative errors, overall and per band of n.v and of r.
struct Errors {
  double sum2 = 0.0, count = 0.0;
  void add(double e) { sum2 += e * e, count += 1.0; }
  double rms() const { return count > 0.0 ? std::sqrt(sum2 / count) : 0.0; }
};

// The errors of a set of cases, over rectangles, disks or both (`shapes`: 1, 2, 3).
struct Report {
  std::vector<double> nv_bands, r_bands;  // lower edges
  int shapes = 3;
  Errors all[2][2];  // [metal, dielectric][T = 10%, 1%]
  std::vector<Errors> band[2][2];

  int band_of(const std::vector<double>& edges, double x) const {
    int b = 0;
    while (b + 1 < int(edges.size()) && x >= edges[size_t(b) + 1]) ++b;
    return b;
  }

  // Adds one (n.v, r) group of cases.
  void add(const std::vector<Case>& group) {
    for (int m = 0; m < 2; ++m) {
      const double f0 = m == 0 ? 1.0 : 0.04;  // metal (F0 = F90 = 1) or dielectric (0.04, 1)
      double largest = 0.0;
      for (const Case& c : group) largest = std::max(largest, f0 * (c.reference.x - c.reference.y) + c.reference.y);
      for (const Case& c : group) {
        if (!(shapes & (c.light.disk ? 2 : 1))) continue;
        const double want = f0 * (c.reference.x - c.reference.y) + c.reference.y;
        const glm::dvec2 got = c.kernel;
        const double e = (f0 * (got.x - got.y) + got.y - want) / want;
        const size_t cell = size_t(band_of(nv_bands, c.nv)) * r_bands.size() + size_t(band_of(r_bands, c.r));
        for (int t = 0; t < 2; ++t) {
          if (band[m][t].empty()) band[m][t].resize(nv_bands.size() * r_bands.size());
          if (want >= (t == 0 ? 0.1 : 0.01) * largest && want > 0.0) all[m][t].add(e), band[m][t][cell].add(e);
        }
      }
    }
  }

  void print(const char* title) const {
    std::printf("[ ltc      ] %s: RMS relative error, metal | dielectric, T = 10%% (T = 1%%)\n", title);
    std::printf("[ ltc      ]   all: %5.1f%% (%5.1f%%) | %5.1f%% (%5.1f%%)   over %.0f (%.0f) lights\n",
                100 * all[0][0].rms(), 100 * all[0][1].rms(), 100 * all[1][0].rms(), 100 * all[1][1].rms(),
                all[0][0].count, all[0][1].count);
    for (size_t i = 0; i < nv_bands.size(); ++i)
      for (size_t j = 0; j < r_bands.size(); ++j) {
        const size_t c = i * r_bands.size() + j;
        std::printf("[ ltc      ]   n.v >= %.2f, r >= %.2f: %5.1f%% (%5.1f%%) | %5.1f%% (%5.1f%%)\n", nv_bands[i],
                    r_bands[j], 100 * band[0][0][c].rms(), 100 * band[0][1][c].rms(), 100 * band[1][0][c].rms(),
                    100 * band[1][1][c].rms());
      }
  }
};

// The cases of light_set for every (n.v, r), with their references.
std::vector<Case> cases_for(const std::vector<double>& nvs, const std::vector<double>& rs) {
  std::vector<Case> cases;
  for (double nv : nvs)
    for (double r : rs) {
      const std::vector<Case> group = light_set(nv, r);
      cases.insert(cases.end(), group.begin(), group.end());
    }
  compute_references(cases);
  compute_kernels(cases);
  return cases;
}

Report report_of(const std::vector<Case>& cases, std::vector<double> nv_bands, std::vector<double> r_bands,
                 int shapes = 3) {
  Report report{std::move(nv_bands), std::move(r_bands), shapes, {}, {}};
  const size_t per_group = light_set(0.5, 0.5).size();
  for (size_t g = 0; g < cases.size(); g += per_group)
    report.add(std::vector<Case>(cases.begin() + long(g), cases.begin() + long(g + per_group)));
  return report;
}

// ---- the table ------------------------------------------------------------------------------------------

// The table compiled in at build time is the fit's, bit for bit (hexadecimal float literals), at nodes
// spread over it (the whole fit takes seconds; every node is fitted on its own, so any node can be
// checked alone).
TEST(AreaLtc, BuiltInTableIsTheFit) {
  const int last = kLtcSize - 1;
  for (const auto& [i, j] : std::vector<std::pair<int, int>>{
           {0, 0}, {last, last}, {0, last}, {last, 0}, {20, 31}, {45, 10}, {7, 55}, {62, 3}}) {
    float node[kLtcNodeFloats];
    fit_ltc_node(i, j, node);
    for (int k = 0; k < kLtcNodeFloats; ++k)
      EXPECT_EQ(node[k], kLtcTable[kLtcNodeFloats * (j * kLtcSize + i) + k])
          << "node " << i << ", " << j << " float " << k;
  }
}

// At a node the lookup returns the node (up to the rounding of its coordinates); out of range it clamps.
TEST(AreaLtc, LookupAtNodesAndEdges) {
  for (const auto& [i, j] : std::vector<std::pair<int, int>>{{0, 0}, {10, 20}, {40, 63}, {63, 5}}) {
    const double u = double(i) / (kLtcSize - 1), s = 0.17320508 + (1.0 - 0.17320508) * double(j) / (kLtcSize - 1);
    const LtcCoefficients c = ltc_lookup(float(1.0 - u * u), float(s * s));
    const float* node = kLtcTable + kLtcNodeFloats * (j * kLtcSize + i);
    const float got[kLtcNodeFloats] = {
        c.lobe.m00,         c.lobe.m02,         c.lobe.m20,         c.lobe.m22, c.fresnel_lobe.m00,
        c.fresnel_lobe.m02, c.fresnel_lobe.m20, c.fresnel_lobe.m22, c.norm,     c.fresnel};
    for (int k = 0; k < kLtcNodeFloats; ++k)
      EXPECT_NEAR(got[k], node[k], 2e-3 * (std::abs(node[k]) + 1e-3)) << "node " << i << ", " << j << " float " << k;
  }
  const LtcCoefficients a = ltc_lookup(1.5f, 0.01f), b = ltc_lookup(1.0f, 0.03f);
  EXPECT_EQ(a.norm, b.norm);
  EXPECT_EQ(a.lobe.m22, b.lobe.m22);
  const LtcCoefficients c = ltc_lookup(-0.2f, 1.2f), d = ltc_lookup(0.0f, 1.0f);
  EXPECT_EQ(c.fresnel, d.fresnel);
  EXPECT_EQ(c.fresnel_lobe.m00, d.fresnel_lobe.m00);
}

// The amplitudes are the hemispherical integrals of D Vis n.l and of its Fresnel-weighted part: at the
// nodes within 2e-5 of the lobe's (the fit's quadrature); between them, bilinear, within 0.5% from
// n.v = 0.1 on (below, at low roughness, the lobe's integral drops fast toward n.v = 0).
TEST(AreaLtc, AmplitudesAreTheHemisphericalIntegrals) {
  for (const auto& [i, j] : std::vector<std::pair<int, int>>{{0, 0}, {0, 63}, {30, 10}, {55, 40}, {62, 5}, {63, 63}}) {
    const double u = double(i) / (kLtcSize - 1),
                 s = std::sqrt(0.03) + (1.0 - std::sqrt(0.03)) * double(j) / (kLtcSize - 1);
    const glm::dvec2 want = ref::hemisphere_specular(1.0 - u * u, s * s, 1e-9);
    const float* node = kLtcTable + kLtcNodeFloats * (j * kLtcSize + i);
    EXPECT_NEAR(node[8], want.x, 2e-5 * want.x) << "node " << i << ", " << j;
    EXPECT_NEAR(node[9], want.y, 2e-5 * want.x) << "node " << i << ", " << j;
  }
  double worst = 0.0, worst_grazing = 0.0;
  for (double nv : {0.02, 0.05, 0.1, 0.2, 0.5, 0.8, 1.0})
    for (double r : {0.03, 0.1, 0.3, 0.6, 1.0}) {
      const glm::dvec2 want = ref::hemisphere_specular(nv, r, 1e-7);
      const LtcCoefficients c = ltc_lookup(float(nv), float(r));
      const double e = std::max(std::abs(c.norm - want.x), std::abs(c.fresnel - want.y)) / want.x;
      double& w = nv < 0.1 ? worst_grazing : worst;
      w = std::max(w, e);
      if (nv >= 0.1) {
        EXPECT_LE(e, 0.005) << "n.v " << nv << " r " << r << ": " << c.norm << ", " << c.fresnel << " vs " << want.x;
      }
    }
  std::printf("[ ltc      ] amplitudes between nodes: worst error %.2g of norm from n.v = 0.1 on, %.2g below\n", worst,
              worst_grazing);
}

// ---- the specular radiance --------------------------------------------------------------------------------

// 64 (n.v, r) with n.v in [0.1, 1] and r in [0.1, 1], off the table's nodes, 84 lights each (light_set).
TEST(AreaLtc, SpecularAgainstBruteForce) {
  const std::vector<Case> cases =
      cases_for({0.1, 0.2, 0.3, 0.45, 0.6, 0.75, 0.9, 1.0}, {0.1, 0.18, 0.25, 0.35, 0.5, 0.65, 0.8, 1.0});
  const Report report = report_of(cases, {0.1, 0.3, 0.6, 0.9}, {0.1, 0.3, 0.6});
  report.print("n.v in [0.1, 1], r in [0.1, 1], disks as 16-gons");
  EXPECT_LE(report.all[0][0].rms(), 0.08);  // metal, T = 10%
  EXPECT_LE(report.all[1][0].rms(), 0.08);  // dielectric
  EXPECT_LE(report.all[0][1].rms(), 0.35);  // T = 1%
  EXPECT_LE(report.all[1][1].rms(), 0.25);
  report_of(cases, {0.1}, {0.1}, 1).print("rectangles only");
  report_of(cases, {0.1}, {0.1, 0.3, 0.6}, 2).print("disks only, as 16-gons");
}

// Below r = 0.1 (the materials' floor is 0.03): the highlight is smaller than most lights, and where it
// falls on a disk's rim the polygon's outline shows.
TEST(AreaLtc, SpecularLowRoughness) {
  const std::vector<Case> cases = cases_for({0.1, 0.2, 0.3, 0.45, 0.6, 0.75, 0.9, 1.0}, {0.03, 0.05, 0.07});
  const Report rects = report_of(cases, {0.1, 0.3, 0.6, 0.9}, {0.03}, 1), disks = report_of(cases, {0.1}, {0.03}, 2);
  rects.print("n.v in [0.1, 1], r in [0.03, 0.07], rectangles");
  disks.print("disks as 16-gons");
  EXPECT_LE(rects.all[0][0].rms(), 0.05);
  EXPECT_LE(rects.all[1][0].rms(), 0.05);
  EXPECT_LE(disks.all[0][0].rms(), 0.35);
}

// A light seen from behind gives no specular; one across the whole sky (all but the last 0.06 degrees
// above the horizon) gives the lobe's amplitude, less the LTC's little share below the horizon.
TEST(AreaLtc, SpecularLimits) {
  const glm::dvec3 n(0.0, 0.0, 1.0), v(0.6, 0.0, 0.8);
  auto rect = [](glm::vec3 center, glm::vec3 u, glm::vec3 w) {
    PmrLight l{};
    l.type = PMR_LIGHT_RECT;
    const glm::vec3 toward = glm::normalize(glm::cross(u, w));
    for (int k = 0; k < 3; ++k)
      l.position[k] = center[k], l.direction[k] = toward[k], l.half_width[k] = u[k], l.half_height[k] = w[k];
    return l;
  };
  const std::vector<PmrLight> lights = {
      rect({-0.6f, 0.0f, 0.8f}, {0.3f, 0.0f, 0.0f}, {0.0f, 0.3f, 0.0f}),  // emits upward
      rect({0.0f, 0.0f, 1.0f}, {0.0f, 1e3f, 0.0f}, {1e3f, 0.0f, 0.0f})};
  const std::vector<test::AreaProbeResult> got =
      test::probe_area_lights(lights, {{0, glm::dvec3(0.0), n, v, 0.4}, {1, glm::dvec3(0.0), n, v, 0.4}});
  EXPECT_EQ(got[0].lobe, 0.0);
  EXPECT_EQ(got[0].cosine, 0.0);
  const LtcCoefficients c = ltc_lookup(0.8f, 0.4f);
  EXPECT_NEAR(got[1].lobe, c.norm, 0.01 * c.norm);
  EXPECT_NEAR(got[1].cosine, 3.14159265358979, 0.01);  // the whole hemisphere: pi
}

}  // namespace
}  // namespace pmr
