// exr_chunk_problem (pmr/output.h): an EXR file's structure checked without decoding a pixel. The
// headers' geometry comes from OpenEXRCore; the chunk table and each chunk's leading bytes are read
// here, because OpenEXRCore quietly rebuilds a damaged table by scanning the chunks.
#include <openexr.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "pmr/output.h"

namespace pmr {

namespace {

void silent(exr_const_context_t, exr_result_t, const char*) {}

std::string name_of(const std::string& path) { return std::filesystem::path(path).filename().string(); }

constexpr uint32_t kMultiPartFlag = 0x1000;  // version field bit 12

// Little-endian reads from an open file; any failure leaves ok() false.
class Reader {
 public:
  explicit Reader(const std::string& path) : in_(path, std::ios::binary) {}
  bool ok() const { return bool(in_); }
  void seek(uint64_t at) { in_.seekg(std::streamoff(at)); }
  uint64_t tell() { return uint64_t(in_.tellg()); }
  uint64_t u(int bytes) {
    unsigned char b[8] = {};
    in_.read(reinterpret_cast<char*>(b), bytes);
    uint64_t v = 0;
    for (int k = 0; k < bytes; ++k) v |= uint64_t(b[k]) << (8 * k);
    return v;
  }
  // a NUL-terminated name (attribute names and types are at most 255 characters)
  std::string name() {
    std::string s;
    for (char c; in_.get(c) && c != '\0';)
      if (s.size() < 256) s += c;
      else return in_.setstate(std::ios::failbit), s;
    return s;
  }
  void skip(uint64_t bytes) { in_.seekg(std::streamoff(bytes), std::ios::cur); }

 private:
  std::ifstream in_;
};

// Skips one header (attributes up to the empty name); false if it is empty (the end of the headers of
// a multi-part file) or unreadable.
bool skip_header(Reader& r, uint64_t file_bytes) {
  bool any = false;
  for (;;) {
    const std::string attr = r.name();
    if (!r.ok()) return false;
    if (attr.empty()) return any;
    r.name();  // type
    const uint64_t size = r.u(4);
    if (!r.ok() || size > file_bytes) return false;
    r.skip(size);
    any = true;
  }
}

}  // namespace

std::string exr_chunk_problem(const std::string& path) {
  std::error_code ec;
  const uint64_t file_bytes = std::filesystem::file_size(path, ec);
  if (ec) return name_of(path) + " cannot be read";
  // the geometry of every part from OpenEXRCore
  struct Part {
    int64_t min_y = 0;
    int32_t lines = 0, chunks = 0;
  };
  std::vector<Part> parts;
  {
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = silent;
    exr_context_t ctx = nullptr;
    bool ok = exr_start_read(&ctx, path.c_str(), &init) == EXR_ERR_SUCCESS;
    int count = 0;
    ok = ok && exr_get_count(ctx, &count) == EXR_ERR_SUCCESS && count >= 1;
    for (int p = 0; ok && p < count; ++p) {
      exr_storage_t storage;
      exr_attr_box2i_t dw;
      Part part;
      ok = exr_get_storage(ctx, p, &storage) == EXR_ERR_SUCCESS && storage == EXR_STORAGE_SCANLINE &&
           exr_get_data_window(ctx, p, &dw) == EXR_ERR_SUCCESS &&
           exr_get_scanlines_per_chunk(ctx, p, &part.lines) == EXR_ERR_SUCCESS &&
           exr_get_chunk_count(ctx, p, &part.chunks) == EXR_ERR_SUCCESS && part.lines >= 1 && dw.max.y >= dw.min.y &&
           part.chunks == (int64_t(dw.max.y) - dw.min.y + part.lines) / part.lines;
      part.min_y = dw.min.y;
      parts.push_back(part);
    }
    exr_finish(&ctx);
    if (!ok) return name_of(path) + " has no readable scanline EXR header";
  }
  // past the headers to the chunk tables
  Reader r(path);
  r.u(4);  // magic, checked by OpenEXRCore
  const bool multi = (r.u(4) & kMultiPartFlag) != 0;
  for (size_t p = 0; p < parts.size(); ++p)
    if (!skip_header(r, file_bytes)) return name_of(path) + " has an unreadable header";
  if (multi && r.u(1) != 0) return name_of(path) + " has an unreadable header";
  if (!r.ok()) return name_of(path) + " has an unreadable header";
  const uint64_t tables_at = r.tell();
  std::vector<std::vector<uint64_t>> tables;
  uint64_t tables_end = tables_at;
  for (const Part& part : parts) {
    tables.emplace_back();
    for (int32_t c = 0; c < part.chunks; ++c) tables.back().push_back(r.u(8));
    tables_end += 8u * uint64_t(part.chunks);
  }
  if (!r.ok() || tables_end > file_bytes) return name_of(path) + " is truncated (in its chunk table)";
  // every chunk: inside the file after the tables, at the part and scanline the table says, its data
  // inside the file, none overlapping another
  std::vector<std::pair<uint64_t, uint64_t>> extents;
  const uint64_t leader = multi ? 12 : 8;  // [part,] y, data size
  for (size_t p = 0; p < parts.size(); ++p)
    for (size_t c = 0; c < tables[p].size(); ++c) {
      const uint64_t at = tables[p][c];
      const int64_t y = parts[p].min_y + int64_t(c) * parts[p].lines;
      auto damaged = [&] {
        return name_of(path) + " is truncated or damaged (chunk at scanline " + std::to_string(y) + ")";
      };
      if (at < tables_end || at > file_bytes || file_bytes - at < leader) return damaged();
      r.seek(at);
      if (multi && r.u(4) != p) return damaged();
      const int64_t chunk_y = int32_t(uint32_t(r.u(4)));
      const uint64_t size = r.u(4);
      if (!r.ok() || chunk_y != y || size > file_bytes - at - leader) return damaged();
      extents.emplace_back(at, at + leader + size);
    }
  std::sort(extents.begin(), extents.end());
  for (size_t i = 1; i < extents.size(); ++i)
    if (extents[i].first < extents[i - 1].second) return name_of(path) + " is damaged (overlapping chunks)";
  return "";
}

}  // namespace pmr
