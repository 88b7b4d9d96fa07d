// Reading environment images: Radiance .hdr through stb_image (Debian's libstb-dev header, compiled
// here with only the HDR decoder, functions static to this file) and .exr through OpenEXR.
//
// stb_image's HDR decoder reads past the end of the data as zero bytes: a truncated file decodes as
// black texels, and a run-length count of 0 (which a truncated file produces) makes it loop forever.
// So the bytes are read into memory and walked first with stb's own rules (check_hdr_data), and
// stbi_loadf_from_memory only runs on data that is complete.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <new>
#include <optional>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "pmr/error.h"
#include "pmr/memory_budget.h"
#include "pmr/printable.h"
#include "shading/environment.h"

#define STBI_ONLY_HDR
#define STBI_MAX_DIMENSIONS (1 << 24)
#include "input/stb_image_static.h"

namespace pmr {
namespace {

// A file name safe to print, at most 160 characters.
std::string printable(const std::string& text) { return printable_text(text, 160); }

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  return printable(s);
}

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw Error("cannot read environment " + printable(path) + ": " + why);
}

std::string lower_extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// What is wrong with an image of w x h texels as an environment, "" when nothing: the size the file
// gave and the limits it exceeds.
std::string size_problem(uint64_t w, uint64_t h) {
  const std::string size = std::to_string(w) + "x" + std::to_string(h);
  if (w == 0 || h == 0) return "the image is empty (" + size + ")";
  if (w > kEnvMaxSide || h > kEnvMaxSide || w * h > kEnvMaxTexels)
    return "the image is too large (" + size + "); environments may be at most " + std::to_string(kEnvMaxSide) +
           " texels on a side and " + std::to_string(kEnvMaxTexels) + " texels in all (8192x4096)";
  return "";
}

// The size limits, then the memory decoding and prefiltering the image take (kEnvBytesPerTexel),
// against the memory budget before any pixel is decoded.
void check_size(const std::string& path, uint64_t w, uint64_t h) {
  if (const std::string why = size_problem(w, h); !why.empty()) fail(path, why);
  check_memory(w * h * kEnvBytesPerTexel, "decoding the " + std::to_string(w) + "x" + std::to_string(h) +
                                              " environment " + printable(path));
}

// ---- Radiance .hdr --------------------------------------------------------------------------------

// Walks the header and the scanlines as stb_image 2.27 decodes them (stbi__hdr_load) and returns ""
// when every byte the decoder will read is present and well formed, else what is wrong.
std::string check_hdr_data(const std::vector<unsigned char>& b, int& width, int& height) {
  size_t p = 0;
  auto line = [&](std::string& out) {  // stb's tokens: up to a newline, at most 1023 characters
    out.clear();
    if (p >= b.size()) return false;
    while (p < b.size() && b[p] != '\n') {
      if (out.size() < 1023) out += char(b[p]);
      ++p;
    }
    if (p < b.size()) ++p;  // the newline
    return true;
  };
  std::string t;
  if (!line(t) || (t != "#?RADIANCE" && t != "#?RGBE")) return "not a Radiance HDR file (no #?RADIANCE line)";
  bool rgbe = false;
  for (;;) {
    if (!line(t)) return "truncated header";
    if (t.empty()) break;
    if (t == "FORMAT=32-bit_rle_rgbe") rgbe = true;
    if (t.rfind("FORMAT=", 0) == 0 && t != "FORMAT=32-bit_rle_rgbe")
      return "unsupported pixel format '" + t.substr(7, 40) + "' (only 32-bit_rle_rgbe)";
  }
  if (!rgbe) return "no FORMAT=32-bit_rle_rgbe line in the header";
  if (!line(t)) return "truncated header (no resolution line)";
  long h = 0, w = 0;
  char tail = 0;
  if (std::sscanf(t.c_str(), "-Y %ld +X %ld%c", &h, &w, &tail) != 2)
    return "unsupported resolution line '" + t.substr(0, 40) + "' (only -Y H +X W, rows top to bottom)";
  if (w <= 0 || h <= 0) return "the image is empty (" + std::to_string(w) + "x" + std::to_string(h) + ")";
  if (const std::string why = size_problem(uint64_t(w), uint64_t(h)); !why.empty()) return why;
  width = int(w), height = int(h);
  const uint64_t flat_bytes = uint64_t(w) * uint64_t(h) * 4;
  auto truncated = [&](long row) {
    return "truncated pixel data (row " + std::to_string(row) + " of " + std::to_string(h) + " is incomplete)";
  };
  if (w < 8 || w >= 32768) {
    if (b.size() - p < flat_bytes) return truncated(long((b.size() - p) / (uint64_t(w) * 4)));
    return "";
  }
  for (long j = 0; j < h; ++j) {
    if (b.size() - p < 4) return truncated(j);
    if (b[p] != 2 || b[p + 1] != 2 || (b[p + 2] & 0x80)) {
      if (j != 0) return "corrupt pixel data (row " + std::to_string(j) + " is not run-length encoded)";
      if (b.size() - p < flat_bytes) return truncated(long((b.size() - p) / (uint64_t(w) * 4)));
      return "";
    }
    const long len = (long(b[p + 2]) << 8) | b[p + 3];
    if (len != w) return "corrupt pixel data (row " + std::to_string(j) + " has length " + std::to_string(len) + ")";
    p += 4;
    for (int k = 0; k < 4; ++k) {
      long i = 0;
      while (i < w) {
        if (p >= b.size()) return truncated(j);
        unsigned count = b[p++];
        if (count > 128) {
          count -= 128;
          if (p >= b.size()) return truncated(j);
          ++p;
        } else {
          if (count == 0) return "corrupt pixel data (row " + std::to_string(j) + ": a run of length 0)";
          if (b.size() - p < count) return truncated(j);
          p += count;
        }
        if (long(count) > w - i) return "corrupt pixel data (row " + std::to_string(j) + ": a run past the row's end)";
        i += long(count);
      }
    }
  }
  return "";
}

