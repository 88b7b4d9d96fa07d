// An environment image's brightest regions as lights (DESIGN section 4d): with shadows on, a sun in an
// HDR image is taken out of the image before it is prefiltered and drawn as a distant light of its
// size, so that it casts shadows; the rest of the image stays the environment.
//
// The rule (docs/SHADING.md, "Suns in environment images"):
// - a texel is bright when its luminance exceeds kBrightOverMedian times the image's median luminance;
// - bright texels that touch (4-neighbours, wrapping in longitude) form a region;
// - a region becomes a light when it spans at most kMaxRegionSolidAngle and holds at least
//   kMinRegionShare of the image's power (luminance x solid angle) above its rim; at most
//   kMaxEnvironmentLights regions, the most powerful first;
// - the region's texels take its rim's mean radiance (the bright texels' neighbours that are not
//   bright), and the light takes the rest: a distant disk centred on the region's power-weighted mean
//   direction, of the region's solid angle, whose luminance times that solid angle is the power taken
//   out (colour by colour). The image's power is kept.
#pragma once
#include <vector>

#include "pmr/scene.h"
#include "shading/environment.h"

namespace pmr {

// Rec. 709 luminance of a linear colour (the images' colour space is linear Rec. 709).
double luminance(const glm::dvec3& rgb);

constexpr double kBrightOverMedian = 50.0;
constexpr double kMaxRegionSolidAngle = 0.1;  // sr: a cap of 10 degrees' radius
constexpr double kMinRegionShare = 0.05;
constexpr int kMaxEnvironmentLights = 4;

// Takes the regions of `image` (checked: finite, non-negative) out by the rule above, in place, and
// returns them as distant disks (SceneLight::distant), unrotated, at intensity 1. Memory: two bytes a
// texel (the bright and seen maps) and the bright texels' indices (at most 5% of the texels), beside
// the decoded image's 12: within the kEnvBytesPerTexel charged before decoding, whose peak is the
// prefilter's, later.
std::vector<SceneLight> take_out_bright_regions(EnvironmentImage& image);

}  // namespace pmr
