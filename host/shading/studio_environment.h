// The built-in studio environment (docs/SHADING.md, "Environment"): a procedural room, generated in code,
// so that metals show shape and dielectrics show highlights without an HDR file at hand. Grey walls
// (brighter toward the ceiling) and four rectangular soft boxes: above, left, right and behind the
// camera (+Z, where the framing camera stands). Scaled so that a white rough dielectric facing the
// camera reads about 0.9.
//
// With shadows on (DESIGN section 4d) the boxes are taken out of the image and drawn as distant area
// lights of their solid angle, shadowed as directional lights of that size: the walls alone stay an
// environment (studio_walls_image), and the boxes become studio_box_lights.
#pragma once
#include <vector>

#include "pmr/scene.h"
#include "shading/environment.h"

namespace pmr {

// The studio as an equirectangular image of linear radiance (EnvironmentImage's layout), width x
// width / 2 texels.
EnvironmentImage studio_environment_image(int width = 512);

// The studio's walls without the boxes (the walls' radiance where a box was), width x width / 2.
EnvironmentImage studio_walls_image(int width = 128);

// The boxes as distant area lights (SceneLight::distant), unrotated, at intensity 1: the ceiling a disk
// and the others rects on the plane tangent to the unit sphere at the box's centre, each of exactly
// the solid angle of its patch of the image, with the box's radiance as luminance.
std::vector<SceneLight> studio_box_lights();

}  // namespace pmr
