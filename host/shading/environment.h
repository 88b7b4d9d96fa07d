// Environment lighting for the physically based shading model (DESIGN section 4b): loading an
// equirectangular image of linear radiance, the direction <-> image mapping, and the tables that are
// precomputed once per environment so that the kernels and the C++ reference read the same numbers.
//
// Mapping. A world-space direction d = (x, y, z) reads the image at
//   u = 1/2 + atan2(x, -z) / (2 pi),  v = acos(y) / pi
// (u from the image's left, v from its top): -Z is the middle column, +X is at u = 3/4, +Y is the top
// row. Texel (j, i) has its center at u = (j + 1/2) / W, v = (i + 1/2) / H; lookups are bilinear,
// wrapping in u and clamped in v (the image itself; the prefiltered levels blend toward the poles,
// below). A rotation of DEG degrees turns the map counter-clockwise seen from
// above (right-hand rule about +Y, as the turntable): a feature at +X moves to -Z at DEG = 90. It is
// applied at lookup time (d is turned by -DEG before the mapping); the intensity also multiplies at
// lookup time, so neither changes the tables.
//
// What is precomputed (all radiance in the image's units, before intensity):
// - Prefiltered levels, equirectangular RGB maps for a fixed set of roughness values r_k:
//     P(d, r) = integral of L(l) D(dot(d, h)) dot(d, l) dl / integral of D(dot(d, h)) dot(d, l) dl
//   over dot(d, l) > 0, h = normalize(l + d), alpha = r^2, D = GGX. Level 0 (r = 0) is the image
//   itself (box-downsampled by 2 while wider than kEnvMaxBaseWidth), so P(d, 0) is the bilinear
//   image lookup. Levels 1..14 are r = 0.2, 0.22, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.7,
//   0.8, 0.9, 1.0 at W x W/2 texels, W = the power of two >= 16 / r^2 clamped to [128, 512] and to
//   at most max(128, the power of two >= 2x the image's width): 512x256 for r = 0.2 and 0.22,
//   256x128 for r = 0.25 to 0.35, 128x64 from r = 0.4 on. Each level is the exact discrete
//   convolution of the image (resampled to the level's grid: mean of bilinear lookups over each
//   texel) with the GGX lobe over every texel of the hemisphere (no sampling noise, no truncated
//   tails), normalized by the discrete sum of the weights, done row pair by row pair with FFTs.
// - I(n) = irradiance / pi about n = the cosine-weighted mean radiance. At r = 1 (alpha = 1) D is
//   constant and P(n, 1) is exactly this mean, so I(n) is read from the last level (r = 1). (Order-2
//   spherical harmonics were not used: for a point light they are 6% high facing it and 9% of its
//   irradiance wrong at 90 degrees, far from the 1% we want with a sun in the map.)
// - Sheen levels (KHR_materials_sheen), PMR_SHEEN_LEVELS (16) equirectangular RGB maps for the
//   sheen roughness values s_k = 0.07^(1 - k / 15) (evenly spaced in log s from 0.07 to 1), the same
//   integral with the Charlie lobe's integrand at v = d in place of D dot(d, l):
//     S(d, s) = integral of L(l) f(d, l) dot(d, l) dl / integral of f(d, l) dot(d, l) dl,
//   f = D_Charlie V_Charlie (sheen.h). All 256x128 texels; the lobe is integrated over each source
//   texel (up to 8 x 8 points per texel: at s = 0.07 it is a ring about 2 degrees wide just above
//   d's horizon). Between levels S is the linear blend of the two around s in log s (the sheen
//   roughness clamped to [0.07, 1]). Errors against brute force: docs/SHADING.md ("Sheen").
// - Between levels: a table of c(r), the fractional level coordinate, kEnvRoughnessNodes nodes at
//   r = i / 100 (linear in between; each level's r is a node where c is the level's index).
//   l = floor(c), f = c - l (l at most level_count - 2), P = the levels l and l + 1, each bilinear:
//     l = 0 (r < 0.2): (1 - f) * P_0 + f * P_1 with f = r / 0.2, a plain blend of the image and the
//       r = 0.2 level, not an approximation of P with a stated error;
//     l >= 1: per channel P_l * (P_{l+1} / P_l)^f when both are > 0 (else the linear blend), with
//       f chosen so that a point light at d (whose P goes like 1 / (alpha^2 N(alpha)), N the
//       normalization integral) is interpolated exactly: f = log(p(r) / p(r_l)) / log(p(r_{l+1}) /
//       p(r_l)), p the point peak. Linear blending between levels 0.05 apart was 10% off at a sun.
// - The split-sum terms (A, B)(dot(n, v), r) of DESIGN 4b's F (Schlick), D (GGX) and height-
//   correlated Smith Vis: integral of f_spec * dot(n, l) dl = F0 * A + B. A kEnvSplitSumSize^2
//   table, nodes at dot(n, v) = (i / (N - 1))^2 (denser at grazing angles, where A changes fast) and
//   r = j / (N - 1), bilinear in (sqrt(dot(n, v)), r), computed at build time (independent of the
//   environment; split_sum_integral.h) with 8192 Hammersley GGX samples per node; r = 0 is exact
//   (A = 1 - (1 - dot(n, v))^5, B = (1 - dot(n, v))^5).
//
// Flat layout for upload (EnvironmentTables::data, 32-bit floats; EnvTablesHeader says where):
//   [levels]     level k: width_k * (height_k + 2) texels of 4 floats (R, G, B, 0), rows top to
//                bottom, starting at float offset levels[k].offset: a north pole row, the level's
//                rows, a south pole row. Lookups clamp v half a texel beyond the outer rows'
//                centers, and interpolate there between the outer row and its pole row. Level 0's
//                pole rows repeat its outer rows (clamped, as the map is defined); a prefiltered
//                level's hold 2 m - t beside each outer texel t, m the outer row's mean, so that the
//                lookup at the pole itself reads m: the mean of the ring of texels around the pole,
//                where clamping would read the ring's texel at the direction's longitude, 1.4 degrees
//                off the pole in a 128x64 level (2% of I at +Y under the studio).
//   [roughness]  kEnvRoughnessNodes floats at roughness_offset: c(r) at r = i / (nodes - 1)
//                The sheen levels follow the GGX levels (header sheen_first = level_count).
//   [split sum]  kEnvSplitSumSize^2 nodes of 2 floats (A, B) at split_sum_offset, node (i, j) =
//                (dot(n, v) = (i / (N - 1))^2, r = j / (N - 1)) at split_sum_offset + 2 * (j * N + i)
// For a 1024x512 image: 4 x (1024 x 514 + 2 x 512 x 258 + 3 x 256 x 130 + 9 x 128 x 66) floats +
// 101 + 8192, about 3.8 M floats (15 MB). The uniform environment (no image; radiance 0.2) has 1x1 levels.
//
// Cost: per level H^2 / 4 complex FFTs of length W and 3 H^2 W / 2 multiply-adds; about 1 s for a
// 1024x512 image on 2 cores (measured: docs/SHADING.md). Accuracy against brute-force integration:
// docs/SHADING.md and tests/test_environment.cpp.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "pmr/shared.h"

