// Linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt 2016) for rectangle and disk lights
// under the pbr BRDF (docs/SHADING.md): the table fitted at build time (pmr_ltc_gen, tools/ltc_gen.cpp,
// compiled in as kLtcTable; tests check the two agree bit for bit) and its lookup as the kernels compute
// it. The polygon integrals are the kernels' (cl/area_lights.h).
//
// The specular radiance of a one-sided Lambertian light of radiance L is L times the integral over the
// light's solid angle of F D Vis n.l. In the frame where n = +z and v lies in the xz-plane with
// positive x, two lobes are approximated, each by a clamped cosine seen through a linear map M (an
// LTC) and scaled by its exact hemispherical integral:
//   the lobe                D Vis n.l,              amplitude norm    = integral of D Vis n.l
//   the Fresnel-weighted    (1 - v.h)^5 D Vis n.l,  amplitude fresnel = integral of (1 - v.h)^5 D Vis n.l
// so that, with S(M, P) the LTC's share of the polygon P (the cosine integral of M^-1 P over pi),
//   specular ~ L (F0 (norm S(M_lobe, P) - fresnel S(M_fresnel, P)) + F90 fresnel S(M_fresnel, P)).
// A single shape for both parts was measured 29% RMS wrong for a dielectric (F0 = 0.04: at grazing views
// the Fresnel part dominates and is shaped differently); with two, 6.7% (tests/test_area_ltc.cpp).
//
// Table layout (kLtcTable, kLtcSize^2 nodes of kLtcNodeFloats floats):
//   node (i, j), i, j in [0, kLtcSize - 1], at kLtcNodeFloats * (j * kLtcSize + i):
//     i: n.v = 1 - (i / (N - 1))^2                          (i = 0: n.v = 1; i = N - 1: n.v = 0)
//     j: r = (sqrt(0.03) + (1 - sqrt(0.03)) j / (N - 1))^2   (j = 0: r = 0.03; j = N - 1: r = 1)
//   floats: [0..3] the lobe's M^-1 as (m00, m02, m20, m22), [4..7] the Fresnel-weighted lobe's,
//           [8] norm, [9] fresnel.
//   M^-1 = ( m00  0  m02 )
//          (  0   1   0  )     (normalized so that its middle entry is 1; an LTC does not depend on
//          ( m20  0  m22 )      the scale of M)
// Lookup (ltc_lookup, bilinear between nodes and clamped at the table's edges):
//   x = sqrt(1 - clamp(n.v, 0, 1)) (N - 1),  y = (sqrt(r) - kLtcSqrtRMin) / (1 - kLtcSqrtRMin) (N - 1),
//   each clamped to [0, N - 1]; i = min(int(x), N - 2), fx = x - i (same for y: j, fy); every float
//   f = (1 - fy) ((1 - fx) T(i, j) + fx T(i + 1, j)) + fy ((1 - fx) T(i, j + 1) + fx T(i + 1, j + 1)).
#pragma once
#include <vector>

#include <glm/glm.hpp>

namespace pmr {

constexpr int kLtcSize = 64;
constexpr int kLtcNodeFloats = 10;
constexpr float kLtcSqrtRMin = 0.17320508f;  // sqrt(0.03): the materials' least roughness

// M^-1 of one LTC (see the layout above).
struct LtcInverse {
  float m00, m02, m20, m22;
};

// What the table gives for (n.v, r).
struct LtcCoefficients {
  LtcInverse lobe, fresnel_lobe;
  float norm, fresnel;
};

// The bilinear lookup of kLtcTable, exactly as the kernels compute it.
LtcCoefficients ltc_lookup(float n_dot_v, float r);

// ---- the fit (host/shading/ltc_fit.cpp) ----------------------------------------------------------------

// Node (i, j) of the table (kLtcNodeFloats floats), fitted as described in ltc_fit.cpp.
void fit_ltc_node(int i, int j, float* out);

// The whole table (kLtcSize^2 nodes), rows fitted on `threads` threads (the result does not depend on it).
std::vector<float> compute_ltc_table(int threads);

// The build's copy of compute_ltc_table() (generated/ltc_table.cpp), and as a vector (what the kernels
// read: SceneBuffers uploads it).
extern const float kLtcTable[];
const std::vector<float>& ltc_table();

}  // namespace pmr
