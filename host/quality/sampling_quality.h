// How close each sampling of the display comes to what the display would show from a much finer
// rendering (issue: "render exactly what the display shows"). The reference is --sampling view with
// views `scale` times wider and taller, interlaced with nearest sampling (as Fink et al. 2023 use a
// high-resolution render as ground truth); the candidates are --sampling subpixel, --sampling view at
// the configured size, and --sampling view --bilinear. docs/SAMPLING.md has the tables.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pmr/rig.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"

namespace pmr {

// Differences between two encoded display images (half RGBA) over every subpixel's colour channel
// (channel k of display pixel j is subpixel 3j + k; alpha is not compared), in linear units.
struct ImageDifference {
  double rmse = 0.0;        // root mean square difference of the linear values
  double rmse_shown = 0.0;  // the same with every value clamped to [0, 1], as a panel shows it: one
                            // highlight of 10^4 (or an infinite half) cannot decide the comparison
  double differing = 0.0;   // fraction of subpixels differing by more than kDifferingThreshold
};
constexpr double kDifferingThreshold = 1.0 / 256.0;
ImageDifference compare_display_images(const std::vector<uint16_t>& a, const std::vector<uint16_t>& b);

struct SamplingQualityRow {
  std::string name;  // "subpixel", "view", "view --bilinear", and "reference" (first)
  int view_w = 0, view_h = 0;
  double samples = 0.0;    // samples rasterized per frame: voxels, or display subpixels
  double render_ms = 0.0;  // one frame after a warm-up (indicative; pmr bench measures speed)
  ImageDifference error;   // against the reference
};
// Frame 0 of `scene` with the rig and display given; throws pmr::Error when the reference views would
// exceed the raster limit (8192 px). `extra_view_sizes` adds rows of --sampling view at other view
// sizes (the cost of matching subpixel sampling's error by rendering larger views).
std::vector<SamplingQualityRow> sampling_quality(const ClRuntime& rt, const Scene& scene, const RigConfig& rig,
                                                 const Display& display, int scale,
                                                 const std::vector<std::pair<int, int>>& extra_view_sizes = {});

}  // namespace pmr
