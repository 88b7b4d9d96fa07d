#include "pmr/json_text.h"

#include <algorithm>

namespace pmr {

int json_depth(const std::string& text, uint64_t* values) {
  int depth = 0, max_depth = 0;
  uint64_t count = 1;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      max_depth = std::max(max_depth, ++depth);
      ++count;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == ',' || c == ':') {
      ++count;
    }
  }
  if (values) *values = count;
  return max_depth;
}

nlohmann::json parse_json_text(const std::string& text) {
  if (json_depth(text) > kMaxJsonDepth) return nlohmann::json(nlohmann::json::value_t::discarded);
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

}  // namespace pmr
