// Linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt 2016) for rectangle and disk lights
// under the pbr BRDF (docs/SHADING.md): the table fitted at build time (pmr_ltc_gen, tools/ltc_gen.cpp,
// compiled in as kLtcTable; tests check the two agree bit for bit), its lookup, and the polygon
// integrals, written as scalar float code that the kernels mirror line by line.
//
// The specular radiance of a one-sided Lambertian light of radiance L is L times the integral over the
// light's solid angle of F D Vis n.l. In the frame where n = +z and v lies in the xz-plane with
// positive x, two lobes are approximated, each by a clamped cosine seen through a linear map M (an
// LTC) and scaled by its exact hemispherical integral:
//   the lobe                D Vis n.l,              amplitude norm    = integral of D Vis n.l
//   the Fresnel-weighted    (1 - v.h)^5 D Vis n.l,  amplitude fresnel = integral of (1 - v.h)^5 D Vis n.l
// so that, with S(M, P) the LTC's share of the polygon P (ltc_polygon_integral),
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
// The most vertices a light polygon has here (a disk's 32-gon; a clipped one has one more). A kernel
// that only draws rectangles and 16-gons needs arrays of 17.
constexpr int kLtcMaxVertices = 32;

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

// The form factor (the integral of z over the solid angle / pi) of the spherical polygon with the
// `count` (3..kLtcMaxVertices + 1) vertices (x[k], y[k], z[k]) relative to the point, all with z >= 0
// (clip first: below z = 0 the formula counts z negative): Lambert's formula, the sum over edges of
// acos(a.b) normalize(a x b).z / (2 pi), with acos(d) / sin(acos(d)) from ltc_theta_over_sin. Positive
// for a polygon whose vertices turn clockwise seen from the point (the order of rect_light_polygon and
// disk_light_polygon seen from the emitting side), negative seen from behind. The arrays are
// overwritten (the vertices are normalized in place). Every edge must span less than 180 degrees: a
// light that fills almost a whole hemisphere seen from the point (which, clipped, has two nearly
// opposite vertices) comes out wrong.
float ltc_form_factor(float* x, float* y, float* z, int count);

// acos(d) / sqrt(1 - d^2) for d in [-1, 1] (1 at d = 1): a (2, 2) rational fitted on [0, 1] (relative
// error below 6e-7), and pi / sqrt(1 - d^2) - f(-d) below 0 (1 - d^2 at least 1e-7 there; from d = -0.9
// on, 8e-7 in float, then 1 - d^2 loses digits toward d = -1).
float ltc_theta_over_sin(float d);

// S(M, P): the share of the LTC with inverse minv in the polygon of `count` (3..kLtcMaxVertices) vertices
// (x[k], y[k], z[k]) relative to the shading point in the frame of n = +z, v in the xz-plane: the
// vertices transformed by minv, clipped to z >= 0 (Sutherland-Hodgman), integrated by ltc_form_factor.
// Signed as ltc_form_factor.
float ltc_polygon_integral(const LtcInverse& minv, const float* x, const float* y, const float* z, int count);

// The specular radiance per unit light radiance: F0 (norm S_lobe - fresnel S_fresnel) + F90 fresnel
// S_fresnel, each S at least 0 (a one-sided light), for the unit normal n, the unit direction to the
// eye v, the light polygon's `count` (3..kLtcMaxVertices) vertices relative to the shading point (world space),
// the clamped roughness r in [0.03, 1] and the Fresnel terms F0 (rgb), F90.
glm::vec3 ltc_specular(const glm::vec3& n, const glm::vec3& v, const glm::vec3* polygon, int count, float r,
                       const glm::vec3& f0, float f90);

// The form factor of the polygon (vertices relative to the point, world space) above the horizon of the
// unit normal n: the integral of n.l > 0 over its solid angle divided by pi, at least 0 (pi not
// included: a Lambertian surface of albedo c under a light of radiance L sends back c L times this).
float polygon_irradiance(const glm::vec3& n, const glm::vec3* polygon, int count);

// The rectangle center + a u + b v (|a|, |b| <= 1, u and v its half extents), emitting toward
// cross(u, v): its 4 corners in the winding ltc_form_factor counts positive in front. Returns 4.
int rect_light_polygon(const glm::vec3& center, const glm::vec3& u, const glm::vec3& v, glm::vec3* out);

// The disk center + a u + b v (a^2 + b^2 <= 1; u, v orthogonal, as long as the radius), emitting
// toward cross(u, v), as the regular polygon of `sides` (3..kLtcMaxVertices) vertices and the disk's
// area: radius x sqrt((2 pi / sides) / sin(2 pi / sides)), 1.0130 for 16 (an inscribed 16-gon has 2.5%
// less area and reads 2.5% low wherever the lobe is smooth across the disk). 16 sides are within 0.5% of
// the disk's irradiance; a glossy highlight on the disk's rim needs more (tests/test_area_ltc.cpp: RMS
// 5.6% for 16 sides, 1.9% for 32 at r in [0.1, 0.25]). Returns `sides`.
int disk_light_polygon(const glm::vec3& center, const glm::vec3& u, const glm::vec3& v, int sides, glm::vec3* out);

// ---- the fit (host/shading/ltc_fit.cpp) ----------------------------------------------------------------

// Node (i, j) of the table (kLtcNodeFloats floats), fitted as described in ltc_fit.cpp.
void fit_ltc_node(int i, int j, float* out);

// The whole table (kLtcSize^2 nodes), rows fitted on `threads` threads (the result does not depend on it).
std::vector<float> compute_ltc_table(int threads);

// The build's copy of compute_ltc_table() (generated/ltc_table.cpp).
extern const float kLtcTable[];

}  // namespace pmr
