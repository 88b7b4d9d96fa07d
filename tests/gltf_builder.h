// Writing small glTF files in tests: a minimal PNG encoder, base64 data URIs, and a builder for a glTF
// document with one binary buffer (.gltf + .bin, embedded, or .glb). Used by the loader tests.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "pmr/scene.h"

namespace pmr::test {

namespace gltf_builder_detail {
namespace fs = std::filesystem;
using nlohmann::json;

inline constexpr int kByte = 5120, kUByte = 5121, kUShort = 5123, kUInt = 5125, kFloat = 5126;

// ---- writing test files ------------------------------------------------------------------------------

inline std::string base64(const std::vector<uint8_t>& data) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    const uint32_t n = uint32_t(data[i]) << 16 | (i + 1 < data.size() ? uint32_t(data[i + 1]) << 8 : 0u) |
                       (i + 2 < data.size() ? uint32_t(data[i + 2]) : 0u);
    out += digits[n >> 18 & 63];
    out += digits[n >> 12 & 63];
    out += i + 1 < data.size() ? digits[n >> 6 & 63] : '=';
    out += i + 2 < data.size() ? digits[n & 63] : '=';
  }
  return out;
}

inline void put_be32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}

inline void put_le32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 0; s < 32; s += 8) out.push_back(uint8_t(v >> s));
}

inline uint32_t crc32(const uint8_t* p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

// A minimal PNG (no filtering, stored deflate blocks), so tests control channels and bit depth exactly.
// color_type: 0 grey, 2 RGB, 4 grey + alpha, 6 RGBA. `samples` are big-endian for 16 bits, as in PNG.
inline std::vector<uint8_t> make_png(int w, int h, int color_type, int depth, const std::vector<uint8_t>& samples) {
  const int channels = color_type == 0 ? 1 : color_type == 2 ? 3 : color_type == 4 ? 2 : 4;
  const size_t row = size_t(w) * size_t(channels) * size_t(depth / 8);
  std::vector<uint8_t> raw;
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);  // filter: none
    raw.insert(raw.end(), samples.begin() + long(row * size_t(y)), samples.begin() + long(row * size_t(y + 1)));
  }
  std::vector<uint8_t> z = {0x78, 0x01};
  uint32_t a = 1, b = 0;
  for (uint8_t c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  for (size_t off = 0; off < raw.size() || off == 0; off += 65535) {
    const size_t n = std::min<size_t>(65535, raw.size() - off);
    z.push_back(off + n >= raw.size() ? 1 : 0);
    z.push_back(uint8_t(n)), z.push_back(uint8_t(n >> 8)), z.push_back(uint8_t(~n)), z.push_back(uint8_t(~n >> 8));
    z.insert(z.end(), raw.begin() + long(off), raw.begin() + long(off + n));
    if (raw.empty()) break;
  }
  put_be32(z, b << 16 | a);
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto chunk = [&](const char* type, const std::vector<uint8_t>& data) {
    put_be32(png, uint32_t(data.size()));
    std::vector<uint8_t> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    png.insert(png.end(), body.begin(), body.end());
    put_be32(png, crc32(body.data(), body.size()));
  };
  std::vector<uint8_t> ihdr;
  put_be32(ihdr, uint32_t(w));
  put_be32(ihdr, uint32_t(h));
  ihdr.insert(ihdr.end(), {uint8_t(depth), uint8_t(color_type), 0, 0, 0});
  chunk("IHDR", ihdr);
  chunk("IDAT", z);
  chunk("IEND", {});
  return png;
}

inline std::string png_uri(const std::vector<uint8_t>& png) { return "data:image/png;base64," + base64(png); }

inline int components(const std::string& type) {
  return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
}

// Builds a glTF document and its single binary buffer.
struct GltfFile {
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::vector<uint8_t> bin;

  template <class T>
  int view(const std::vector<T>& data, int stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    const auto* bytes = reinterpret_cast<const uint8_t*>(data.data());
    bin.insert(bin.end(), bytes, bytes + data.size() * sizeof(T));
    json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", data.size() * sizeof(T)}};
    if (stride) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return int(doc["bufferViews"].size() - 1);
  }
  int accessor(int view, int component_type, const std::string& type, size_t count, bool normalized = false,
               size_t offset = 0) {
    json a = {{"componentType", component_type}, {"type", type}, {"count", count}};
    if (view >= 0) a["bufferView"] = view;
    if (offset) a["byteOffset"] = offset;
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size() - 1);
  }
  // Tightly packed data in its own bufferView.
  template <class T>
  int data(const std::vector<T>& values, int component_type, const std::string& type, bool normalized = false) {
    return accessor(view(values), component_type, type, values.size() / size_t(components(type)), normalized);
  }
  int add(const char* array, const json& item) {
    doc[array].push_back(item);
    return int(doc[array].size() - 1);
  }
  int mesh(const json& primitives) { return add("meshes", {{"primitives", primitives}}); }
  void scene(const std::vector<int>& roots) { doc["scenes"] = json::array({{{"nodes", roots}}}); }

  json finished(const std::string& uri) const {
    json d = doc;
    if (!bin.empty()) {
      d["buffers"] = json::array({{{"byteLength", bin.size()}}});
      if (!uri.empty()) d["buffers"][0]["uri"] = uri;
    }
    return d;
  }
  // Writes name.gltf (+ name.bin unless embedded as a data URI); returns the .gltf path.
  std::string write(const fs::path& dir, const std::string& name, bool embed = false) const {
    const std::string uri = embed ? "data:application/octet-stream;base64," + base64(bin) : name + ".bin";
    if (!embed && !bin.empty())
      std::ofstream(dir / (name + ".bin"), std::ios::binary).write((const char*)bin.data(), long(bin.size()));
    std::ofstream(dir / (name + ".gltf")) << finished(uri).dump(1);
    return (dir / (name + ".gltf")).string();
  }
  std::vector<uint8_t> glb() const {
    std::string text = finished("").dump();
    while (text.size() % 4) text += ' ';
    std::vector<uint8_t> payload = bin;
    while (payload.size() % 4) payload.push_back(0);
    std::vector<uint8_t> out = {'g', 'l', 'T', 'F'};
    put_le32(out, 2);
    put_le32(out, uint32_t(12 + 8 + text.size() + (payload.empty() ? 0 : 8 + payload.size())));
    put_le32(out, uint32_t(text.size()));
    put_le32(out, 0x4E4F534Au);
    out.insert(out.end(), text.begin(), text.end());
    if (!payload.empty()) {
      put_le32(out, uint32_t(payload.size()));
      put_le32(out, 0x004E4942u);
      out.insert(out.end(), payload.begin(), payload.end());
    }
    return out;
  }
};

inline void write_bytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), long(bytes.size()));
}

// The loader's error for a file, or "(loaded without error)".
inline std::string load_error(const std::string& path) {
  try {
    load_scene(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(loaded without error)";
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace gltf_builder_detail

using namespace gltf_builder_detail;

}  // namespace pmr::test
