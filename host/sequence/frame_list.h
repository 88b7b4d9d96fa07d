// Frame lists as the CLI takes them: "A:B[:STEP]" ranges (inclusive, like Blender's -s A -e B -j STEP),
// single frames and comma-separated lists of both ("0:99,120,130:140"), or "all".
#pragma once
#include <string>
#include <vector>

namespace pmr {

// The largest frame number, and the most frames one run renders (a --frames list, or --frames all).
constexpr long kMaxFrame = 9999999;
constexpr long kMaxFramesPerRun = 10000000;

// The frames in the order given, duplicates dropped (first occurrence kept). "all" is not handled here
// (the caller knows the animation's range). Throws pmr::Error with one line on anything malformed,
// reversed ranges, non-positive steps, frames outside 0..kMaxFrame or lists over kMaxFramesPerRun.
std::vector<long> parse_frame_list(const std::string& text);

// The shortest comma list of ranges and single frames that parse_frame_list reads back as `frames`
// (sorted and de-duplicated first): {0,1,2,3,7,9,11} -> "0:3,7:11:2".
std::string format_frame_list(std::vector<long> frames);

}  // namespace pmr
