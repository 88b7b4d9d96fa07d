#include "quality/sampling_quality.h"

#include <algorithm>
#include <cmath>

#include <Imath/half.h>

#include "pipeline/pipeline.h"
#include "pmr/error.h"
#include "sequence/frame_renderer.h"

namespace pmr {

ImageDifference compare_display_images(const std::vector<uint16_t>& a, const std::vector<uint16_t>& b) {
  if (a.size() != b.size() || a.empty()) throw InternalError("comparing display images of different sizes");
  double sum = 0.0, sum_shown = 0.0;
  size_t differing = 0, n = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;  // alpha
    Imath::half ha, hb;
    ha.setBits(a[i]);
    hb.setBits(b[i]);
    const double d = double(float(ha)) - double(float(hb));
    sum += d * d;
    const double shown = std::clamp(double(float(ha)), 0.0, 1.0) - std::clamp(double(float(hb)), 0.0, 1.0);
    sum_shown += shown * shown;  // NaN clamps to NaN: a NaN stays visible
    differing += std::abs(d) > kDifferingThreshold;
    ++n;
  }
  ImageDifference r;
  r.rmse = std::sqrt(sum / double(n));
  r.rmse_shown = std::sqrt(sum_shown / double(n));
  r.differing = double(differing) / double(n);
  return r;
}

namespace {

std::vector<uint16_t> render_display(const ClRuntime& rt, const Scene& scene, RigConfig rc, const Display& display,
                                     Sampling sampling, SamplingQualityRow& row) {
  SequenceSpec spec;
  select_animation(scene, "", spec);
  FrameRenderer renderer(scene, spec, rc, display, nullptr);
  PipelineConfig pc;
  pc.sampling = sampling;
  pc.fuse_encode = true;  // the encoded-only job (bilinear sampling keeps the view volume by itself)
  Pipeline p(rt, pc);
  renderer.attach(p, &display);
  renderer.render(0);  // warm-up
  row.render_ms = renderer.render(0).times.wall;
  row.view_w = rc.view_w, row.view_h = rc.view_h;
  row.samples =
      sampling == Sampling::Subpixel ? 3.0 * display.width * display.height : double(rc.views) * rc.view_w * rc.view_h;
  std::vector<uint16_t> image;
  p.read_display(image);
  return image;
}

}  // namespace

std::vector<SamplingQualityRow> sampling_quality(const ClRuntime& rt, const Scene& scene, const RigConfig& rig,
                                                 const Display& display, int scale,
                                                 const std::vector<std::pair<int, int>>& extra_view_sizes) {
  if (scale < 1 || rig.view_w * scale > PMR_MAX_RASTER || rig.view_h * scale > PMR_MAX_RASTER)
    throw Error("the reference views (" + std::to_string(rig.view_w) + "x" + std::to_string(rig.view_h) + " times " +
                std::to_string(scale) + ") exceed " + std::to_string(PMR_MAX_RASTER) +
                " px; use a smaller --view-size");
  std::vector<SamplingQualityRow> rows(4);
  rows[0].name = "reference";
  RigConfig fine = rig;
  fine.view_w *= scale, fine.view_h *= scale;
  Display nearest = display;
  nearest.bilinear = false;
  nearest.blend_views = false;
  const std::vector<uint16_t> reference = render_display(rt, scene, fine, nearest, Sampling::View, rows[0]);
  rows[1].name = "subpixel";
  rows[2].name = "view";
  rows[3].name = "view --bilinear";
  Display bilinear = nearest;
  bilinear.bilinear = true;
  const std::vector<uint16_t> images[3] = {render_display(rt, scene, rig, nearest, Sampling::Subpixel, rows[1]),
                                           render_display(rt, scene, rig, nearest, Sampling::View, rows[2]),
                                           render_display(rt, scene, rig, bilinear, Sampling::View, rows[3])};
  for (int k = 0; k < 3; ++k) rows[size_t(k) + 1].error = compare_display_images(images[k], reference);
  for (const auto& size : extra_view_sizes) {
    SamplingQualityRow row;
    row.name = "view";
    RigConfig larger = rig;
    larger.view_w = size.first, larger.view_h = size.second;
    row.error = compare_display_images(render_display(rt, scene, larger, nearest, Sampling::View, row), reference);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace pmr
