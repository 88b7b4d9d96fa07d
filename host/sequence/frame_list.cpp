#include "sequence/frame_list.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <set>
#include <sstream>

#include "pmr/error.h"

namespace pmr {

namespace {

long parse_frame(const std::string& text, const std::string& item) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || text[0] == '+' || text[0] == ' ')
    throw Error("invalid --frames item '" + item + "': expected FRAME or FIRST:LAST[:STEP] with whole numbers");
  if (v < 0 || v > kMaxFrame)
    throw Error("invalid --frames item '" + item + "': frame numbers must be 0.." + std::to_string(kMaxFrame));
  return v;
}

}  // namespace

std::vector<long> parse_frame_list(const std::string& text) {
  if (text.empty()) throw Error("invalid --frames '': expected a frame, a range A:B[:STEP], a list of them, or all");
  std::vector<long> frames;
  std::set<long> seen;
  std::stringstream ss(text);
  std::string item;
  size_t items = 0;
  while (std::getline(ss, item, ',')) {
    ++items;
    std::vector<std::string> parts;
    std::stringstream is(item);
    std::string part;
    while (std::getline(is, part, ':')) parts.push_back(part);
    if (item.empty() || item.back() == ':' || parts.empty() || parts.size() > 3)
      throw Error("invalid --frames item '" + item + "': expected FRAME or FIRST:LAST[:STEP]");
    const long first = parse_frame(parts[0], item);
    const long last = parts.size() > 1 ? parse_frame(parts[1], item) : first;
    const long step = parts.size() > 2 ? parse_frame(parts[2], item) : 1;
    if (last < first) throw Error("invalid --frames item '" + item + "': the last frame comes before the first");
    if (step < 1) throw Error("invalid --frames item '" + item + "': the step must be at least 1");
    for (long f = first; f <= last; f += step) {
      if (seen.insert(f).second) frames.push_back(f);
      if (frames.size() > size_t(kMaxFramesPerRun))
        throw Error("invalid --frames '" + text + "': more than " + std::to_string(kMaxFramesPerRun) + " frames");
    }
  }
  if (items == 0 || text.back() == ',') throw Error("invalid --frames '" + text + "': empty item");
  return frames;
}

std::string format_frame_list(std::vector<long> frames) {
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  std::string out;
  size_t i = 0;
  while (i < frames.size()) {
    // The longest arithmetic run from i (at least 3 frames to be worth a step, 2 for step 1).
    size_t j = i + 1;
    if (j < frames.size()) {
      const long step = frames[j] - frames[i];
      while (j + 1 < frames.size() && frames[j + 1] - frames[j] == step) ++j;
      const size_t run = j - i + 1;
      if (!(run >= 3 || (run == 2 && step == 1))) j = i;
      if (!out.empty()) out += ",";
      if (j > i) {
        out += std::to_string(frames[i]) + ":" + std::to_string(frames[j]);
        if (step != 1) out += ":" + std::to_string(step);
        i = j + 1;
        continue;
      }
    } else if (!out.empty()) {
      out += ",";
    }
    out += std::to_string(frames[i]);
    ++i;
  }
  return out;
}

}  // namespace pmr