EnvironmentImage read_hdr(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) fail(path, std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  if (uint64_t(st.st_size) > kEnvMaxFileBytes)
    fail(path, "the file is too large (" + std::to_string(st.st_size) + " bytes; at most " +
                   std::to_string(kEnvMaxFileBytes) + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::strerror(errno));
  std::vector<unsigned char> bytes(static_cast<size_t>(st.st_size));
  if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
    fail(path, "read error");
  if (bytes.empty()) fail(path, "the file is empty");
  if (bytes.size() > size_t(INT32_MAX)) fail(path, "the file is too large");
  int w = 0, h = 0;
  const std::string problem = check_hdr_data(bytes, w, h);
  if (!problem.empty()) fail(path, problem);
  // stb's own view of the size, checked against the budget before anything is decoded.
  int sw = 0, sh = 0, comp = 0;
  if (!stbi_info_from_memory(bytes.data(), int(bytes.size()), &sw, &sh, &comp))
    fail(path, "not a readable Radiance HDR file (" + one_line(stbi_failure_reason()) + ")");
  check_size(path, uint64_t(sw), uint64_t(sh));
  if (sw != w || sh != h) fail(path, "inconsistent size in the header");
  float* pixels = stbi_loadf_from_memory(bytes.data(), int(bytes.size()), &sw, &sh, &comp, 3);
  if (!pixels) fail(path, "cannot decode it (" + one_line(stbi_failure_reason()) + ")");
  EnvironmentImage img;
  img.width = sw, img.height = sh;
  img.rgb.assign(pixels, pixels + size_t(sw) * size_t(sh) * 3);
  stbi_image_free(pixels);
  return img;
}

// ---- OpenEXR ----------------------------------------------------------------------------------------

