// A sequence's frames as resolved from the job (SequenceRun::choose_frames): the animation chosen, the
// frame rate and the turntable. The framing, the poses and the sidecar follow from it.
#pragma once
#include <cstdint>
#include <string>

#include "pmr/input_files.h"
#include "pmr/scene.h"

namespace pmr {

struct SequenceSpec {
  int animation = kNoAnimation;  // Scene::animations index, kAllAnimations or kNoAnimation
  std::string animation_label;   // what the sidecar records: the clip's name (or "#index"), "all" or ""
  double fps = 24.0;
  bool turntable = false;
  double turntable_deg = 0.0;  // DEG of DEG:FRAMES
  long turntable_frames = 1;   // FRAMES of DEG:FRAMES
  // --limit framing-work: the framing poses the scene at every frame of the animation before the first
  // frame renders; poses x the scene's vertices above this are refused (FrameRenderer).
  uint64_t framing_work = InputLimits().framing_work;
};

}  // namespace pmr