namespace pmr {

constexpr int kEnvMaxLevels = PMR_ENV_MAX_LEVELS;
constexpr int kEnvRoughnessNodes = 101;  // r = 0, 0.01, ..., 1: every level's r is a node
constexpr int kEnvSplitSumSize = 64;
constexpr int kEnvMaxBaseWidth = 4096;  // level 0 is box-downsampled by 2 until it is at most this wide
// Memory budget for an image: at most kEnvMaxTexels texels (8192x4096; decoding needs at most
// 16 bytes per texel, 512 MiB) and, for .hdr, a file of at most kEnvMaxFileBytes.
constexpr uint64_t kEnvMaxTexels = uint64_t(1) << 25;
constexpr uint64_t kEnvMaxSide = uint64_t(1) << 14;  // texels on a side (an image 2:1 wide reaches the total first)
// Peak host memory of decoding and prefiltering an image, per texel of the image (an 8192x4096 .hdr
// peaked at 1.46 GB: 44 bytes a texel), counted against the memory budget before decoding.
constexpr uint64_t kEnvBytesPerTexel = 48;
constexpr uint64_t kEnvMaxFileBytes = uint64_t(1) << 28;

// The description of EnvironmentTables::data, shared with the kernels (include/pmr/shared.h).
using EnvLevel = PmrEnvLevel;
using EnvTablesHeader = PmrEnvironment;

struct EnvironmentTables {
  EnvTablesHeader header{};
  std::vector<float> data;
};

// Linear radiance, row 0 at the top, 3 floats (R, G, B) per texel.
struct EnvironmentImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
};

// Reads FILE.hdr (Radiance RGBE) or FILE.exr (R, G, B channels or Y; half, float or uint; the data
// window). Throws pmr::Error, one line naming the file, for: an unknown extension, a missing or
// unreadable file, a truncated or corrupt one, a zero or over-budget size, a negative or non-finite
// value (naming the first such pixel, column and row from the top-left; see check_environment_image
// for the tiny negative values lossy compression leaves, which read as 0).
EnvironmentImage load_environment_image(const std::string& path);

// Checks the image (size, finite non-negative values) and sets negative values down to
// -kEnvNegativeTolerance x the image's mean value (lossy-compression noise) to 0; throws pmr::Error
// mentioning `name` and the first bad pixel otherwise.
constexpr double kEnvNegativeTolerance = 1e-2;
void check_environment_image(EnvironmentImage& image, const std::string& name);