// OpenEXR's C++ reader (3.1) allocates the declared size of a string, vector or unknown (opaque)
// header attribute, and 4 w h bytes for a preview image, before reading it: a 280-byte file declaring a
// 1.7 GB attribute cost 1.7 GB (found by fuzzing). Walks the header(s) as that reader does (Header::
// readFrom: a channel list is read up to its terminating entry and the fixed-size types by their own
// size, whatever size the file declares for them) and returns what is wrong when such an allocation
// would exceed what the file holds after it; "" otherwise (OpenEXR then reports anything else).
// Opening the file also allocates line buffers of (bytes per pixel) x (data window width) x (lines per
// chunk): the data window, the channels' bytes per pixel and the compression are returned for a check
// of that before OpenEXR opens the file (a 414-byte file claiming 824203271 x 133687 cost 1.6 GB).
struct ExrLayout {
  bool has_window = false;
  int64_t min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  uint64_t bytes_per_pixel = 0;
  int compression = 0;
};
// The header bytes of an EXR file, read in OpenEXR's order and encoding, counting the bytes read so
// far: what an attribute declares is checked against what the file holds after it (left()).
class ExrHeaderReader {
 public:
  ExrHeaderReader(const std::string& path, uint64_t file_size) : in_(path, std::ios::binary), file_size_(file_size) {}
  // The magic number and the version field; false when this is no EXR file (OpenEXR then says so).
  bool read_magic(bool& multipart) {
    unsigned char head[8];
    if (!in_.read(reinterpret_cast<char*>(head), 8) || head[0] != 0x76 || head[1] != 0x2f || head[2] != 0x31 ||
        head[3] != 0x01)
      return false;
    pos_ = 8;
    multipart = head[5] & 0x10;  // version flags, bit 12
    return true;
  }
  bool read_name(std::string& out) {  // null-terminated, at most 255 bytes
    out.clear();
    for (char c; in_.get(c);) {
      ++pos_;
      if (c == '\0') return true;
      if (out.size() == 255) return false;
      out += c;
    }
    return false;
  }
  bool read_u32(uint32_t& v) {  // little-endian
    unsigned char b[4];
    if (!in_.read(reinterpret_cast<char*>(b), 4)) return false;
    pos_ += 4;
    v = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
    return true;
  }
  int read_byte() {
    ++pos_;
    return in_.get();
  }
  void skip(uint64_t n) {
    in_.seekg(std::streamoff(n), std::ios::cur);
    pos_ += n;
  }
  // A multi-part file's list of headers ends with an empty header: one more empty name.
  bool at_end_of_headers() { return in_.peek() == 0; }
  uint64_t left() const { return file_size_ - std::min(pos_, file_size_); }

 private:
  std::ifstream in_;
  uint64_t file_size_ = 0, pos_ = 0;
};

// What checking one attribute found: nothing (std::nullopt: read on), or the walk's answer: "" when
// the header cannot be read further (OpenEXR reports what is wrong), else the problem.
using AttributeCheck = std::optional<std::string>;

std::string quoted_name(const std::string& name) { return "'" + printable(name.substr(0, 40)) + "'"; }

// The channel list: channels (name, pixel type, 12 more bytes) up to an empty name, however long the
// file declares it.
AttributeCheck read_channels(ExrHeaderReader& in, ExrLayout& layout) {
  std::string channel;
  uint32_t pixel_type = 0;
  while (in.read_name(channel) && !channel.empty() && in.read_u32(pixel_type)) {
    layout.bytes_per_pixel += pixel_type == 1 ? 2 : 4;  // HALF, else UINT or FLOAT
    in.skip(12);
  }
  return std::nullopt;
}

AttributeCheck read_data_window(ExrHeaderReader& in, ExrLayout& layout) {
  uint32_t v[4];
  for (uint32_t& x : v)
    if (!in.read_u32(x)) return "";
  layout.has_window = true;
  layout.min_x = int32_t(v[0]), layout.min_y = int32_t(v[1]), layout.max_x = int32_t(v[2]),
  layout.max_y = int32_t(v[3]);
  return std::nullopt;
}

// A preview image: 4 w h bytes allocated, whatever size the attribute declares.
AttributeCheck check_preview(ExrHeaderReader& in, const std::string& name) {
  uint32_t w = 0, h = 0;
  if (!in.read_u32(w) || !in.read_u32(h)) return "";
  if (uint64_t(w) * h * 4 > in.left())
    return "preview attribute " + quoted_name(name) + " of " + std::to_string(w) + "x" + std::to_string(h) +
           " pixels is larger than the file";
  in.skip(uint64_t(w) * h * 4);
  return std::nullopt;
}

