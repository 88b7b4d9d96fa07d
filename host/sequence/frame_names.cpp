// --name patterns (frame_names.h).
#include "sequence/frame_names.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "pmr/error.h"

namespace pmr {

namespace {

const char* const kNameExample = "e.g. --name shot_%04d or shot_#### (frame 7: shot_0007)";

}  // namespace

NamePattern parse_name_pattern(const std::string& p) {
  NamePattern n;
  auto refuse = [&](const std::string& why) -> Error {
    return Error("invalid --name '" + p + "': " + why + "; " + kNameExample);
  };
  auto field = [&](int width) {
    if (n.has_field) throw refuse("more than one frame number field");
    n.has_field = true;
    n.width = width;
  };
  for (size_t i = 0; i < p.size(); ++i) {
    std::string& out = n.has_field ? n.suffix : n.prefix;
    if (p[i] == '/') throw refuse("a file stem cannot contain '/' (--out names the folder)");
    if (p[i] == '#') {  // Blender: a run of N '#' is the frame zero-padded to N digits
      size_t j = i;
      while (j < p.size() && p[j] == '#') ++j;
      if (j - i > 99) throw refuse("at most 99 '#'");
      field(int(j - i));
      i = j - 1;
      continue;
    }
    if (p[i] != '%') {
      out += p[i];
      continue;
    }
    if (i + 1 < p.size() && p[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    size_t j = i + 1;
    const bool zero = j < p.size() && p[j] == '0';
    if (zero) ++j;
    size_t digits = 0;
    while (j < p.size() && std::isdigit((unsigned char)p[j])) ++j, ++digits;
    const std::string spec = p.substr(i, std::min(j + 1, p.size()) - i);
    if (j >= p.size() || p[j] != 'd')
      throw refuse("'" + spec + "' is not a frame number field (%d, %0Nd or ####; %% for a percent sign)");
    if (!zero && digits > 0)
      throw refuse("'" + spec + "' pads with spaces; use %0" + spec.substr(1) + " (zero-padded)");
    if (digits > 2) throw refuse("'" + spec + "': at most 99 digits");
    field(digits ? std::atoi(p.substr(i + 2, digits).c_str()) : 0);
    i = j;
  }
  return n;
}

void check_name_pattern(const std::string& p) {
  const std::string stem = frame_stem(p, 0);
  if (stem.empty() || stem[0] == '.')
    throw Error("invalid --name '" + p + "': the file stem would be empty or hidden; " + kNameExample);
}

std::string frame_stem(const std::string& pattern, long frame) {
  const NamePattern n = parse_name_pattern(pattern);
  if (!n.has_field) return n.prefix;
  std::string number = std::to_string(frame);
  if (number.size() < size_t(n.width)) number.insert(0, size_t(n.width) - number.size(), '0');
  return n.prefix + number + n.suffix;
}

std::string canonical_name_pattern(const std::string& pattern) {
  const NamePattern n = parse_name_pattern(pattern);
  auto escaped = [](const std::string& text) {
    std::string out;
    for (char c : text) out += c == '%' ? std::string("%%") : std::string(1, c);
    return out;
  };
  if (!n.has_field) return escaped(n.prefix);
  const std::string field = n.width ? "%0" + std::to_string(n.width) + "d" : "%d";
  return escaped(n.prefix) + field + escaped(n.suffix);
}

void check_name_covers_frames(const std::string& pattern, size_t frame_count) {
  if (frame_count > 1 && !parse_name_pattern(pattern).has_field)
    throw Error("--name '" + pattern + "' has no frame number field, so it names one frame, and " +
                std::to_string(frame_count) + " frames were asked for; " + kNameExample);
}

}  // namespace pmr
