// KHR_materials_sheen's lobe on the host (docs/SHADING.md, "Sheen"): the Charlie distribution and
// visibility of the extension's implementation notes in double precision, the lobe's directional
// albedo E(n.v, r) that scales the layers beneath it, and the table of E the kernels read. The kernels'
// float version is cl/brdf.h; the environment's Charlie-prefiltered levels (environment_prefilter.cpp)
// weigh with sheen_lobe_cos.
//
// With alpha = r^2 (r the sheen roughness, clamped to [kSheenMinRoughness, 1]):
//   D(h) = (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi)
//   V = 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 n.v n.l), Lambda the Estevez-Kulla fit
//   f_sheen n.l = sheenColor D V n.l
// E(n.v, r) = integral over the hemisphere of D V n.l dl (sheenColor 1), n.v raised to kSheenMinCos as
// the lobe reads it. A kSheenAlbedoSize^2 table
// at n.v = (i / (N - 1))^2 and r = kSheenMinRoughness + (1 - kSheenMinRoughness) j / (N - 1), node
// (i, j) at j * N + i, bilinear in (sqrt(n.v), r): computed at build time (pmr_brdf_tables_gen) by a
// midpoint rule over the half vector.
#pragma once
#include <vector>

#include "pmr/shared.h"

namespace pmr {

// The sheen roughness floor: the Charlie lobe of a smaller roughness is a ring thinner than the
// environment's levels resolve (docs/SHADING.md). three.js clamps at the same value.
constexpr double kSheenMinRoughness = PMR_SHEEN_MIN_ROUGHNESS;
constexpr int kSheenAlbedoSize = PMR_SHEEN_ALBEDO_N;
// n.v is read at least this (PMR_SHEEN_MIN_COS): at n.v = 0 exactly V's clamp at 1 takes over (the
// Lambda fit times n.v only tends to 0 below n.v = 1e-10), and the lobe and its albedo would jump to
// 1.2 to 2.4 times their values just above, on every shading normal facing away.
constexpr double kSheenMinCos = double(PMR_SHEEN_MIN_COS);

// r clamped to [kSheenMinRoughness, 1] (non-finite: 1).
double sheen_roughness(double r);

// D V n.l of the Charlie lobe for the cosines n.v (raised to kSheenMinCos), n.l and n.h and the clamped
// roughness r; 0 where n.l is not positive.
double sheen_lobe_cos(double nv, double nl, double nh, double r);

// E(n.v, r) by a midpoint rule over the half vector (the table's nodes).
double sheen_albedo_integral(double n_dot_v, double r);

// The table of E (see above), and its bilinear lookup as the kernels do it (arguments clamped); the
// build's table and its lookup are in environment.cpp, beside the split-sum table's.
std::vector<float> compute_sheen_albedo_table();
const std::vector<float>& sheen_albedo_table();
double sheen_albedo(double n_dot_v, double r);

// The build's copy of compute_sheen_albedo_table() (generated/brdf_tables.cpp).
extern const float kSheenAlbedoTable[];

}  // namespace pmr