// Strings of their own length each, within the declared size: each one allocated as it declares.
AttributeCheck check_string_vector(ExrHeaderReader& in, const std::string& name, uint32_t size) {
  for (uint64_t read = 0; read < size;) {
    uint32_t n = 0;
    if (!in.read_u32(n)) return "";
    if (n > in.left())
      return "header attribute " + quoted_name(name) + " holds a string of " + std::to_string(n) +
             " bytes, more than the file holds";
    in.skip(n);
    read += 4 + uint64_t(n);
  }
  return std::nullopt;
}

// The bytes OpenEXR reads for an attribute of a fixed-size type, whatever size the file declares; 0
// for the other types.
uint64_t fixed_size(const std::string& type) {
  static const std::pair<const char*, uint64_t> kFixed[] = {{"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
                                                            {"compression", 1}, {"double", 8},   {"envmap", 1},
                                                            {"float", 4},       {"int", 4},      {"keycode", 28},
                                                            {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
                                                            {"m44f", 64},       {"m44d", 128},   {"rational", 8},
                                                            {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
                                                            {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
                                                            {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
  for (const auto& [t, n] : kFixed)
    if (type == t) return n;
  return 0;
}

// One attribute after its name, type and declared size, read as OpenEXR's Header::readFrom does.
AttributeCheck check_attribute(ExrHeaderReader& in, const std::string& name, const std::string& type, uint32_t size,
                               ExrLayout& layout) {
  if (type == "chlist") return read_channels(in, layout);
  if (type == "box2i" && name == "dataWindow") return read_data_window(in, layout);
  if (type == "compression" && name == "compression") {
    layout.compression = in.read_byte();
    return std::nullopt;
  }
  if (type == "preview") return check_preview(in, name);
  if (type == "stringvector") return check_string_vector(in, name, size);
  if (const uint64_t n = fixed_size(type)) {
    in.skip(n);
    return std::nullopt;
  }
  if (size > in.left())  // string, floatvector or an unknown type: size bytes allocated
    return "header attribute " + quoted_name(name) + " declares " + std::to_string(size) +
           " bytes, more than the file holds";
  in.skip(size);
  return std::nullopt;
}

std::string check_exr_allocations(const std::string& path, uint64_t file_size, ExrLayout& layout) {
  ExrHeaderReader in(path, file_size);
  bool multipart = false;
  if (!in.read_magic(multipart)) return "";
  for (;;) {  // attributes until an empty name; a multi-part file's headers end with an empty one
    std::string name, type;
    uint32_t size = 0;
    if (!in.read_name(name)) return "";
    if (name.empty()) {
      if (!multipart || in.at_end_of_headers()) return "";
      continue;
    }
    if (!in.read_name(type) || !in.read_u32(size)) return "";
    if (const AttributeCheck found = check_attribute(in, name, type, size, layout)) return *found;
  }
}

EnvironmentImage read_exr(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) fail(path, std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  if (st.st_size == 0) fail(path, "the file is empty");
  ExrLayout layout;
  if (const std::string why = check_exr_allocations(path, uint64_t(st.st_size), layout); !why.empty())
    fail(path, "not a readable OpenEXR file (" + why + ")");
  if (layout.has_window) {  // the size limits, before OpenEXR sizes its line buffers by the window
    const int64_t w = layout.max_x - layout.min_x + 1, h = layout.max_y - layout.min_y + 1;
    if (w <= 0 || h <= 0) fail(path, "the image is empty");
    check_size(path, uint64_t(w), uint64_t(h));
    static const uint64_t kLinesPerChunk[10] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};  // by compression
    const uint64_t lines = layout.compression >= 0 && layout.compression < 10 ? kLinesPerChunk[layout.compression] : 1;
    if (layout.bytes_per_pixel * uint64_t(w) * lines > (uint64_t(1) << 30))
      fail(path, "its " + std::to_string(layout.bytes_per_pixel) + " bytes per pixel in rows of " + std::to_string(w) +
                     " need more than 1 GiB of line buffers to read");
  }
  EnvironmentImage img;
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const int64_t w = int64_t(dw.max.x) - int64_t(dw.min.x) + 1, h = int64_t(dw.max.y) - int64_t(dw.min.y) + 1;
    if (w <= 0 || h <= 0) fail(path, "the image is empty");
    check_size(path, uint64_t(w), uint64_t(h));
    const Imf::ChannelList& ch = file.header().channels();
    const bool rgb = ch.findChannel("R") && ch.findChannel("G") && ch.findChannel("B");
    const bool gray = !rgb && ch.findChannel("Y");
    if (!rgb && !gray) fail(path, "no R, G, B (or Y) channels");
    // before the pixels are allocated: a small file claiming a large data window costs nothing
    if (!file.isComplete()) fail(path, "the file is truncated (some pixel data is missing)");
    img.width = int(w), img.height = int(h);
    img.rgb.assign(size_t(w) * size_t(h) * 3, 0.0f);
    Imf::FrameBuffer fb;
    const size_t xs = 3 * sizeof(float), ys = size_t(w) * xs;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < (rgb ? 3 : 1); ++c)
      fb.insert(rgb ? names[c] : "Y", Imf::Slice::Make(Imf::FLOAT, img.rgb.data() + c, dw, xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    if (gray)
      for (size_t t = 0; t < size_t(w) * size_t(h); ++t) img.rgb[3 * t + 1] = img.rgb[3 * t + 2] = img.rgb[3 * t];
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {  // not the file's fault: not "not a readable OpenEXR file"
    fail(path, "out of host memory while reading it");
  } catch (const std::exception& e) {  // Iex::BaseExc derives from std::exception
    std::string msg = e.what();
    for (size_t at = msg.find(path); !path.empty() && at != std::string::npos; at = msg.find(path))
      msg.replace(at, path.size(), "the file");
    fail(path, "not a readable OpenEXR file (" + one_line(msg.substr(0, 200)) + ")");
  }
  return img;
}

}  // namespace

namespace {

void check_image(EnvironmentImage& img, const std::string& lead) {
  if (img.width <= 0 || img.height <= 0) throw Error(lead + "the image is empty");
  if (uint64_t(img.width) * uint64_t(img.height) > kEnvMaxTexels) throw Error(lead + "the image is too large");
  if (img.rgb.size() != size_t(img.width) * size_t(img.height) * 3)
    throw Error(lead + "pixel data does not match the size");
  static const char* channel[3] = {"R", "G", "B"};
  auto refuse = [&](size_t t, const char* what) {
    const size_t px = t / 3;
    char value[64];
    std::snprintf(value, sizeof value, "%g", double(img.rgb[t]));
    throw Error(lead + "pixel (" + std::to_string(px % size_t(img.width)) + ", " +
                std::to_string(px / size_t(img.width)) + ") (column, row from the top-left) has " + what +
                channel[t % 3] + " = " + value + "; radiance must be finite and >= 0");
  };
  double sum = 0.0;
  for (size_t t = 0; t < img.rgb.size(); ++t) {
    if (!std::isfinite(img.rgb[t])) refuse(t, "non-finite ");
    sum += std::max(0.0f, img.rgb[t]);
  }
  // Lossy EXR compression (DWA) leaves tiny negative values, e.g. -2e-4 in images of mean 0.1 to 1:
  // those down to -kEnvNegativeTolerance x the mean are read as 0, anything below is refused.
  const double tolerance = kEnvNegativeTolerance * sum / double(img.rgb.size());
  for (size_t t = 0; t < img.rgb.size(); ++t)
    if (img.rgb[t] < 0.0f) {
      if (double(img.rgb[t]) < -tolerance) refuse(t, "negative ");
      img.rgb[t] = 0.0f;
    }
}

}  // namespace

void check_environment_image(EnvironmentImage& img, const std::string& name) {
  check_image(img, "environment " + printable(name) + ": ");
}

EnvironmentImage load_environment_image(const std::string& path) {
  if (path.empty()) throw Error("cannot read environment: no file name given");
  const std::string ext = lower_extension(path);
  EnvironmentImage img;
  if (ext == ".hdr") img = read_hdr(path);
  else if (ext == ".exr") img = read_exr(path);
  else fail(path, "unknown extension '" + printable(ext.substr(0, 16)) + "' (an environment is a .hdr or .exr file)");
  check_image(img, "cannot read environment " + printable(path) + ": ");
  return img;
}

}  // namespace pmr
