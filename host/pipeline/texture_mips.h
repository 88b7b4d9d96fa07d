// Mip chains of the texture table (DESIGN section 3b, "Textures are filtered"): each level halves each
// side of the one before, rounding down, at least 1; a box filter over the texels decoded to linear
// light first (a colour map's RGB through sRGB -> linear, then the mean encoded back to 8-bit sRGB;
// alpha and data maps averaged as they are). A normal map's chain averages unit normals and keeps, in
// alpha, the roughness widening that their spread calls for (Toksvig, docs/ANTIALIASING.md).
#pragma once
#include <cstdint>
#include <vector>

namespace pmr {

// The sRGB transfer function and its inverse (IEC 61966-2-1), on [0, 1].
double srgb_to_linear(double c);
double linear_to_srgb(double c);

// Levels of a full chain of a w x h level 0: down to 1 x 1.
int mip_levels(int width, int height);
// Texels (RGBA8 texels, not bytes) of a chain of `levels` levels of a w x h level 0.
uint64_t mip_chain_texels(int width, int height, int levels);

// How a chain averages its texels.
enum class MipKind {
  Colour,  // RGB sRGB-decoded before averaging, alpha linear
  Data,    // every channel as it is (metallic-roughness, occlusion)
  Normal,  // RGB the mean of the level-0 normals 2c - 1, each normalized first, encoded back as
           // (n + 1) / 2; alpha sqrt(min(1, 2 (1 - |n|) / |n|)), the increment of alpha^2 (Toksvig),
           // stored as its square root for precision near 0. Level 0's alpha is 0 (unit normals).
};

// The levels 1.. of the chain of level 0 `rgba` (w x h RGBA8, row 0 first), back to back after one
// another (each level's rows first to last), as PmrTexture lays them out after level 0.
std::vector<uint8_t> build_mips(const uint8_t* rgba, int width, int height, MipKind kind);

// The Toksvig increment of alpha^2 for a mean of unit normals of length `length` (1: none).
double toksvig_increment(double length);

}  // namespace pmr
