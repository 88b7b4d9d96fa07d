// The shadow maps' sizes (DESIGN section 4d), apart from the shadow stage so that a configuration needs
// no OpenCL.
#pragma once

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

}  // namespace pmr
