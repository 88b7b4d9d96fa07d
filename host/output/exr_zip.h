// The ZIP-compressed scanline EXR writer: the header from OpenEXR (Imf::Header::writeTo), the chunks
// compressed here with libdeflate, in parallel, straight from the caller's pixels. The file is a
// standard single-part ZIP_COMPRESSION EXR (16 scanlines per chunk) that every reader opens.
#pragma once

#include <ImfHeader.h>

#include <cstddef>
#include <string>
#include <vector>

namespace pmr {

// One channel of the image: element (x, y) at base + x * x_stride + y * y_stride bytes, a half (2 bytes)
// or a float (4 bytes), matching the header's channel of the same name.
struct ExrZipChannel {
  std::string name;
  const char* base;
  size_t x_stride, y_stride;
};

// Writes `header` (whose compression must be ZIP_COMPRESSION; its channels are the ones given, in any
// order) and the pixels to the file `path`, compressing at zlib-style `level` (1-12; OpenEXR's default
// is 4) on `threads` threads (0: the hardware's). Throws pmr::Error naming `shown_path`.
void write_zip_exr(const std::string& path, const std::string& shown_path, const Imf::Header& header,
                   const std::vector<ExrZipChannel>& channels, int level, int threads);

// The CPU time (seconds, summed since the process started) of the threads write_zip_exr starts besides
// the calling one, whose own time the caller can measure.
double exr_zip_helper_cpu_seconds();

}  // namespace pmr
