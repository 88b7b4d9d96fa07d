#include "output/sidecar_names.h"

#include <algorithm>

#include "output/checksum.h"

namespace pmr {

namespace {

// The length of the well-formed UTF-8 sequence at text[i] (RFC 3629: no overlong forms, surrogates or
// code points above U+10FFFF), 0 when there is none.
size_t utf8_length(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return k < text.size() ? (unsigned char)text[k] : 0u; };
  const unsigned c = byte(i);
  if (c < 0x80) return 1;
  const size_t n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  const unsigned second = byte(i + 1);
  if ((c == 0xE0 && second < 0xA0) || (c == 0xED && second > 0x9F) || (c == 0xF0 && second < 0x90) ||
      (c == 0xF4 && second > 0x8F))
    return 0;
  return n;
}

int hex_digit(char c) {
  return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

}  // namespace

bool is_utf8(const std::string& bytes) {
  for (size_t i = 0; i < bytes.size();) {
    const size_t n = utf8_length(bytes, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::string to_hex(const std::string& bytes) {
  static const char digits[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * bytes.size());
  for (unsigned char c : bytes) out += digits[c >> 4], out += digits[c & 15];
  return out;
}

std::string recorded_name(const nlohmann::json* text, const nlohmann::json* hex) {
  if (hex && hex->is_string()) {
    const std::string& h = hex->get_ref<const std::string&>();
    std::string bytes;
    bool ok = h.size() % 2 == 0;
    for (size_t i = 0; ok && i < h.size(); i += 2) {
      const int hi = hex_digit(h[i]), lo = hex_digit(h[i + 1]);
      ok = hi >= 0 && lo >= 0;
      bytes += char(hi * 16 + lo);
    }
    if (ok) return bytes;
  }
  return text && text->is_string() ? text->get<std::string>() : std::string();
}

std::vector<std::pair<std::string, const nlohmann::json*>> recorded_scene_files(const nlohmann::json& checksums) {
  std::vector<std::pair<std::string, const nlohmann::json*>> files;
  if (!checksums.is_object()) return files;
  if (const auto plain = checksums.find("scene_files"); plain != checksums.end() && plain->is_object())
    for (auto it = plain->begin(); it != plain->end(); ++it) files.push_back({it.key(), &it.value()});
  if (const auto hex = checksums.find("scene_files_hex"); hex != checksums.end() && hex->is_object())
    for (auto it = hex->begin(); it != hex->end(); ++it) {
      const nlohmann::json key = it.key();
      files.push_back({recorded_name(nullptr, &key), &it.value()});
    }
  return files;
}

std::string bounded_text(const std::string& text, size_t limit) {
  if (text.size() <= limit) return text;
  size_t cut = 0;  // whole characters (a stray byte counts as one)
  while (cut < text.size()) {
    const size_t n = std::max<size_t>(1, utf8_length(text, cut));
    if (cut + n > limit - std::min<size_t>(limit, 48)) break;
    cut += n;
  }
  return text.substr(0, cut) + "... (" + std::to_string(text.size()) + " bytes, XXH3 " +
         checksum_hex(text.data(), text.size()) + ")";
}

}  // namespace pmr
