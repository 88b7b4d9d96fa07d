#include "quality/samples_quality.h"

#include <algorithm>
#include <cmath>

#include <Imath/half.h>

#include "pipeline/pipeline.h"
#include "pmr/error.h"
#include "sequence/frame_renderer.h"

namespace pmr {

std::vector<float> clamped_volume(const std::vector<uint16_t>& halves) {
  std::vector<float> out(halves.size());
  for (size_t i = 0; i < halves.size(); ++i) {
    Imath::half h;
    h.setBits(halves[i]);
    out[i] = std::clamp(float(h), 0.0f, 1.0f);  // NaN stays NaN: it shows in the error
  }
  return out;
}

std::vector<float> downsample_2x2(const std::vector<float>& fine, int views, int w, int h) {
  std::vector<float> out(size_t(views) * w * h * 4);
  for (size_t v = 0; v < size_t(views); ++v)
    for (size_t y = 0; y < size_t(h); ++y)
      for (size_t x = 0; x < size_t(w); ++x)
        for (size_t c = 0; c < 4; ++c) {
          auto at = [&](size_t fy, size_t fx) { return fine[((v * 2 * h + fy) * 2 * w + fx) * 4 + c]; };
          out[((v * h + y) * w + x) * 4 + c] =
              0.25f * (at(2 * y, 2 * x) + at(2 * y, 2 * x + 1) + at(2 * y + 1, 2 * x) + at(2 * y + 1, 2 * x + 1));
        }
  return out;
}

namespace {

// Whether reference pixel (x, y) of view v is an edge pixel (compare_views).
bool is_edge(const std::vector<float>& ref, size_t v, int x, int y, int w, int h) {
  auto px = [&](int xx, int yy) { return &ref[((v * size_t(h) + size_t(yy)) * size_t(w) + size_t(xx)) * 4]; };
  const float alpha = px(x, y)[3];
  if (alpha > 0.0f && alpha < 1.0f) return true;
  for (int c = 0; c < 4; ++c) {
    float lo = INFINITY, hi = -INFINITY;
    for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
      for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx)
        lo = std::min(lo, px(xx, yy)[c]), hi = std::max(hi, px(xx, yy)[c]);
    if (hi - lo > kEdgeVariation) return true;
  }
  return false;
}

std::vector<float> render_views(const ClRuntime& rt, const Scene& scene, const RigConfig& rc, const Display& display,
                                PipelineConfig pc, int samples, double& render_ms) {
  SequenceSpec spec;
  select_animation(scene, "", spec);
  FrameRenderer renderer(scene, spec, rc, display, nullptr);
  pc.samples = samples;
  pc.fuse_encode = false;  // the views themselves
  Pipeline p(rt, pc);
  renderer.attach(p, nullptr);
  renderer.render(0);  // warm-up
  render_ms = renderer.render(0).times.wall;
  std::vector<uint16_t> volume;
  p.read_volume(volume);
  return clamped_volume(volume);
}

}  // namespace

ViewDifference compare_views(const std::vector<float>& image, const std::vector<float>& reference, int views, int w,
                             int h) {
  if (image.size() != reference.size() || image.size() != size_t(views) * w * h * 4 || image.empty())
    throw InternalError("comparing view volumes of different sizes");
  double sum = 0.0, edge_sum = 0.0;
  size_t edges = 0;
  for (size_t v = 0; v < size_t(views); ++v)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t at = ((v * size_t(h) + size_t(y)) * size_t(w) + size_t(x)) * 4;
        double d2 = 0.0;
        for (size_t c = 0; c < 4; ++c)
          d2 += double(image[at + c] - reference[at + c]) * (image[at + c] - reference[at + c]);
        sum += d2;
        if (!is_edge(reference, v, x, y, w, h)) continue;
        edge_sum += d2;
        ++edges;
      }
  const double pixels = double(views) * w * h;
  ViewDifference r;
  r.rmse = std::sqrt(sum / (4.0 * pixels));
  r.edge_rmse = edges ? std::sqrt(edge_sum / (4.0 * double(edges))) : 0.0;
  r.edge_fraction = double(edges) / pixels;
  return r;
}

std::vector<SamplesQualityRow> samples_quality(const ClRuntime& rt, const Scene& scene, const RigConfig& rig,
                                               const Display& display, const PipelineConfig& config,
                                               const std::vector<int>& samples) {
  if (2 * rig.view_w > PMR_MAX_RASTER || 2 * rig.view_h > PMR_MAX_RASTER)
    throw Error("the reference views (" + std::to_string(rig.view_w) + "x" + std::to_string(rig.view_h) +
                " times 2) exceed " + std::to_string(PMR_MAX_RASTER) + " px; use a smaller --view-size");
  RigConfig fine = rig;
  fine.view_w *= 2, fine.view_h *= 2;
  double ms = 0.0;
  const std::vector<float> reference =
      downsample_2x2(render_views(rt, scene, fine, display, config, 16, ms), rig.views, rig.view_w, rig.view_h);
  std::vector<SamplesQualityRow> rows;
  for (int s : samples) {
    SamplesQualityRow row;
    row.samples = s;
    row.error = compare_views(render_views(rt, scene, rig, display, config, s, row.render_ms), reference, rig.views,
                              rig.view_w, rig.view_h);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace pmr
