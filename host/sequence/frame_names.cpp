// --name patterns (frame_names.h).
#include "sequence/frame_names.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "pmr/error.h"
#include "pmr/printable.h"

namespace pmr {

namespace {

const char* const kNameExample = "e.g. --name shot_%04d or shot_#### (frame 7: shot_0007)";

}  // namespace

NamePattern parse_name_pattern(const std::string& p) {
  NamePattern n;
  auto refuse = [&](const std::string& why) -> Error {
    return Error("invalid --name '" + printable_text(p) + "': " + why + "; " + kNameExample);
  };
  auto field = [&](int width) {
    if (n.has_field) throw refuse("more than one frame number field");
    n.has_field = true;
    n.width = width;
  };
  for (size_t i = 0; i < p.size(); ++i) {
    std::string& out = n.has_field ? n.suffix : n.prefix;
    if (p[i] == '/') throw refuse("a file stem cannot contain '/' (--out names the folder)");
    // names pmr verify and other tools read back: no terminal controls, no Windows separator
    if (p[i] == '\\') throw refuse("a file stem cannot contain '\\'");
    if ((unsigned char)p[i] < 0x20 || p[i] == 0x7f) throw refuse("a file stem cannot contain control characters");
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
    if (i + 1 < p.size() && p[i + 1] == 'q') {
      if (n.has_quilt) throw refuse("more than one %q");
      n.has_quilt = true, n.quilt_in_suffix = n.has_field, n.quilt_at = out.size();
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
      throw refuse("'" + spec +
                   "' is not a frame number field (%d, %0Nd or ####; %q for the quilt tag, %% for a percent sign)");
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
    throw Error("invalid --name '" + printable_text(p) + "': the file stem would be empty or hidden; " + kNameExample);
}

namespace {

// The stem of `frame` with `tag` at the pattern's %q.
std::string stem_with(NamePattern n, long frame, const std::string& tag) {
  if (n.has_quilt) (n.quilt_in_suffix ? n.suffix : n.prefix).insert(n.quilt_at, tag);
  if (!n.has_field) return n.prefix;
  std::string number = std::to_string(frame);
  if (number.size() < size_t(n.width)) number.insert(0, size_t(n.width) - number.size(), '0');
  return n.prefix + number + n.suffix;
}

}  // namespace

std::string frame_stem(const std::string& pattern, long frame) {
  return stem_with(parse_name_pattern(pattern), frame, "");
}

std::string quilt_file_stem(const std::string& pattern, long frame, bool sequence, const std::string& tag) {
  NamePattern n = parse_name_pattern(pattern);
  if (!n.has_quilt && sequence && n.has_field) {
    const size_t cut = n.prefix.find_last_not_of("._-") + 1;  // npos + 1 = 0: all separators
    n.has_quilt = true, n.quilt_in_suffix = false, n.quilt_at = cut;
    if (cut == n.prefix.size()) n.prefix += '_';
  }
  if (!n.has_quilt) return stem_with(n, frame, "") + tag;
  return stem_with(n, frame, tag);
}

std::string canonical_name_pattern(const std::string& pattern) {
  const NamePattern n = parse_name_pattern(pattern);
  auto escaped = [](const std::string& text) {
    std::string out;
    for (char c : text) out += c == '%' ? std::string("%%") : std::string(1, c);
    return out;
  };
  auto with_quilt = [&](const std::string& text, bool in_suffix) {
    if (!n.has_quilt || n.quilt_in_suffix != in_suffix) return escaped(text);
    return escaped(text.substr(0, n.quilt_at)) + "%q" + escaped(text.substr(n.quilt_at));
  };
  if (!n.has_field) return with_quilt(n.prefix, false);
  const std::string field = n.width ? "%0" + std::to_string(n.width) + "d" : "%d";
  return with_quilt(n.prefix, false) + field + with_quilt(n.suffix, true);
}

void check_name_covers_frames(const std::string& pattern, size_t frame_count) {
  if (frame_count > 1 && !parse_name_pattern(pattern).has_field)
    throw Error("--name '" + pattern + "' has no frame number field, so it names one frame, and " +
                std::to_string(frame_count) + " frames were asked for; " + kNameExample);
}

}  // namespace pmr
