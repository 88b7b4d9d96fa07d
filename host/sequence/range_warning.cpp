#include "sequence/range_warning.h"

#include <algorithm>
#include <cstdio>

#include "pmr/printable.h"
#include "sequence/frame_list.h"

namespace pmr {

std::string frames_outside_animation(const Scene& scene, const SequenceSpec& spec, const std::vector<long>& frames,
                                     bool frames_all) {
  if (frames_all || spec.animation == kNoAnimation) return "";
  long first = 0, last = -1;
  const bool inside = animation_key_frames(scene, spec, first, last);
  std::vector<long> outside;
  bool before = false, after = false;
  for (long f : frames)
    if (f < first || f > last) {
      outside.push_back(f);
      (f < first ? before : after) = true;
    }
  if (outside.empty()) return "";
  std::string list = format_frame_list(outside);
  if (list.size() > 60) {
    long lo = outside[0], hi = outside[0];
    for (long f : outside) lo = std::min(lo, f), hi = std::max(hi, f);
    list = std::to_string(outside.size()) + " frames between " + std::to_string(lo) + " and " + std::to_string(hi);
  } else {
    list = (outside.size() == 1 ? "frame " : "frames ") + list;
  }
  char range[96];
  if (inside) std::snprintf(range, sizeof range, "frames %ld:%ld at %g fps", first, last, spec.fps);
  else std::snprintf(range, sizeof range, "no frame at %g fps lies inside its keys", spec.fps);
  const std::string what = spec.animation == kAllAnimations
                               ? "the animations (all)"
                               : "the animation '" + printable_text(spec.animation_label, 80) + "'";
  const char* pose = before && after ? "its first or last pose" : before ? "its first pose" : "its last pose";
  return list + (outside.size() == 1 ? " lies" : " lie") + " outside " + what + " (" + range +
         "): " + (outside.size() == 1 ? "it repeats " : "they repeat ") + pose +
         (spec.turntable ? " (the turntable still turns)" : "");
}

}  // namespace pmr
