// Texture images: PNG and JPEG (the glTF formats) through stb_image, compiled here with only those two
// decoders, its functions static to this file.
//
// The header is read before anything is decoded. Debian's stb_image computes some buffer sizes in
// 32-bit int arithmetic that it does not check: a 16-bit greyscale PNG of 32768x16385 expanded to 4
// channels needs 4 x 32768 x 16385 x 2 bytes, which wraps to 262,144, and the decoder then writes
// gigabytes into that buffer. So an image is decoded only when its pixels are within the
// texture-pixels budget and its decoded size (4 channels of 1 or 2 bytes) fits in an int.
#include <algorithm>
#include <climits>
#include <cstring>
#include <string>
#include <vector>

#include "scene/gltf_internal.h"

#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#include "input/stb_image_static.h"

namespace pmr::gltf {

namespace {

uint32_t be32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

// A copy of the PNG without its empty IDAT chunks (up to the first chunk that runs past the end, after
// which the bytes are kept as they are), or an empty vector when it has none. Empty IDAT chunks are
// legal and carry no data, but Debian's stb_image passes a null buffer to memcpy for one that comes
// first (undefined behaviour that an optimizing compiler may turn into a skipped null check; found by
// the fuzzer).
std::vector<unsigned char> without_empty_idat(const unsigned char* bytes, size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || std::memcmp(bytes, kSignature, 8) != 0) return {};
  std::vector<unsigned char> out(bytes, bytes + 8);
  bool removed = false;
  size_t at = 8;
  for (; at + 12 <= size;) {
    const uint64_t length = be32(bytes + at);
    if (length > size - at - 12) break;  // a chunk past the end: the rest as it is
    if (length == 0 && std::memcmp(bytes + at + 4, "IDAT", 4) == 0) removed = true;
    else out.insert(out.end(), bytes + at, bytes + at + 12 + length);
    at += 12 + size_t(length);
  }
  if (!removed) return {};
  out.insert(out.end(), bytes + at, bytes + size);
  return out;
}

}  // namespace

std::string decode_image(tinygltf::Image& image, const unsigned char* bytes, int size, uint64_t max_pixels,
                         uint64_t memory_left, bool& over_limit) {
  over_limit = false;
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(bytes, size, &w, &h, &comp))
    return std::string("cannot decode it: not a PNG or JPEG image (") + stbi_failure_reason() + ")";
  const bool sixteen = stbi_is_16_bit_from_memory(bytes, size) != 0;
  const uint64_t pixels = uint64_t(w) * uint64_t(h);
  const std::string size_text = std::to_string(w) + "x" + std::to_string(h) + (sixteen ? " 16-bit" : "");
  if (w <= 0 || h <= 0) return "the image has no pixels (" + size_text + ")";
  if (pixels > max_pixels) {
    over_limit = true;
    return size_text + " is " + std::to_string(pixels) + " pixels, more than the texture-pixels limit of " +
           std::to_string(max_pixels) + " (raise it with --limit texture-pixels=N)";
  }
  const uint64_t channel_bytes = sixteen ? 2 : 1, decoded = pixels * 4 * channel_bytes;
  if (decoded > uint64_t(INT_MAX))
    return size_text + " decodes to " + std::to_string(decoded) +
           " bytes, more than the image decoder can address (2 GiB)";
  // While it decodes, the decoder holds the inflated rows (or JPEG planes) in the file's channels and its
  // own RGBA buffer, which is then copied into the kept image: all of it must fit, not just what stays.
  const uint64_t decoding = decoded + pixels * uint64_t(std::max(comp, 1)) * channel_bytes + uint64_t(h);
  if (decoded + decoding > memory_left) {
    over_limit = true;
    return size_text + " decodes to " + std::to_string(decoded >> 20) + " MiB (" +
           std::to_string((decoded + decoding) >> 20) +
           " MiB while decoding), more than the memory budget leaves the scene's decoded images (" +
           std::to_string(memory_left >> 20) + " MiB; raise it with --limit memory=N)";
  }
  const std::vector<unsigned char> cleaned = without_empty_idat(bytes, size_t(size));
  if (!cleaned.empty()) bytes = cleaned.data(), size = int(cleaned.size());
  int dw = 0, dh = 0, dc = 0;
  void* data = sixteen ? static_cast<void*>(stbi_load_16_from_memory(bytes, size, &dw, &dh, &dc, 4))
                       : static_cast<void*>(stbi_load_from_memory(bytes, size, &dw, &dh, &dc, 4));
  if (!data) return std::string("cannot decode it (") + stbi_failure_reason() + ")";
  if (dw != w || dh != h) {  // stb read the header twice: cannot differ, but the buffer size depends on it
    stbi_image_free(data);
    return "cannot decode it (inconsistent size)";
  }
  image.width = w;
  image.height = h;
  image.component = 4;
  image.bits = sixteen ? 16 : 8;
  image.pixel_type = sixteen ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  const unsigned char* p = static_cast<const unsigned char*>(data);
  image.image.assign(p, p + decoded);
  stbi_image_free(data);
  return "";
}

}  // namespace pmr::gltf
