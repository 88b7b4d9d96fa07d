// How close each samples-per-pixel setting (DESIGN section 3b) comes to a finer reference, on the views
// themselves: the reference is the same views rendered twice as wide and tall with 16 samples per pixel
// and box-filtered 2x2, 64 samples per pixel (four times the most a setting takes). docs/ANTIALIASING.md
// has the tables.
#pragma once
#include <vector>

#include "pipeline/pipeline_config.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"

namespace pmr {

// Differences between two view volumes ([view][y][x][RGBA], premultiplied, linear) with colour clamped to
// [0, 1]: over every pixel, and over the edge pixels: those whose reference alpha lies strictly between
// 0 and 1, or whose 3x3 neighbourhood in the reference varies by more than kEdgeVariation in some
// channel.
struct ViewDifference {
  double rmse = 0.0, edge_rmse = 0.0;
  double edge_fraction = 0.0;  // of the pixels
};
constexpr double kEdgeVariation = 0.1;
ViewDifference compare_views(const std::vector<float>& image, const std::vector<float>& reference, int views, int w,
                             int h);

// A volume of half RGBA bits as floats, colour clamped to [0, 1].
std::vector<float> clamped_volume(const std::vector<uint16_t>& halves);
// Box filter by 2 in x and y of a [view][2h][2w][4] volume into [view][h][w][4].
std::vector<float> downsample_2x2(const std::vector<float>& fine, int views, int w, int h);

struct SamplesQualityRow {
  int samples = 1;
  double render_ms = 0.0;  // one frame after a warm-up (indicative; pmr bench measures speed)
  ViewDifference error;    // against the reference
};
// Frame 0 of `scene` with the rig given for `display` (its aspect; nothing is encoded), shaded as
// `config` says (its samples and fusing are set here), at each entry of `samples`; throws pmr::Error when
// the reference views would exceed the raster limit.
std::vector<SamplesQualityRow> samples_quality(const ClRuntime& rt, const Scene& scene, const RigConfig& rig,
                                               const Display& display, const PipelineConfig& config,
                                               const std::vector<int>& samples);

}  // namespace pmr
