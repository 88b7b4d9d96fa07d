// The file stems of a sequence's frames: --name patterns with one frame number field.
#pragma once
#include <cstddef>
#include <string>

namespace pmr {

// A --name pattern read: at most one frame number field, %d (as many digits as the number has), %0Nd
// or Blender's run of N '#' (zero-padded to N digits); at most one %q, where the quilt's name has its
// Looking Glass tag (quilt_file_stem; the other files have nothing there); %% is a percent sign; no
// '/'. Without a field the pattern is the stem of a single frame. Throws pmr::Error with one line
// (showing an accepted example) otherwise, e.g. for the space-padded %Nd.
struct NamePattern {
  std::string prefix, suffix;  // the text before and after the field (%% read as %); no field: prefix
  bool has_field = false;
  int width = 0;  // zero-padded to this many digits; 0: as many as the number needs
  // %q: at position quilt_at of the prefix (or of the suffix when quilt_in_suffix)
  bool has_quilt = false, quilt_in_suffix = false;
  size_t quilt_at = 0;
};
NamePattern parse_name_pattern(const std::string& pattern);
// Throws what parse_name_pattern throws, and when the stem would be empty or hidden.
void check_name_pattern(const std::string& pattern);
// The file stem of a frame under the pattern (a %q, if any, left out).
std::string frame_stem(const std::string& pattern, long frame);
// The stem of a frame's quilt, `tag` its Looking Glass tag (quilt_tag, "_qs8x6a0.75"): at the pattern's
// %q; else, in a sequence whose pattern has a frame field, before that field, ahead of the separators
// ('.', '_', '-') that precede it ("_" when none do), so that the frame number stays the last digit
// group of the stem, which is what sequence readers (Blender, fileseq, pyseq) take as the frame;
// else (a still) at the end of the stem, as Looking Glass tools write it.
std::string quilt_file_stem(const std::string& pattern, long frame, bool sequence, const std::string& tag);
// The pattern in one spelling (#### as %04d), so that two spellings of the same names compare equal.
std::string canonical_name_pattern(const std::string& pattern);
// Refuses a --name without a frame field for more than one frame (they would share one name).
void check_name_covers_frames(const std::string& pattern, size_t frame_count);

}  // namespace pmr
