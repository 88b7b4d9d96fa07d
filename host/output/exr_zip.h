// The ZIP-compressed scanline EXR writer: the headers from OpenEXR (Imf::Header::writeTo), the chunks
// compressed here with libdeflate, in parallel, straight from the caller's pixels. The file is a
// standard ZIP_COMPRESSION scanline EXR (16 scanlines per chunk), single-part or multi-part, that every
// reader opens.
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

// One part of the file: its header (compression ZIP_COMPRESSION; in a file of several parts, with a
// unique name and the type scanlineimage) and the pixels of each of its channels, in any order.
struct ExrZipPart {
  Imf::Header header;
  std::vector<ExrZipChannel> channels;
};

// Which deflate encoder compresses the chunks. Both write standard zlib streams, so the file is the same
// ZIP EXR either way; they trade size for time (docs/SEQUENCES.md, "The ZIP writer"):
//   Default: ISA-L's igzip at level 2 for the chunks it shrinks 16-fold or more, libdeflate at level 4
//     (OpenEXR's own level) for the others: a third of OpenEXR's writer CPU for files within 2% of its
//     zlib ones.
//   Fast: ISA-L's igzip at level 2 for every chunk: deflate 7x faster than libdeflate, files about 11%
//     larger.
enum class ZipEncoder { Default, Fast };

// Writes the parts (one: a single-part file; more: a multi-part file, each header given its chunkCount)
// to the file `path`, compressing with `encoder` on `threads` threads (0: the hardware's). Throws
// pmr::Error naming `shown_path`.
void write_zip_exr(const std::string& path, const std::string& shown_path, const std::vector<ExrZipPart>& parts,
                   ZipEncoder encoder, int threads);

// The CPU time (seconds, summed since the process started) of the threads write_zip_exr starts besides
// the calling one, whose own time the caller can measure.
double exr_zip_helper_cpu_seconds();

}  // namespace pmr
