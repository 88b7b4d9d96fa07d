// The file stems of a sequence's frames: --name patterns with one frame number field.
#pragma once
#include <cstddef>
#include <string>

namespace pmr {

// A --name pattern read: at most one frame number field, %d (as many digits as the number has), %0Nd
// or Blender's run of N '#' (zero-padded to N digits); %% is a percent sign; no '/'. Without a field
// the pattern is the stem of a single frame. Throws pmr::Error with one line (showing an accepted
// example) otherwise, e.g. for the space-padded %Nd.
struct NamePattern {
  std::string prefix, suffix;  // the text before and after the field (%% read as %); no field: prefix
  bool has_field = false;
  int width = 0;  // zero-padded to this many digits; 0: as many as the number needs
};
NamePattern parse_name_pattern(const std::string& pattern);
// Throws what parse_name_pattern throws, and when the stem would be empty or hidden.
void check_name_pattern(const std::string& pattern);
// The file stem of a frame under the pattern.
std::string frame_stem(const std::string& pattern, long frame);
// The pattern in one spelling (#### as %04d), so that two spellings of the same names compare equal.
std::string canonical_name_pattern(const std::string& pattern);
// Refuses a --name without a frame field for more than one frame (they would share one name).
void check_name_covers_frames(const std::string& pattern, size_t frame_count);

}  // namespace pmr
