// Prefiltering an environment image into its tables (environment.h says what they hold and how they
// are laid out).
//
// Prefiltering one level. On an equirectangular grid of W x H texels the lobe weight between output
// texel (i, j) and source texel (k, m) depends on the rows i, k and on (j - m) mod W only: with
// theta the polar angle of a row and dphi = 2 pi (j - m) / W,
//   dot(d, l) = cos(theta_i) cos(theta_k) + sin(theta_i) sin(theta_k) cos(dphi)
// and D(dot(d, h)) with dot(d, h) = sqrt((1 + dot(d, l)) / 2). So for each pair of rows (i, k) the
// sum over m is a circular convolution along the row, done with FFTs: numerator(i) = sum over k of
// IFFT(FFT(w_ik) * FFT(L_k)), w_ik(n) = K(dot(d, l)) * (solid angle of a texel in row k), and the
// denominator is the sum of all weights, so a uniform map gives exactly its value. w_ik is real and
// even, so its transform is real: two rows' kernels share one complex FFT; row pair (H-1-i, H-1-k)
// has the same kernel as (i, k), so each kernel transform serves two output rows.
#include "shading/environment_prefilter.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <functional>
#include <memory>
#include <thread>

#include "pmr/error.h"
#include "shading/sheen.h"
#include "shading/split_sum_integral.h"

