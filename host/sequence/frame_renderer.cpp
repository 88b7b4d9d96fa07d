#include "sequence/frame_renderer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "pmr/error.h"
#include "pmr/printable.h"
#include "scene/ground_catcher.h"
#include "scene/motion.h"
#include "sequence/frame_work.h"

namespace pmr {

void select_animation(const Scene& scene, const std::string& choice, SequenceSpec& spec) {
  const auto& a = scene.animations;
  auto label = [&](size_t i) { return a[i].name.empty() ? "#" + std::to_string(i) : a[i].name; };
  if (choice.empty()) {
    spec.animation = a.empty() ? kNoAnimation : 0;
    spec.animation_label = a.empty() ? "" : label(0);
    return;
  }
  if (choice == "none") {  // the rest pose (a clip named "none" is chosen by its index)
    spec.animation = kNoAnimation;
    spec.animation_label = "";
    return;
  }
  if (choice == "all") {
    spec.animation = a.empty() ? kNoAnimation : kAllAnimations;
    spec.animation_label = a.empty() ? "" : "all";
    if (a.empty()) throw Error("--animation all: the scene has no animations");
    return;
  }
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].name == choice) {
      spec.animation = int(i), spec.animation_label = label(i);
      return;
    }
  char* end = nullptr;
  const long index = std::strtol(choice.c_str(), &end, 10);
  if (!choice.empty() && *end == '\0' && index >= 0 && size_t(index) < a.size()) {
    spec.animation = int(index), spec.animation_label = label(size_t(index));
    return;
  }
  std::string known;
  for (size_t i = 0; i < a.size(); ++i)
    known += (known.empty() ? "" : ", ") + std::to_string(i) + " '" + printable_text(a[i].name, 80) + "'";
  throw Error(
      "--animation '" + choice + "': " +
      (a.empty() ? std::string("the scene has no animations") : "no such animation (the scene has " + known + ")"));
}

SequenceSpec resolve_sequence(const Scene& scene, const SequenceChoice& choice, const InputLimits& limits) {
  SequenceSpec spec;
  spec.framing_work = limits.framing_work;
  spec.pose_work = limits.pose_work;
  spec.frame_work = limits.frame_work;
  select_animation(scene, choice.animation, spec);
  spec.fps = choice.fps;
  spec.turntable = choice.turntable;
  spec.turntable_deg = choice.turntable_deg;
  spec.turntable_frames = choice.turntable ? choice.turntable_frames : 1;
  return spec;
}

