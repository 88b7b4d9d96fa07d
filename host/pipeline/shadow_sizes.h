// The shadow maps' sizes (DESIGN section 4d), apart from the shadow stage so that a configuration needs
// no OpenCL.
#pragma once
#include <cstdint>
#include <vector>

#include "pmr/scene.h"

namespace pmr {

// Texels a side: a directional light's one map, and each face of a point or spot light's (one face for
// a spot light of outer cone angle up to kSpotSingleMapAngle, else a cube of six).
struct ShadowSizes {
  int directional = 2048;
  int local = 1024;
};
constexpr double kSpotSingleMapAngle = 0.8726646259971648;  // 50 degrees

// A frame's maps hold at most this many texels (256 MiB of depths): with more lights the maps of every
// light are halved in size until they fit, down to kMinShadowSize a side; the lights after the first
// kMaxShadowedLights cast no shadow.
constexpr unsigned long long kShadowTexelBudget = 1ull << 26;
constexpr int kMinShadowSize = 256;
constexpr int kMaxShadowedLights = 64;
// A light with a size is sampled at this many points (or directions) of it, each with its maps (at a
// quarter of the sizes above, not below kMinShadowSize / 2): its shadow is the mean of their hard
// shadows. Measured on a sphere light and a wide sun over occluders at two heights
// (Shadows.SoftShadowsMatchTheExactFraction), mean |V error| over the penumbra: 16 samples at half
// size 0.031 and 0.030, 32 at half size 0.022 and 0.021, 32 at a quarter 0.024 and 0.025.
constexpr int kShadowSamples = 32;
// The samples light l's shadows take: 1 for a point-like light. The studio's boxes, 20 to 28 degrees
// wide, take kShadowSamples too: with 16 the key box's mean |V error| is 0.038 (at a quarter of the
// sizes) and 0.041 (at an eighth); with 32 at an eighth 0.029.
inline int shadow_samples(const SceneLight& l) { return has_size(l) ? kShadowSamples : 1; }

// The environment's occlusion maps (shading/environment_occlusion.h) are this many texels a side: the
// occlusion is an integral over many directions, smooth where one light's shadow is sharp.
constexpr int kOcclusionSize = 256;

// What the shadows of `lights` and of `occlusion_directions` of the environment's occlusion cost a
// frame (as placed with `sizes`, before any halving): the map passes (each over every triangle), their
// texels, and the maps one shaded point reads (one per sample of each shadowed light, one per
// occlusion direction).
struct ShadowCost {
  uint64_t maps = 0, texels = 0, lookups_per_point = 0;
};
ShadowCost shadow_cost(const std::vector<SceneLight>& lights, size_t occlusion_directions, const ShadowSizes& sizes);

}  // namespace pmr
