// JSON text pmr reads back from files anyone may have written (sidecars, lock files, calibration files,
// the glTF loader's document): the nesting depth is checked before parsing, because nlohmann's values
// copy and compare themselves recursively (a value nested 100,000 deep overflows the stack), and
// objects are parsed into nlohmann::json, whose sorted keys make parsing O(n log n) in an object's keys
// (ordered_json's linear lookups made it quadratic).
#pragma once
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace pmr {

// The deepest nesting of arrays and objects pmr parses; real files nest a few levels.
constexpr int kMaxJsonDepth = 128;

// Nesting depth of JSON text, counting brackets outside strings (no recursion); `values` gets an
// upper bound of its values (separators and openings outside strings, plus one).
int json_depth(const std::string& text, uint64_t* values = nullptr);

// The parsed text, or a discarded value (is_discarded()) when it is not JSON or nests deeper than
// kMaxJsonDepth. Only running out of memory throws (std::bad_alloc).
nlohmann::json parse_json_text(const std::string& text);

}  // namespace pmr
