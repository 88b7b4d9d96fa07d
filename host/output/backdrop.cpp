#include "output/backdrop.h"

#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "scene/motion.h"
#include "shading/environment.h"

namespace pmr {

namespace {

// The largest |s_{i+1} - s_i| / D over neighbouring cameras (the rendered, quantized offsets).
double largest_camera_step(const Rig& rig) {
  double step = 0.0;
  for (int i = 0; i + 1 < rig.views; ++i)
    step = std::max(step, std::abs(rig.camera_offset(i + 1) - rig.camera_offset(i)) / rig.focal);
  return step;
}

// View pixels of disparity per unit of s / D at f = 1: W / (2 A t).
double pixels_per_offset(const Rig& rig) { return double(rig.view_w) / (2.0 * rig.aspect * std::tan(rig.yfov / 2.0)); }

}  // namespace

BackdropParallax backdrop_parallax(const Rig& rig, const BackdropDepth& depth) {
  BackdropParallax p;
  const double wanted = depth.kind == BackdropDepth::Kind::Focal      ? 0.0
                        : depth.kind == BackdropDepth::Kind::Infinity ? 1.0
                                                                      : 1.0 - rig.focal / depth.distance;
  const double unit_step = largest_camera_step(rig) * pixels_per_offset(rig);  // at f = 1
  const double limit = unit_step > 0.0 ? std::min(1.0, kBackdropMaxStepPx / unit_step) : 1.0;
  p.fraction = std::clamp(wanted, 0.0, limit);
  p.clamped = p.fraction != wanted;
  p.step_px = p.fraction * unit_step;
  return p;
}

bool same_backdrop_rig(const Rig& a, const Rig& b) {
  return a.views == b.views && a.view_w == b.view_w && a.view_h == b.view_h && a.yfov == b.yfov && a.cone == b.cone &&
         a.aspect == b.aspect && a.focal == b.focal && a.angular == b.angular && a.spacing_q == b.spacing_q &&
         a.center_view == b.center_view;
}

BackdropRays::BackdropRays(const Rig& rig, double fraction)
    : rig_(rig),
      fraction_(fraction),
      tan_half_(std::tan(rig.yfov / 2.0)),
      to_world_(glm::inverse(glm::dmat3(rig.center_view))) {}  // directions turn with the inverse linear part

glm::dvec3 BackdropRays::direction(int view, int x, int y) const {
  const double sx = (2.0 * (x + 0.5) / rig_.view_w - 1.0) * rig_.aspect * tan_half_ -
                    fraction_ * rig_.camera_offset(view) / rig_.focal;
  const double sy = (1.0 - 2.0 * (y + 0.5) / rig_.view_h) * tan_half_;
  return to_world_ * glm::dvec3(sx, sy, -1.0);
}

std::vector<uint16_t> render_backdrop(const Rig& rig, const Environment& environment, double fraction) {
  const size_t plane = size_t(rig.view_w) * size_t(rig.view_h);
  std::vector<uint16_t> out(plane * size_t(rig.views) * 4);
  const int computed = fraction == 0.0 ? 1 : rig.views;  // on the focal plane every view is view 0's
  const BackdropRays rays(rig, fraction);
  parallel_for(size_t(computed) * size_t(rig.view_h), 8, [&](size_t begin, size_t end) {
    for (size_t row = begin; row < end; ++row) {
      const int view = int(row / size_t(rig.view_h)), y = int(row % size_t(rig.view_h));
      uint16_t* px = out.data() + row * size_t(rig.view_w) * 4;
      for (int x = 0; x < rig.view_w; ++x, px += 4) {
        const glm::dvec3 c = environment.radiance(rays.direction(view, x, y));
        px[0] = half(float(c.r)).bits(), px[1] = half(float(c.g)).bits(), px[2] = half(float(c.b)).bits();
        px[3] = half(1.0f).bits();
      }
    }
  });
  for (int v = computed; v < rig.views; ++v)
    std::memcpy(out.data() + size_t(v) * plane * 4, out.data(), plane * 4 * sizeof(uint16_t));
  return out;
}

}  // namespace pmr