// What lights a pbr scene besides its own lights (--environment): the built-in studio (the default),
// the uniform environment of radiance 0.2 (with the default light), or an image file.
struct EnvironmentSource {
  enum class Kind { Studio, Uniform, File };
  Kind kind = Kind::Studio;
  std::string file;  // Kind::File: the path as given

  // "studio" and "uniform" are the keywords; anything else is a file ("./studio" for a file of that
  // name). Throws pmr::Error for an empty text.
  static EnvironmentSource parse(const std::string& text);
  // The keyword or the file as given.
  std::string name() const;
  bool operator==(const EnvironmentSource& o) const { return kind == o.kind && file == o.file; }
};

struct EnvironmentOptions {
  EnvironmentSource source;
  double rotation_deg = 0.0;  // counter-clockwise seen from above
  double intensity = 1.0;     // >= 0; 0 turns the environment off
  // With shadows on (DESIGN 4d) the studio's boxes (Environment::studio_walls) and an image's
  // brightest regions (take_out_bright_regions) are taken out and drawn as shadowed distant lights;
  // off keeps them in the image.
  bool take_out_lights = false;
  double uniform_radiance = 0.2;  // the radiance of the uniform environment (DESIGN 4b: 0.2)
};

class Environment {
 public:
  // The uniform environment of the given radiance (before intensity).
  static Environment uniform(double radiance = 0.2);
  // Prefilters an image (checked with check_environment_image).
  static Environment from_image(const EnvironmentImage& image, const std::string& name = "environment");
  // The built-in studio (studio_environment.h), prefiltered at build time: from_image of
  // studio_environment_image(), bit for bit, without the wait.
  static Environment studio();
  // The studio's walls alone (studio_walls_image, prefiltered here: 0.27-0.31 s on 2 cores),
  // with its boxes as distant_lights(): what the studio is with shadows on.
  static Environment studio_walls();
  // An image (checked here) with its brightest regions taken out as distant_lights()
  // (take_out_bright_regions, shading/environment_lights.h), the rest prefiltered.
  static Environment with_lights_taken_out(EnvironmentImage image, const std::string& name);
  // studio(), uniform() or load_environment_image + from_image as the source says; then the rotation
  // and intensity (which must be finite, intensity >= 0).
  static Environment make(const EnvironmentOptions& options);

  void set_rotation(double degrees);
  void set_intensity(double intensity);

  // Host-side evaluation from exactly the tables (as cl/environment.h samples them on the device),
  // intensity and rotation applied; directions need not be unit length (zero vectors read +Y).
  glm::dvec3 radiance(const glm::dvec3& d) const;                 // the map: P(d, 0)
  glm::dvec3 irradiance(const glm::dvec3& n) const;               // I(n) = P(n, 1)
  glm::dvec3 prefiltered(const glm::dvec3& d, double r) const;    // P(d, r), r clamped to [0, 1]
  glm::dvec3 sheen(const glm::dvec3& d, double s) const;          // S(d, s), s clamped to [0.07, 1]
  glm::dvec3 level_sample(int level, const glm::dvec3& d) const;  // one level, bilinear

  // The lights taken out of the environment (studio_walls' boxes, an image's bright regions; none
  // otherwise), world space: turned by the rotation and scaled by the intensity as the tables are;
  // none at intensity 0.
  std::vector<SceneLight> distant_lights() const;

  const EnvironmentTables& tables() const { return tables_; }
  double prefilter_seconds() const { return prefilter_seconds_; }  // wall time of from_image; 0: studio()'s

 private:
  EnvironmentTables tables_;
  double prefilter_seconds_ = 0.0;
  std::vector<SceneLight> distant_;  // unrotated, at intensity 1
};

// The environment a run's pipelines share (PipelineConfig::environment), made once: null for the
// uniform one, whose radiance the kernels take from the frame's parameters.
std::shared_ptr<const Environment> make_pipeline_environment(const EnvironmentOptions& options);

// One line for the log: "studio: 512x256, prefiltered when pmr was built (9.2 MB of tables)", "FILE:
// 1024x512, prefiltered in 0.33 s (15.4 MB of tables)" or "uniform (radiance 0.2 x intensity)"; `e`
// is the source's environment (null for the uniform one).
std::string environment_summary(const EnvironmentSource& source, const Environment* e);

// (A, B) for (dot(n, v), r) from the table (bilinear; arguments clamped to [0, 1]).
glm::dvec2 split_sum(double n_dot_v, double r);
// The table itself: kEnvSplitSumSize^2 nodes of (A, B), node (i, j) at 2 * (j * N + i). Computed
// at build time (shading/split_sum_integral.h), so no process pays for it.
const std::vector<float>& split_sum_table();

// The roughness of each prefiltered level after level 0, and c(r) (the fractional level coordinate).
const std::vector<double>& environment_level_roughness();
double environment_level_coordinate(double r);
// The sheen roughness of each sheen level.
const std::vector<double>& environment_sheen_roughness();

}  // namespace pmr
