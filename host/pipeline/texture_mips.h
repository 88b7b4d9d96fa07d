// Mip chains of the texture table (DESIGN section 3b, "Textures are filtered"): each level halves each
// side of the one before, rounding down, at least 1; a box filter over the texels decoded to linear
// light first (a colour map's RGB through sRGB -> linear, then the mean encoded back to 8-bit sRGB;
// alpha and data maps averaged as they are).
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
// The levels 1.. of the chain of level 0 `rgba` (w x h RGBA8, row 0 first), back to back after one
// another (each level's rows first to last), as PmrTexture lays them out after level 0.
std::vector<uint8_t> build_mips(const uint8_t* rgba, int width, int height, bool srgb);

}  // namespace pmr
