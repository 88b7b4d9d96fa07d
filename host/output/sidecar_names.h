// Names and other text as a sidecar records them. File names are byte-exact: one that is valid UTF-8
// is a JSON string; any other is written as that string with U+FFFD for its stray bytes (what a person
// reads) and, in a sibling field "<key>_hex" (or "name_hex"), its bytes in hex (what pmr reads back,
// so that pmr verify and --resume look for the same file). Text that comes from the scene file (light
// names, warnings) is bounded, so that pmr never writes a sidecar larger than it reads back.
#pragma once
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace pmr {

bool is_utf8(const std::string& bytes);
std::string to_hex(const std::string& bytes);
// The name a sidecar records as `text` with its sibling `hex`: hex's bytes when it is a string of hex
// digits, else text's string; "" when neither is a string.
std::string recorded_name(const nlohmann::json* text, const nlohmann::json* hex);
// The scene files a sidecar's "checksums" object records: (name as bytes, its recorded checksum
// value), from scene_files and, for names that are not UTF-8, scene_files_hex. Empty when absent.
std::vector<std::pair<std::string, const nlohmann::json*>> recorded_scene_files(const nlohmann::json& checksums);
// At most about `limit` bytes: longer text is cut at a character boundary and ends with its length and
// checksum, "... (N bytes, XXH3 H)", so that two long names stay distinct in comparisons.
std::string bounded_text(const std::string& text, size_t limit = 256);

}  // namespace pmr
