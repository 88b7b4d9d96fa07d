#include "pipeline/texture_mips.h"

#include <algorithm>
#include <cmath>

namespace pmr {
double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double linear_to_srgb(double c) { return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; }

namespace {

uint8_t to_byte(double c) { return uint8_t(std::lround(std::clamp(c, 0.0, 1.0) * 255.0)); }

}  // namespace

int mip_levels(int width, int height) {
  int levels = 1;
  while ((width >> levels) > 0 || (height >> levels) > 0) ++levels;
  return levels;
}

uint64_t mip_chain_texels(int width, int height, int levels) {
  uint64_t n = 0;
  for (int k = 0; k < levels; ++k) n += uint64_t(std::max(1, width >> k)) * uint64_t(std::max(1, height >> k));
  return n;
}

std::vector<uint8_t> build_mips(const uint8_t* rgba, int width, int height, bool srgb) {
  // Each level is averaged from the one above in linear doubles, not from its 8-bit storage, so the
  // quantization of one level does not accumulate into the next.
  std::vector<double> level(size_t(width) * size_t(height) * 4);
  for (size_t i = 0; i < level.size(); ++i) {
    const double c = rgba[i] / 255.0;
    level[i] = srgb && i % 4 != 3 ? srgb_to_linear(c) : c;
  }
  std::vector<uint8_t> out;
  int w = width, h = height;
  for (int k = 1; k < mip_levels(width, height); ++k) {
    const int nw = std::max(1, w >> 1), nh = std::max(1, h >> 1);
    const int sx = w > 1 ? 2 : 1, sy = h > 1 ? 2 : 1;  // a side already 1 stays one texel wide
    std::vector<double> next(size_t(nw) * size_t(nh) * 4, 0.0);
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x)
        for (int c = 0; c < 4; ++c) {
          double sum = 0.0;
          for (int j = 0; j < sy; ++j)
            for (int i = 0; i < sx; ++i) sum += level[((size_t(y) * sy + j) * size_t(w) + size_t(x) * sx + i) * 4 + c];
          const double mean = sum / (sx * sy);
          next[(size_t(y) * nw + x) * 4 + c] = mean;
          out.push_back(to_byte(srgb && c != 3 ? linear_to_srgb(mean) : mean));
        }
    level.swap(next);
    w = nw, h = nh;
  }
  return out;
}

}  // namespace pmr