namespace {

// Clip key range of the selection (empty selection: false).
bool key_range(const Scene& scene, int animation, double& start, double& end) {
  bool any = false;
  for (size_t i = 0; i < scene.animations.size(); ++i) {
    if (animation != kAllAnimations && animation != int(i)) continue;
    start = any ? std::min(start, scene.animations[i].start) : scene.animations[i].start;
    end = any ? std::max(end, scene.animations[i].end) : scene.animations[i].end;
    any = true;
  }
  return any;
}

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

bool animation_key_frames(const Scene& scene, const SequenceSpec& spec, long& first, long& last) {
  double start = 0, end = 0;
  first = 0, last = -1;
  if (spec.animation == kNoAnimation || !key_range(scene, spec.animation, start, end)) return false;
  // The tolerance keeps key times stored as floats on their frames: CesiumMan's first key, 1/24 s as a
  // float, is frame 1.00000003 at 24 fps, and frame 1 it stays.
  const double a = std::ceil(start * spec.fps - 1e-6), b = std::floor(end * spec.fps + 1e-6);
  // The framing poses every frame of the range: refuse absurd ranges (key times near float's
  // maximum, hours of animation) with one line instead of working for days or overflowing.
  if (!(b - std::max(a, 0.0) < double(kMaxFramesPerRun)))
    throw Error("the animation's keys span " + std::to_string(start) + " to " + std::to_string(end) + " s, over " +
                std::to_string(kMaxFramesPerRun) + " frames at " + std::to_string(spec.fps) + " fps");
  // Frames are numbers 0..kMaxFrame: keys wholly before 0 or after kMaxFrame hold none (and a or b
  // beyond a long's range must not be converted at all)
  const double lo = std::max(a, 0.0), hi = std::min(b, double(kMaxFrame));
  if (!(lo <= hi)) return false;
  first = long(lo);
  last = long(hi);
  return true;
}

void animation_frame_range(const Scene& scene, const SequenceSpec& spec, long& first, long& last) {
  if (spec.turntable) {
    first = 0, last = std::max(0L, spec.turntable_frames - 1);
    return;
  }
  if (animation_key_frames(scene, spec, first, last)) return;
  if (spec.animation != kNoAnimation && !scene.animations.empty()) {
    double start = 0, end = 0;
    key_range(scene, spec.animation, start, end);
    char line[200];
    std::snprintf(line, sizeof line,
                  "--frames all: no frame time f / %g lies inside the animation's keys (%g to %g s): "
                  "give --frames or a higher --fps",
                  spec.fps, start, end);
    throw Error(line);
  }
  first = last = 0;
}

PoseRequest FrameRenderer::request(long frame) const {
  PoseRequest r;
  r.time = double(frame) / spec_.fps;
  r.animation = spec_.animation;
  r.turntable = spec_.turntable;
  r.turntable_deg = spec_.turntable ? turntable_angle(frame, spec_.turntable_deg, spec_.turntable_frames) : 0.0;
  r.pivot = pivot();
  return r;
}

namespace {

// True when the sequence's animation moves something (the turntable aside): frames are posed, and the
// framing poses the animation's range.
bool animates_at_all(const Scene& rest, const SequenceSpec& spec) {
  return pose_moves(rest, PoseRequest{0.0, spec.animation});
}

// Both posing budgets, before any posing: one pose (every frame poses once) against pose-work, and
// the framing's poses (the first and last key and every frame between) against framing-work.
void check_pose_work(const Scene& rest, const SequenceSpec& spec) {
  if (!pose_moves(rest, PoseRequest{0.0, spec.animation, spec.turntable})) return;
  const uint64_t work = pose_work(rest, spec.animation);
  const std::string units = " units (docs/SECURITY.md, \"Posing\")";
  if (work > spec.pose_work)
    throw Error("posing one frame of the scene takes " + std::to_string(work) + units +
                ", more than the pose-work limit of " + std::to_string(spec.pose_work) +
                " (raise it with --limit pose-work=N)");
  if (!animates_at_all(rest, spec)) return;
  long first = 0, last = -1;
  animation_key_frames(rest, spec, first, last);
  const uint64_t poses = uint64_t(2 + std::max(0L, last - first + 1));
  if (poses > spec.framing_work / std::max<uint64_t>(1, work))
    throw Error("framing the animation poses the scene " + std::to_string(poses) +
                " times (every frame of its keys at " + std::to_string(spec.fps) + " fps), " + std::to_string(work) +
                units + " each, more than the framing-work limit of " + std::to_string(spec.framing_work) +
                " (raise it with --limit framing-work=N)");
}

// Framing: the union of the bounds of the animation's first and last pose (what frames outside its
// keys repeat) and of every frame inside its keys, without the turntable (its sphere is centered on
// the pivot, so turning does not change it). False when nothing has bounds (no triangles).
bool frame_bounds(const Scene& rest, const SequenceSpec& spec, glm::dvec3& lo, glm::dvec3& hi) {
  if (!animates_at_all(rest, spec)) return scene_bounds(rest, lo, hi);
  double start = 0.0, end = 0.0;
  key_range(rest, spec.animation, start, end);
  long first = 0, last = -1;
  animation_key_frames(rest, spec, first, last);
  std::vector<double> times{start, end};
  for (long f = first; f <= last; ++f) times.push_back(double(f) / spec.fps);
  bool any = false;
  Scene posed;
  for (double t : times) {
    pose_scene(rest, PoseRequest{t, spec.animation}, posed);
    glm::dvec3 l, h;
    if (scene_bounds(posed, l, h)) {
      lo = any ? glm::min(lo, l) : l;
      hi = any ? glm::max(hi, h) : h;
      any = true;
    }
  }
  return any;
}

// Whether a part of the triangle lies where the raised near plane cut it off from some view: between
// the requested and the raised near planes (w is the same in every view) and inside the union of the
// views' frusta, which nearer than the focal plane is bounded by view 0's left plane and view N-1's right
// one. The six bounds are affine in the point, so the triangle is clipped on their values alone.
bool cut_by_raised_near(const double (&bounds)[6][3]) {
  std::vector<std::array<double, 6>> poly(3), next;
  for (int v = 0; v < 3; ++v)
    for (int k = 0; k < 6; ++k) poly[size_t(v)][size_t(k)] = bounds[k][v];
  for (size_t k = 0; k < 6 && poly.size() >= 3; ++k) {
    next.clear();
    for (size_t i = 0; i < poly.size(); ++i) {
      const auto& a = poly[i];
      const auto& b = poly[(i + 1) % poly.size()];
      if (a[k] >= 0.0) next.push_back(a);
      if ((a[k] >= 0.0) != (b[k] >= 0.0)) {
        const double t = a[k] / (a[k] - b[k]);
        std::array<double, 6> m;
        for (size_t j = 0; j < 6; ++j) m[j] = a[j] + t * (b[j] - a[j]);
        next.push_back(m);
      }
    }
    poly.swap(next);
  }
  return poly.size() >= 3;
}

// Triangles of which the raised near plane hides a part that some view would show: what the raise cost.
uint64_t count_near_clipped(const Scene& placed, const Rig& rig) {
  if (!(rig.near_eff > rig.near) || rig.views < 1) return 0;
  const glm::dmat4 first = rig.projection(0) * rig.view_matrix(0);
  const glm::dmat4 last = rig.projection(rig.views - 1) * rig.view_matrix(rig.views - 1);
  uint64_t n = 0;
  for (const PmrTriangle& t : placed.triangles) {
    double bounds[6][3];  // >= 0 inside
    for (int v = 0; v < 3; ++v) {
      const glm::dvec4 p(glm::dvec3(placed.positions[t.v[size_t(v)]]), 1.0);
      const glm::dvec4 a = first * p, b = last * p;  // the same w and y in every view
      bounds[0][v] = a.w - rig.near, bounds[1][v] = rig.near_eff - a.w;
      bounds[2][v] = a.x + a.w, bounds[3][v] = b.w - b.x;
      bounds[4][v] = a.w - a.y, bounds[5][v] = a.w + a.y;
    }
    n += cut_by_raised_near(bounds);
  }
  return n;
}

}  // namespace

FrameRenderer::FrameRenderer(const Scene& rest, const SequenceSpec& spec, const RigConfig& rig_config,
                             const Display& display, std::vector<std::string>* warnings)
    : rest_(rest), spec_(spec), rig_config_(rig_config), display_(display) {
  if (!(spec.fps > 0.0) || !std::isfinite(spec.fps)) throw Error("invalid --fps: must be a positive number");
  if (rig_config.camera >= 0) {
    if (rig_config.camera >= int(rest.cameras.size()))
      throw Error("--camera " + std::to_string(rig_config.camera) + ": the scene has " +
                  std::to_string(rest.cameras.size()) + " camera(s)");
    const SceneCamera& cam = rest.cameras[size_t(rig_config.camera)];
    const std::string k = "--camera " + std::to_string(rig_config.camera);
    if (!cam.perspective) throw Error(k + " is an orthographic camera: only perspective cameras drive the rig");
    if (!cam.placed) throw Error(k + " is not placed by any node of the scene");
    if (!cam.invalid.empty()) throw Error(k + " has invalid perspective parameters: " + cam.invalid);
  }
  check_pose_work(rest, spec);
  glm::dvec3 lo, hi;
  const bool any = frame_bounds(rest, spec, lo, hi);
  if (any) lo_ = lo, hi_ = hi;
  else if (warnings) warnings->push_back("nothing to frame (no triangles): framing a unit cube at the origin");
  moves_ = pose_moves(rest, request(0));
  camera_moves_ = rig_config.camera >= 0 && spec.animation != kNoAnimation && rest.motion &&
                  size_t(rig_config.camera) < rest.motion->camera_node.size() &&
                  rest.motion->camera_node[size_t(rig_config.camera)] >= 0;
  rig_ = rig_for(rest, warnings);
}

Rig FrameRenderer::rig_for(const Scene& posed, std::vector<std::string>* warnings) const {
  const glm::dmat4* pose = nullptr;
  double yfov = 0.0;
  if (rig_config_.camera >= 0) {
    pose = &posed.cameras[size_t(rig_config_.camera)].world_from_camera;
    yfov = posed.cameras[size_t(rig_config_.camera)].yfov;
  }
  const double aspect = rig_config_.camera >= 0 ? posed.cameras[size_t(rig_config_.camera)].aspect : 0.0;
  return make_rig(rig_config_, display_, lo_, hi_, pose, yfov, warnings, aspect);
}

void FrameRenderer::attach(Pipeline& pipeline, const Display* encode_display) {
  pipeline_ = &pipeline;
  if (rest_.triangles.empty()) return;  // every frame is transparent: the pipeline is never run
  if (pipeline.config().ground_shadow) {
    // over every view's footprint: as far from the pivot as the far plane reaches
    const glm::dvec3 eye(glm::inverse(rig_.center_view)[3]);
    const Scene catcher = make_ground_catcher(lo_, hi_, rig_.far + glm::length(eye - pivot()));
    pipeline.set_scene(rest_, &catcher);
  } else {
    pipeline.set_scene(rest_);
  }
  pipeline.configure(rig_, encode_display);
}

FrameRenderer::Frame FrameRenderer::render(long frame) {
  if (!pipeline_) throw Error("FrameRenderer::render before attach");
  Frame out;
  out.number = frame;
  const PoseRequest r = request(frame);
  out.time = r.time;
  out.angle = r.turntable_deg;
  if (rest_.triangles.empty()) {  // nothing is rendered; the sidecar still records the rig and lights
    const FrameDescription d = describe(frame, pipeline_->config());
    out.rig = d.rig, out.lights = d.lights;
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (moves_) {
    const bool changed = pose_scene(rest_, r, posed_);
    out.pose_ms = ms_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    if (changed) pipeline_->update_geometry(posed_);
    out.upload_ms = ms_since(t1);
  }
  // the lights every frame: an animation may move a light and no geometry
  const FrameDescription d = describe_posed(moves_ ? posed_ : rest_, pipeline_->config());
  out.rig = d.rig, out.lights = d.lights;
  const PipelineConfig& config = pipeline_->config();
  const bool shadows = config.shadows && config.shading == Shading::Pbr;
  check_frame_work(
      estimate_frame_work(moves_ ? posed_ : rest_, d.rig, light_evaluations_per_point(d.lights), config,
                          shadows ? shadow_cost(d.lights, d.occlusion.size(), config.shadow_sizes) : ShadowCost{}),
      spec_.frame_work);
  out.times = pipeline_->render(d);
  out.visible = out.times.mtas > 0;
  out.near_clipped = count_near_clipped(moves_ ? posed_ : rest_, d.rig);
  return out;
}

FrameDescription FrameRenderer::describe_posed(const Scene& placed, const PipelineConfig& config) const {
  return describe_frame(camera_moves_ ? rig_for(placed, nullptr) : rig_, placed.lights, config);
}

FrameDescription FrameRenderer::describe(long frame, const PipelineConfig& config) const {
  if (!moves_) return describe_posed(rest_, config);
  Scene placed;
  pose_cameras_and_lights(rest_, request(frame), placed);
  return describe_posed(placed, config);
}

}  // namespace pmr
