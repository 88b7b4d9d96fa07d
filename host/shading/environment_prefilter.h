// Prefiltering an environment image into the tables that environment.h describes. Kept apart from the
// rest of the environment code because the build runs it too: pmr_studio_gen (tools/studio_gen.cpp)
// prefilters the built-in studio once, at build time.
#pragma once
#include "shading/environment.h"

namespace pmr {

// The tables of an image that check_environment_image accepted (no timing, no checks).
EnvironmentTables prefilter_environment(const EnvironmentImage& image);

// The tables of the uniform environment of `radiance`: every level 1x1.
EnvironmentTables uniform_environment_tables(float radiance);

// A lookup in a level of the tables (W x H texels and its pole rows, environment.h): bilinear, wrapping
// in u, v clamped half a texel beyond the outer rows' centers.
glm::dvec3 environment_level_bilinear(const float* level, int W, int H, double u, double v);

}  // namespace pmr
