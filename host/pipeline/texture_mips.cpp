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

double toksvig_increment(double length) {
  if (!(length > 0.0)) return 1.0;
  return std::clamp(2.0 * (1.0 - length) / length, 0.0, 1.0);
}

namespace {

// Level 0 decoded to the doubles its chain averages: linear colour, data as it is, or unit normals.
std::vector<double> decoded_level0(const uint8_t* rgba, size_t texels, MipKind kind) {
  std::vector<double> level(texels * 4);
  for (size_t i = 0; i < level.size(); ++i) {
    const double c = rgba[i] / 255.0;
    level[i] = kind == MipKind::Colour && i % 4 != 3 ? srgb_to_linear(c) : c;
  }
  if (kind != MipKind::Normal) return level;
  for (size_t t = 0; t < texels; ++t) {
    double* n = &level[t * 4];
    for (int c = 0; c < 3; ++c) n[c] = 2.0 * n[c] - 1.0;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    // a zero vector (grey 127.5 cannot be stored, but 128-ish noise can be far from unit) faces out
    if (len > 0.0) n[0] /= len, n[1] /= len, n[2] /= len;
    else n[0] = n[1] = 0.0, n[2] = 1.0;
  }
  return level;
}

// One texel of a level as stored: `mean` the averaged doubles.
void encode_texel(const double* mean, MipKind kind, std::vector<uint8_t>& out) {
  if (kind == MipKind::Normal) {
    const double len = std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
    for (int c = 0; c < 3; ++c) out.push_back(to_byte(0.5 * mean[c] + 0.5));
    out.push_back(to_byte(std::sqrt(toksvig_increment(len))));
    return;
  }
  for (int c = 0; c < 4; ++c)
    out.push_back(to_byte(kind == MipKind::Colour && c != 3 ? linear_to_srgb(mean[c]) : mean[c]));
}

}  // namespace

std::vector<uint8_t> build_mips(const uint8_t* rgba, int width, int height, MipKind kind) {
  // Each level is averaged from the one above in linear doubles, not from its 8-bit storage, so the
  // quantization of one level does not accumulate into the next.
  std::vector<double> level = decoded_level0(rgba, size_t(width) * size_t(height), kind);
  std::vector<uint8_t> out;
  int w = width, h = height;
  for (int k = 1; k < mip_levels(width, height); ++k) {
    const int nw = std::max(1, w >> 1), nh = std::max(1, h >> 1);
    const int sx = w > 1 ? 2 : 1, sy = h > 1 ? 2 : 1;  // a side already 1 stays one texel wide
    std::vector<double> next(size_t(nw) * size_t(nh) * 4, 0.0);
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x) {
        double* mean = &next[(size_t(y) * nw + x) * 4];
        for (int c = 0; c < 4; ++c) {
          double sum = 0.0;
          for (int j = 0; j < sy; ++j)
            for (int i = 0; i < sx; ++i) sum += level[((size_t(y) * sy + j) * size_t(w) + size_t(x) * sx + i) * 4 + c];
          mean[c] = sum / (sx * sy);
        }
        encode_texel(mean, kind, out);
      }
    level.swap(next);
    w = nw, h = nh;
  }
  return out;
}

}  // namespace pmr
