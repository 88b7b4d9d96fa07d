// A sequence's frames as chosen (SequenceChoice) and as resolved against the scene (SequenceSpec): the
// animation, the frame rate and the turntable. The framing, the poses and the sidecar follow from it.
#pragma once
#include <cstdint>
#include <string>

#include "pmr/input_files.h"
#include "pmr/scene.h"

namespace pmr {

// The sequence as the command line chooses it, before the scene resolves the animation
// (resolve_sequence, sequence/frame_renderer.h).
struct SequenceChoice {
  std::string animation;  // name, index, "all" or "none"; "" = the first animation
  double fps = 24.0;
  bool turntable = false;
  double turntable_deg = 0.0;  // DEG of --turntable DEG:FRAMES
  long turntable_frames = 0;   // FRAMES of --turntable DEG:FRAMES
};

struct SequenceSpec {
  int animation = kNoAnimation;  // Scene::animations index, kAllAnimations or kNoAnimation
  std::string animation_label;   // what the sidecar records: the clip's name (or "#index"), "all" or ""
  double fps = 24.0;
  bool turntable = false;
  double turntable_deg = 0.0;  // DEG of DEG:FRAMES
  long turntable_frames = 1;   // FRAMES of DEG:FRAMES
  // --limit pose-work and framing-work: the work of one pose (pose_work, pmr/scene.h), and of all the
  // poses the framing takes (every frame of the animation, before the first frame renders). Checked by
  // FrameRenderer before it poses anything.
  uint64_t pose_work = InputLimits().pose_work;
  uint64_t framing_work = InputLimits().framing_work;
  // --limit frame-work: the estimated work of one frame (sequence/frame_work.h), checked by
  // FrameRenderer before each frame renders.
  uint64_t frame_work = InputLimits().frame_work;
};

}  // namespace pmr
