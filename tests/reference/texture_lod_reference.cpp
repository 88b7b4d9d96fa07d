#include "reference/texture_lod_reference.h"

#include <algorithm>
#include <cmath>

#include "reference/shade_reference.h"

namespace pmr::ref {
namespace {

double decode(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double encode(double c) { return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; }

int floor_log2(int n) {
  int k = 0;
  while ((n >> (k + 1)) > 0) ++k;
  return k;
}

}  // namespace

std::vector<SceneTexture> mip_chain(const SceneTexture& tex, bool srgb) {
  std::vector<SceneTexture> chain = {tex};
  const int levels = floor_log2(std::max(tex.width, tex.height)) + 1;
  for (int k = 1; k < levels; ++k) {
    SceneTexture t = tex;
    t.width = std::max(1, tex.width >> k), t.height = std::max(1, tex.height >> k);
    const int bw = 1 << std::min(k, floor_log2(tex.width)), bh = 1 << std::min(k, floor_log2(tex.height));
    t.rgba.assign(size_t(t.width) * size_t(t.height) * 4, 0);
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x)
        for (int c = 0; c < 4; ++c) {
          double sum = 0.0;
          for (int j = 0; j < bh; ++j)
            for (int i = 0; i < bw; ++i) {
              const double v =
                  tex.rgba[((size_t(y) * bh + j) * size_t(tex.width) + size_t(x) * bw + i) * 4 + c] / 255.0;
              sum += srgb && c < 3 ? decode(v) : v;
            }
          const double mean = sum / (bw * bh);
          t.rgba[(size_t(y) * t.width + x) * 4 + c] =
              uint8_t(std::lround(255.0 * (srgb && c < 3 ? encode(mean) : mean)));
        }
    chain.push_back(t);
  }
  return chain;
}

BaryDerivatives source_barycentric_derivatives(const PmrMta& m, int64_t sample_x, int64_t sample_y, int view) {
  double x[3], y[3];
  for (int k = 0; k < 3; ++k) {
    x[k] = (double(m.x0[k]) + double(view) * m.dx[k]) / PMR_X_ONE;
    y[k] = double(m.y[k]) / PMR_Y_ONE;
  }
  const double X = double(sample_x) / PMR_X_ONE, Y = double(sample_y) / PMR_Y_ONE;
  // l_k = p_k / S, p_k = e_k / w_k with e_k the edge function opposite vertex k (in pixels)
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  double p[3], px[3], py[3], S = 0, Sx = 0, Sy = 0;
  for (int k = 0; k < 3; ++k) {
    const int a = ea[k], b = eb[k];
    p[k] = ((y[b] - y[a]) * (X - x[a]) - (x[b] - x[a]) * (Y - y[a])) * m.inv_w[k];
    px[k] = (y[b] - y[a]) * m.inv_w[k];
    py[k] = -(x[b] - x[a]) * m.inv_w[k];
    S += p[k], Sx += px[k], Sy += py[k];
  }
  BaryDerivatives d;
  for (int k = 0; k < 3; ++k) {
    const double lx = (px[k] * S - p[k] * Sx) / (S * S), ly = (py[k] * S - p[k] * Sy) / (S * S);
    d.dx.y += lx * m.bary[k][0], d.dx.z += lx * m.bary[k][1];
    d.dy.y += ly * m.bary[k][0], d.dy.z += ly * m.bary[k][1];
  }
  d.dx.x = -d.dx.y - d.dx.z, d.dy.x = -d.dy.y - d.dy.z;
  return d;
}

double texture_lod(const std::vector<SceneTexture>& chain, const glm::dvec2& duv_dx, const glm::dvec2& duv_dy) {
  const glm::dvec2 size(chain[0].width, chain[0].height);
  const double rho = std::max(glm::length(duv_dx * size), glm::length(duv_dy * size));
  return std::clamp(rho > 0.0 ? std::log2(rho) : 0.0, 0.0, double(chain.size() - 1));
}

glm::dvec4 sample_trilinear(const std::vector<SceneTexture>& chain, const glm::dvec2& uv, const glm::dvec2& duv_dx,
                            const glm::dvec2& duv_dy, bool srgb) {
  const double lambda = texture_lod(chain, duv_dx, duv_dy);
  const size_t k = size_t(lambda);
  const glm::dvec4 a = sample_texture(chain[k], uv, srgb);
  if (k + 1 >= chain.size()) return a;
  return glm::mix(a, sample_texture(chain[k + 1], uv, srgb), lambda - double(k));
}

}  // namespace pmr::ref
