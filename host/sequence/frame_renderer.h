// One frame of a sequence, the same for `pmr render` and `pmr bench`: the scene posed at the frame's
// time (animation) and angle (turntable), uploaded if it moved (its lights every frame), the rig (fixed, or following an animated
// glTF camera), and the pipeline run. The framing is computed once over the chosen animation's whole
// time range, its first and last pose included (DESIGN section 7), so any frame renders the same alone
// as inside a longer sequence.
#pragma once
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "sequence/frame_list.h"
#include "sequence/sequence_spec.h"
#include "pmr/input_files.h"
#include "pmr/rig.h"
#include "pmr/scene.h"

namespace pmr {

// Resolves --animation (NAME, INDEX, all, or none = the rest pose; empty = the first animation if there
// is one) against the scene's clips. Throws pmr::Error naming the known animations when nothing
// matches.
void select_animation(const Scene& scene, const std::string& choice, SequenceSpec& spec);
// The sequence `choice` makes of `scene`: its animation selected (select_animation), one turntable frame
// without a turntable, `framing_work` the framing's budget.
SequenceSpec resolve_sequence(const Scene& scene, const SequenceChoice& choice, const InputLimits& limits);

// The frames whose times f / fps lie inside the chosen animation's key range: ceil(start * fps) to
// floor(end * fps) (within 1e-6 of a frame: float key times). Outside it a frame repeats the first or
// the last pose (glTF clamps). Returns false, with last < first, when no frame time lies inside, and
// when no animation is chosen. Throws pmr::Error when the range exceeds kMaxFramesPerRun (the frames
// --frames all would render; the framing poses every one of them).
bool animation_key_frames(const Scene& scene, const SequenceSpec& spec, long& first, long& last);

// The frames of --frames all: with a turntable one turn, 0..FRAMES-1 (an animation's time keeps
// running, holding its last pose past its end); else the animation's key frames
// (animation_key_frames; pmr::Error when there are none); without either frame 0 alone.
void animation_frame_range(const Scene& scene, const SequenceSpec& spec, long& first, long& last);

class FrameRenderer {
 public:
  // Computes the framing (the union of the posed bounds over every frame of the animation's range;
  // without triangles anywhere a unit cube at the origin, with a warning) and the rig. `warnings`
  // receives the rig's and the framing's warnings.
  FrameRenderer(const Scene& rest, const SequenceSpec& spec, const RigConfig& rig_config, const Display& display,
                std::vector<std::string>* warnings);

  // Uploads the scene and configures the pipeline (display may be null: views only).
  void attach(Pipeline& pipeline, const Display* encode_display);

  struct Frame {
    long number = 0;
    double time = 0.0;   // seconds: number / fps
    double angle = 0.0;  // turntable degrees
    Rig rig;
    StageTimes times;
    double pose_ms = 0.0;    // posing (animation sampling, morphing, skinning, turntable) on the host
    double upload_ms = 0.0;  // copying the posed geometry to the device
    bool visible = false;    // some MTA was produced (false: a transparent image)
    // triangles the near plane cuts only because it was raised (rig.near_eff > rig.near: the
    // disparity's fixed-point range), partly or wholly not drawn
    uint64_t near_clipped = 0;
    // pbr: the lights the frame was shaded with (FrameDescription::lights), as the sidecar records
    // them; empty under lambert
    std::vector<SceneLight> lights;
  };
  Frame render(long frame);
  // What render(frame) renders under `config` (its rig and lights), without rendering it: cameras and
  // lights posed only. render() renders exactly this description; --resume compares sidecars with it.
  FrameDescription describe(long frame, const PipelineConfig& config) const;

  const Rig& rig() const { return rig_; }
  const glm::dvec3& bounds_lo() const { return lo_; }
  const glm::dvec3& bounds_hi() const { return hi_; }
  glm::dvec3 pivot() const { return 0.5 * (lo_ + hi_); }
  const SequenceSpec& spec() const { return spec_; }
  bool has_geometry() const { return !rest_.triangles.empty(); }

 private:
  Rig rig_for(const Scene& posed, std::vector<std::string>* warnings) const;
  // The description of a frame whose cameras and lights are posed in `placed`.
  FrameDescription describe_posed(const Scene& placed, const PipelineConfig& config) const;
  PoseRequest request(long frame) const;

  const Scene& rest_;
  SequenceSpec spec_;
  RigConfig rig_config_;
  Display display_;
  glm::dvec3 lo_{-1.0}, hi_{1.0};
  Rig rig_;
  bool moves_ = false;         // posing changes something
  bool camera_moves_ = false;  // the selected glTF camera's node is animated
  Scene posed_;
  Pipeline* pipeline_ = nullptr;
};

}  // namespace pmr
