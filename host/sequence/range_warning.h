// The warning for requested frames outside the chosen animation's range (docs/SEQUENCES.md).
#pragma once
#include <string>
#include <vector>

#include "pmr/scene.h"
#include "sequence/frame_renderer.h"

namespace pmr {

// "" when every frame lies inside the animation's key frames (animation_key_frames: the frames `--frames
// all` selects without a turntable), when the frames are `--frames all` themselves (with a turntable
// one turn, which may run past the animation's end: its help says the last pose holds), or when no
// animation is selected (a still scene, or a turntable alone: frames past one turn keep turning). Else
// one line (without "pmr: warning: ") naming the
// frames outside and the animation's range, e.g. "frames 49:240 lie outside the animation 'Walk'
// (frames 0:48 at 24 fps): they repeat its last pose".
std::string frames_outside_animation(const Scene& scene, const SequenceSpec& spec, const std::vector<long>& frames,
                                     bool frames_all);

}  // namespace pmr
