// The built-in studio environment (docs/SHADING.md, "Environment"): a procedural room, generated in code,
// so that metals show shape and dielectrics show highlights without an HDR file at hand. Grey walls
// (brighter toward the ceiling) and four rectangular soft boxes: above, left, right and behind the
// camera (+Z, where the framing camera stands). Scaled so that a white rough dielectric facing the
// camera reads about 0.9.
#pragma once
#include "shading/environment.h"

namespace pmr {

// The studio as an equirectangular image of linear radiance (EnvironmentImage's layout), width x
// width / 2 texels.
EnvironmentImage studio_environment_image(int width = 512);

}  // namespace pmr