namespace pmr {

namespace {

// The bilinear blend of rows row0 and row1 (weight fy of row1) at u: texel centers at (j + 1/2) / W,
// wrapping in u.
glm::dvec3 bilinear_rows(const float* tex, int W, int stride, double u, long row0, long row1, double fy) {
  const double x = u * W - 0.5, x0f = std::floor(x), fx = x - x0f;
  long x0 = long(x0f) % W;
  if (x0 < 0) x0 += W;
  const long x1 = (x0 + 1) % W;
  auto at = [&](long xx, long yy) {
    const float* p = tex + (size_t(yy) * size_t(W) + size_t(xx)) * size_t(stride);
    return glm::dvec3(p[0], p[1], p[2]);
  };
  return (1 - fy) * ((1 - fx) * at(x0, row0) + fx * at(x1, row0)) + fy * ((1 - fx) * at(x0, row1) + fx * at(x1, row1));
}

// An image's bilinear lookup: texel centers at (j + 1/2) / W, wrapping in u, clamped in v.
glm::dvec3 image_bilinear(const float* tex, int W, int H, int stride, double u, double v) {
  const double y = v * H - 0.5, y0f = std::floor(y);
  const long y0 = std::clamp(long(y0f), 0L, long(H - 1)), y1 = std::clamp(long(y0f) + 1, 0L, long(H - 1));
  return bilinear_rows(tex, W, stride, u, y0, y1, y - y0f);
}

constexpr double kPi = 3.14159265358979323846;
using cd = std::complex<double>;

// Roughness of the prefiltered levels after level 0, in hundredths (every one a node of c(r)).
constexpr int kLevelHundredths[] = {20, 22, 25, 30, 35, 40, 45, 50, 55, 60, 70, 80, 90, 100};
constexpr int kPrefilteredLevels = int(sizeof kLevelHundredths / sizeof kLevelHundredths[0]);
static_assert(kPrefilteredLevels + 1 + PMR_SHEEN_LEVELS <= kEnvMaxLevels, "too many levels");

template <class F>
void parallel_for_index(int n, F&& f) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int threads = std::max(1, std::min(n, int(std::min(hw, 16u))));
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i; (i = next.fetch_add(1)) < n;) f(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

// Radix-2 complex FFT (unnormalized; inverse = conjugate twiddles).
class Fft {
 public:
  explicit Fft(int n) : n_(n), rev_(size_t(n)), tw_(size_t(std::max(1, n / 2))) {
    int bits = 0;
    while ((1 << bits) < n) ++bits;
    for (int i = 0; i < n; ++i) {
      int r = 0;
      for (int b = 0; b < bits; ++b)
        if (i & (1 << b)) r |= 1 << (bits - 1 - b);
      rev_[size_t(i)] = r;
    }
    for (int k = 0; k < n / 2; ++k) tw_[size_t(k)] = std::polar(1.0, -2.0 * kPi * k / n);
  }
  void run(cd* a, bool inverse) const {
    for (int i = 0; i < n_; ++i)
      if (i < rev_[size_t(i)]) std::swap(a[i], a[rev_[size_t(i)]]);
    for (int len = 2; len <= n_; len <<= 1) {
      const int half = len / 2, step = n_ / len;
      for (int i = 0; i < n_; i += len)
        for (int k = 0; k < half; ++k) {
          const cd w = inverse ? std::conj(tw_[size_t(k * step)]) : tw_[size_t(k * step)];
          const cd u = a[i + k], v = a[i + k + half] * w;
          a[i + k] = u + v;
          a[i + k + half] = u - v;
        }
    }
  }

 private:
  int n_;
  std::vector<int> rev_;
  std::vector<cd> tw_;
};

struct Image3 {  // RGB, row 0 at the top
  int w = 0, h = 0;
  std::vector<float> rgb;
};

// 2x2 box filter (an odd last column or row is averaged with itself).
Image3 halve(const Image3& s) {
  Image3 d;
  d.w = std::max(1, (s.w + 1) / 2), d.h = std::max(1, (s.h + 1) / 2);
  d.rgb.resize(size_t(d.w) * size_t(d.h) * 3);
  for (int i = 0; i < d.h; ++i)
    for (int j = 0; j < d.w; ++j) {
      const int x0 = std::min(2 * j, s.w - 1), x1 = std::min(2 * j + 1, s.w - 1);
      const int y0 = std::min(2 * i, s.h - 1), y1 = std::min(2 * i + 1, s.h - 1);
      for (int c = 0; c < 3; ++c) {
        auto at = [&](int x, int y) { return double(s.rgb[(size_t(y) * size_t(s.w) + size_t(x)) * 3 + size_t(c)]); };
        d.rgb[(size_t(i) * size_t(d.w) + size_t(j)) * 3 + size_t(c)] =
            float(0.25 * (at(x0, y0) + at(x1, y0) + at(x0, y1) + at(x1, y1)));
      }
    }
  return d;
}

// The level's W x H grid sampled from `s` (at least as wide as W / 2): the mean of s x s bilinear
// lookups spread over each texel (one lookup at the center when not downsampling).
std::vector<double> resample(const Image3& s, int W, int H) {
  const int sx = W >= s.w ? 1 : 2 * ((s.w + W - 1) / W), sy = H >= s.h ? 1 : 2 * ((s.h + H - 1) / H);
  std::vector<double> out(size_t(W) * size_t(H) * 3);
  for (int i = 0; i < H; ++i)
    for (int j = 0; j < W; ++j) {
      glm::dvec3 sum(0.0);
      for (int b = 0; b < sy; ++b)
        for (int a = 0; a < sx; ++a)
          sum += image_bilinear(s.rgb.data(), s.w, s.h, 3, (j + (a + 0.5) / sx) / W, (i + (b + 0.5) / sy) / H);
      sum /= double(sx * sy);
      for (int c = 0; c < 3; ++c) out[(size_t(c) * size_t(H) + size_t(i)) * size_t(W) + size_t(j)] = sum[c];
    }
  return out;
}

// The GGX lobe of the prefilter as a function of dot(d, l): D(dot(d, h)) dot(d, l).
inline double lobe(double c, double a2) {
  if (c <= 0.0) return 0.0;
  const double q2 = 0.5 * (1.0 + c);
  const double t = q2 * (a2 - 1.0) + 1.0;
  return a2 / (kPi * t * t) * c;
}

// The weights of source row k for output row i (whose direction is at column 0), one per azimuth
// offset n = 0 .. W / 2 (dphi = 2 pi n / W): the lobe integrated over the source texel. Returns false
// when they are all 0. The weights are even in n, so the row's circular kernel is real and even.
using RowWeights = std::function<bool(int i, int k, double* w)>;

// The rows' polar angles and the texels' solid angles of an equirectangular W x H grid.
struct GridRows {
  std::vector<double> ct, st, dom;  // cos and sin of each row's center, a texel's solid angle
  GridRows(int W, int H) : ct(size_t(H)), st(size_t(H)), dom(size_t(H)) {
    for (int k = 0; k < H; ++k) {
      const double th = kPi * (k + 0.5) / H;
      ct[size_t(k)] = std::cos(th), st[size_t(k)] = std::sin(th);
      dom[size_t(k)] = 2.0 * kPi / W * (std::cos(kPi * k / H) - std::cos(kPi * (k + 1) / H));
    }
  }
};

// The GGX lobe of roughness alpha^2 = a2 at the source texels' centers.
RowWeights ggx_weights(int W, int H, double a2) {
  auto rows = std::make_shared<GridRows>(W, H);
  auto cphi = std::make_shared<std::vector<double>>(size_t(W / 2 + 1));
  for (int n = 0; n <= W / 2; ++n) (*cphi)[size_t(n)] = std::cos(2.0 * kPi * n / W);
  return [=](int i, int k, double* w) {
    const GridRows& g = *rows;
    const double a = g.ct[size_t(i)] * g.ct[size_t(k)], b = g.st[size_t(i)] * g.st[size_t(k)];
    if (a + b <= 0.0) return false;
    for (int n = 0; n <= W / 2; ++n) w[n] = lobe(a + b * (*cphi)[size_t(n)], a2) * g.dom[size_t(k)];
    return true;
  };
}

// The Charlie lobe of sheen roughness r at v = n = d as a function of c = d.l, the weight D(d.h) V(1, c)
// c of the sheen BRDF's integrand (sheen_lobe_cos), tabulated at kSheenKernelSteps + 1 points of c in
// [0, 1] and integrated over each source texel by an s x s midpoint rule, s from the lobe's width: for
// the smallest roughness the lobe is a ring about 0.03 rad wide just above the horizon of d, where a
// 256x128 level's texels are 0.025 rad (s = 8 there, 1 from r = 0.2 on).
constexpr int kSheenKernelSteps = 4096;
constexpr int kSheenWidth = 256;

RowWeights sheen_weights(int W, int H, double r) {
  auto K = std::make_shared<std::vector<double>>(size_t(kSheenKernelSteps + 1));
  for (int t = 0; t <= kSheenKernelSteps; ++t) {
    const double c = double(t) / kSheenKernelSteps;
    (*K)[size_t(t)] = sheen_lobe_cos(1.0, c, std::sqrt(0.5 * (1.0 + c)), r);
  }
  const int s = std::clamp(int(std::ceil(0.08 / (r * r) * 128.0 / W)), 1, 8);
  // the sub-rows' polar angles and sub-texels' solid angles, the sub-columns' azimuth cosines
  auto rows = std::make_shared<GridRows>(W, H);
  auto sub = std::make_shared<GridRows>(W * s, H * s);
  auto cphi = std::make_shared<std::vector<double>>(size_t((W / 2 + 1) * s));
  for (int n = 0; n <= W / 2; ++n)
    for (int b = 0; b < s; ++b) (*cphi)[size_t(n * s + b)] = std::cos(2.0 * kPi * (n + (b + 0.5) / s - 0.5) / W);
  return [=](int i, int k, double* w) {
    const std::vector<double>& kernel = *K;
    bool any = false;
    for (int n = 0; n <= W / 2; ++n) {
      double sum = 0.0;
      for (int a = 0; a < s; ++a) {
        const size_t q = size_t(k * s + a);
        const double A = rows->ct[size_t(i)] * sub->ct[q], B = rows->st[size_t(i)] * sub->st[q];
        if (A + B <= 0.0) continue;
        for (int b = 0; b < s; ++b) {
          const double c = A + B * (*cphi)[size_t(n * s + b)];
          if (c <= 0.0) continue;
          const double x = std::min(c, 1.0) * kSheenKernelSteps;
          const int t = std::min(int(x), kSheenKernelSteps - 1);
          sum += (kernel[size_t(t)] + (x - t) * (kernel[size_t(t + 1)] - kernel[size_t(t)])) * sub->dom[q];
        }
      }
      w[n] = sum;
      any = any || sum > 0.0;
    }
    return any;
  };
}

// P on a W x H grid (W a power of two, H = W / 2) from the resampled source (planar: [c][row][col]),
// with the lobe `weights`. Writes 4 floats per texel into `out`.
void prefilter_level(const std::vector<double>& src, int W, int H, const RowWeights& weights, float* out) {
  const int M = W / 2 + 1;
  const Fft fft(W);
  // Row spectra of the source, bins 0..W/2 (the rest follow by symmetry).
  std::vector<cd> spec(size_t(3) * size_t(H) * size_t(M));
  parallel_for_index(3 * H, [&](int ck) {
    std::vector<cd> z(static_cast<size_t>(W));
    for (int n = 0; n < W; ++n) z[size_t(n)] = src[size_t(ck) * size_t(W) + size_t(n)];
    fft.run(z.data(), false);
    std::copy(z.begin(), z.begin() + M, spec.begin() + std::ptrdiff_t(size_t(ck) * size_t(M)));
  });
  auto S = [&](int c, int k) { return &spec[(size_t(c) * size_t(H) + size_t(k)) * size_t(M)]; };
  parallel_for_index(H / 2, [&](int i) {
    const int i2 = H - 1 - i;
    std::vector<cd> z(static_cast<size_t>(W)), acc(size_t(6) * size_t(M), cd(0.0));
    double den = 0.0;
    std::vector<double> w0(static_cast<size_t>(M)), w1(static_cast<size_t>(M));
    for (int k = 0; k < H; k += 2) {
      const bool on0 = weights(i, k, w0.data()), on1 = weights(i, k + 1, w1.data());
      if (!on0 && !on1) continue;
      for (int n = 0; n < M; ++n) {
        z[size_t(n)] = cd(on0 ? w0[size_t(n)] : 0.0, on1 ? w1[size_t(n)] : 0.0);
        if (n > 0 && n < W - n) z[size_t(W - n)] = z[size_t(n)];
      }
      fft.run(z.data(), false);
      den += z[0].real() + z[0].imag();
      for (int c = 0; c < 3; ++c) {
        const cd *s0 = S(c, k), *s1 = S(c, k + 1), *m0 = S(c, H - 1 - k), *m1 = S(c, H - 2 - k);
        cd* up = &acc[size_t(c) * size_t(M)];
        cd* down = &acc[size_t(3 + c) * size_t(M)];
        for (int m = 0; m < M; ++m) {
          const double h0 = z[size_t(m)].real(), h1 = z[size_t(m)].imag();
          up[m] += h0 * s0[m] + h1 * s1[m];
          down[m] += h0 * m0[m] + h1 * m1[m];
        }
      }
    }
    for (int half = 0; half < 2; ++half) {
      const int row = half ? i2 : i;
      for (int c = 0; c < 3; ++c) {
        const cd* a = &acc[size_t(3 * half + c) * size_t(M)];
        for (int m = 0; m < M; ++m) z[size_t(m)] = a[m];
        for (int m = 1; m < W - m; ++m) z[size_t(W - m)] = std::conj(a[m]);
        fft.run(z.data(), true);
        for (int j = 0; j < W; ++j) {
          const double v = den > 0.0 ? z[size_t(j)].real() / (double(W) * den) : 0.0;
          out[(size_t(row) * size_t(W) + size_t(j)) * 4 + size_t(c)] = float(std::max(0.0, v));
        }
      }
      for (int j = 0; j < W; ++j) out[(size_t(row) * size_t(W) + size_t(j)) * 4 + 3] = 0.0f;
    }
  });
}

int pow2_at_least(double x) {
  int p = 1;
  while (p < x && p < (1 << 30)) p <<= 1;
  return p;
}

int level_width(double r, int source_width) {
  int w = std::clamp(pow2_at_least(16.0 / (r * r)), 128, 512);
  return std::min(w, std::max(128, pow2_at_least(2.0 * source_width)));
}

// Continuous normalization N(alpha) = integral over the hemisphere of D(dot(d, h)) dot(d, l) dl, in
// closed form: with c = dot(d, l), D's denominator is pi (A + B c)^2, A = (a2 + 1) / 2, B = (a2 - 1) / 2,
// so N = 2 a2 integral_0^1 c / (A + B c)^2 dc = 2 a2 / A^2 sum_k (k + 1) / (k + 2) (-B / A)^k; the
// series where |B / A| < 1/2, else the antiderivative 2 a2 / B^2 (ln(a2 / A) + A / a2 - 1), which has
// no cancellation there. (A midpoint rule was about 0.18 s of every pbr process's start.)
double lobe_norm(double a2) {
  const double A = 0.5 * (a2 + 1.0), B = 0.5 * (a2 - 1.0), x = B / A;
  if (std::fabs(x) >= 0.5) return 2.0 * a2 / (B * B) * (std::log(a2 / A) + A / a2 - 1.0);
  double sum = 0.0, power = 1.0;
  for (int k = 0; k < 64; ++k, power *= -x) sum += (k + 1.0) / (k + 2.0) * power;
  return 2.0 * a2 / (A * A) * sum;
}

// P at d of a point light at d, up to a constant: the peak the level weights interpolate exactly.
double point_peak(double r) {
  const double a2 = r * r * r * r;
  return lobe(1.0, a2) / lobe_norm(a2);
}

const std::vector<float>& roughness_table() {
  static const std::vector<float> table = [] {
    std::vector<float> t(static_cast<size_t>(kEnvRoughnessNodes));
    const int last = kEnvRoughnessNodes - 1;
    for (int i = 0; i <= last; ++i) {
      const int h = i * 100 / last;  // hundredths (kEnvRoughnessNodes = 101)
      if (h <= kLevelHundredths[0]) {
        t[size_t(i)] = float(double(h) / kLevelHundredths[0]);
        continue;
      }
      int a = 0;
      while (a + 1 < kPrefilteredLevels && kLevelHundredths[a + 1] < h) ++a;
      const int b = a + 1;
      if (kLevelHundredths[b] == h) {
        t[size_t(i)] = float(b + 1);
        continue;
      }
      const double fa = point_peak(kLevelHundredths[a] / 100.0), fb = point_peak(kLevelHundredths[b] / 100.0);
      const double f = point_peak(h / 100.0);
      t[size_t(i)] = float(a + 1 + std::log(f / fa) / std::log(fb / fa));
    }
    return t;
  }();
  static_assert(kEnvRoughnessNodes == 101, "roughness nodes are hundredths");
  return table;
}

// A level with its pole rows (environment.h): a row above row 0 and one below the last, so that the
// bilinear lookup, clamped half a texel beyond the outer rows' centers, reaches the pole there. Level
// 0 (the image) repeats its outer rows: clamped, as the map is defined. A prefiltered level puts
// 2 m - t above (below) each outer texel t, m the outer row's mean, so that the lookup at the pole
// is m, the mean of the ring of texels around it, and linear from there to each texel's center:
// clamping would read the ring's texel at the direction's longitude instead, 1.4 degrees off the pole
// in a 128x64 level (2% of I at +Y under the studio, whose boxes sit low).
std::vector<float> with_pole_rows(const std::vector<float>& level, int W, int H, bool prefiltered) {
  std::vector<float> out(size_t(W) * size_t(H + 2) * 4);
  std::copy(level.begin(), level.end(), out.begin() + std::ptrdiff_t(size_t(W) * 4));
  for (int side = 0; side < 2; ++side) {
    const float* ring = &level[size_t(side ? H - 1 : 0) * size_t(W) * 4];
    float* pole = &out[size_t(side ? H + 1 : 0) * size_t(W) * 4];
    for (int c = 0; c < 4; ++c) {
      double mean = 0.0;
      for (int j = 0; j < W; ++j) mean += ring[4 * j + c];
      mean /= W;
      for (int j = 0; j < W; ++j) pole[4 * j + c] = prefiltered ? float(2.0 * mean - ring[4 * j + c]) : ring[4 * j + c];
    }
  }
  return out;
}

// Lays out levels (each 4 floats per texel, with pole rows: the image's first, then the GGX levels,
// then the PMR_SHEEN_LEVELS sheen levels), then c(r), then the split-sum table.
EnvironmentTables assemble(const std::vector<std::pair<glm::ivec2, std::vector<float>>>& plain) {
  std::vector<std::pair<glm::ivec2, std::vector<float>>> levels;
  for (size_t k = 0; k < plain.size(); ++k)
    levels.push_back({plain[k].first, with_pole_rows(plain[k].second, plain[k].first.x, plain[k].first.y, k > 0)});
  EnvironmentTables t;
  EnvTablesHeader& h = t.header;
  h.level_count = uint32_t(levels.size()) - PMR_SHEEN_LEVELS;
  h.sheen_first = h.level_count;
  size_t at = 0;
  for (size_t k = 0; k < levels.size(); ++k) {
    h.levels[k].width = uint32_t(levels[k].first.x);
    h.levels[k].height = uint32_t(levels[k].first.y);
    h.levels[k].offset = uint32_t(at);
    h.levels[k].roughness = k == 0              ? 0.0f
                            : k < h.sheen_first ? float(kLevelHundredths[k - 1] / 100.0)
                                                : float(environment_sheen_roughness()[k - h.sheen_first]);
    at += levels[k].second.size();
  }
  h.roughness_nodes = kEnvRoughnessNodes;
  h.roughness_offset = uint32_t(at);
  at += size_t(kEnvRoughnessNodes);
  h.split_sum_size = kEnvSplitSumSize;
  h.split_sum_offset = uint32_t(at);
  at += split_sum_table().size();
  if (at > size_t(UINT32_MAX)) throw Error("environment tables too large");
  t.data.reserve(at);
  for (const auto& l : levels) t.data.insert(t.data.end(), l.second.begin(), l.second.end());
  t.data.insert(t.data.end(), roughness_table().begin(), roughness_table().end());
  t.data.insert(t.data.end(), split_sum_table().begin(), split_sum_table().end());
  h.intensity = 1.0f;
  h.rotation_cos = 1.0f, h.rotation_sin = 0.0f;
  return t;
}

}  // namespace

const std::vector<float>& split_sum_table() {
  // computed at build time (compute_split_sum_table, by pmr_brdf_tables_gen): it would cost every pbr
  // process about 0.3 s at start
  static const std::vector<float> table(kSplitSumTable, kSplitSumTable + 2 * kEnvSplitSumSize * kEnvSplitSumSize);
  return table;
}

const std::vector<double>& environment_level_roughness() {
  static const std::vector<double> r = [] {
    std::vector<double> v;
    for (int h : kLevelHundredths) v.push_back(h / 100.0);
    return v;
  }();
  return r;
}

const std::vector<double>& environment_sheen_roughness() {
  static const std::vector<double> r = [] {
    std::vector<double> v;
    for (int k = 0; k < PMR_SHEEN_LEVELS; ++k)
      v.push_back(std::pow(kSheenMinRoughness, 1.0 - double(k) / (PMR_SHEEN_LEVELS - 1)));
    return v;
  }();
  return r;
}

double environment_level_coordinate(double r) {
  const std::vector<float>& t = roughness_table();
  const double x = std::clamp(std::isfinite(r) ? r : 1.0, 0.0, 1.0) * (kEnvRoughnessNodes - 1);
  const int i = std::min(int(x), kEnvRoughnessNodes - 2);
  const double f = x - i;
  return (1 - f) * double(t[size_t(i)]) + f * double(t[size_t(i + 1)]);
}

glm::dvec3 environment_level_bilinear(const float* level, int W, int H, double u, double v) {
  const double y = std::clamp(v * H - 0.5, -0.5, H - 0.5), y0f = std::floor(y);
  const long y0 = long(y0f) + 1, y1 = std::min(y0 + 1, long(H + 1));  // rows counted with the pole row
  return bilinear_rows(level, W, 4, u, y0, y1, y - y0f);
}

EnvironmentTables prefilter_environment(const EnvironmentImage& image) {
  Image3 base{image.width, image.height, image.rgb};
  while (base.w > kEnvMaxBaseWidth) base = halve(base);
  // Box pyramid from the base down to 128 texels wide, so each level resamples from an image at most
  // twice its own width.
  std::vector<Image3> pyramid{base};
  while (pyramid.back().w > 128) pyramid.push_back(halve(pyramid.back()));
  std::vector<std::pair<glm::ivec2, std::vector<float>>> levels;
  {
    std::vector<float> l0(size_t(base.w) * size_t(base.h) * 4);
    for (size_t t = 0; t < size_t(base.w) * size_t(base.h); ++t)
      for (int c = 0; c < 3; ++c) l0[4 * t + size_t(c)] = base.rgb[3 * t + size_t(c)];
    levels.push_back({glm::ivec2(base.w, base.h), std::move(l0)});
  }
  for (int k = 0; k < kPrefilteredLevels; ++k) {
    const double r = kLevelHundredths[k] / 100.0;
    const int W = level_width(r, base.w), H = W / 2;
    const Image3* src = &pyramid[0];
    for (const Image3& p : pyramid)
      if (p.w >= W) src = &p;
    std::vector<float> out(size_t(W) * size_t(H) * 4);
    prefilter_level(resample(*src, W, H), W, H, ggx_weights(W, H, r * r * r * r), out.data());
    levels.push_back({glm::ivec2(W, H), std::move(out)});
  }
  // the sheen levels, all kSheenWidth x kSheenWidth / 2 (see sheen_weights)
  const Image3* sheen_src = &pyramid[0];
  for (const Image3& p : pyramid)
    if (p.w >= kSheenWidth) sheen_src = &p;
  const std::vector<double> sheen_source = resample(*sheen_src, kSheenWidth, kSheenWidth / 2);
  for (double r : environment_sheen_roughness()) {
    std::vector<float> out(size_t(kSheenWidth) * (kSheenWidth / 2) * 4);
    prefilter_level(sheen_source, kSheenWidth, kSheenWidth / 2, sheen_weights(kSheenWidth, kSheenWidth / 2, r),
                    out.data());
    levels.push_back({glm::ivec2(kSheenWidth, kSheenWidth / 2), std::move(out)});
  }
  return assemble(levels);
}

EnvironmentTables uniform_environment_tables(float radiance) {
  std::vector<std::pair<glm::ivec2, std::vector<float>>> levels;
  for (int k = 0; k <= kPrefilteredLevels + PMR_SHEEN_LEVELS; ++k)
    levels.push_back({glm::ivec2(1, 1), {radiance, radiance, radiance, 0.0f}});
  return assemble(levels);
}

}  // namespace pmr
