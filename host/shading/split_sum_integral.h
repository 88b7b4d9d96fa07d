// The split-sum terms (A, B) of DESIGN section 4b's BRDF (Karis 2013): the table the environment
// lighting reads (split_sum_table, environment.h). The table is computed at build time by
// pmr_brdf_tables_gen (tools/brdf_tables_gen.cpp) from compute_split_sum_table and compiled in as
// kSplitSumTable; tests check the two agree bit for bit.
#pragma once
#include <vector>

#include <glm/glm.hpp>

namespace pmr {

// (A, B) for (dot(n, v), r): the integrals of F_0-weighted and F_0-free parts of D Vis n.l over the
// hemisphere, by importance sampling the GGX distribution at 8192 Hammersley points.
glm::dvec2 split_sum_integral(double n_dot_v, double r);

// The table: kEnvSplitSumSize^2 nodes (64^2) of (A, B), node (i, j) at 2 * (j * N + i) for
// dot(n, v) = (i / (N - 1))^2 and r = j / (N - 1).
std::vector<float> compute_split_sum_table();

// The build's copy of compute_split_sum_table() (generated/brdf_tables.cpp).
extern const float kSplitSumTable[];

}  // namespace pmr
