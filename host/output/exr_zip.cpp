// The ZIP-compressed scanline EXR writer (exr_zip.h). Layout of a single-part scanline file: magic and
// version, the header's attributes (Imf::Header::writeTo), the offset table (one 64-bit file offset
// per chunk), then per chunk its first y (int32), its data size (int32) and its data: for each of its
// scanlines, each channel in name order, the scanline's values (little-endian). ZIP data is that
// block preconditioned (exr_zip_precondition) and zlib-compressed; a chunk that does not shrink is
// stored as it is, which readers recognise by its size.
#include "output/exr_zip.h"

#include <ImfChannelList.h>
#include <ImfStdIO.h>
#include <ImfVersion.h>
#include <libdeflate.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include "pmr/error.h"

namespace pmr {
namespace {

constexpr int kLinesPerChunk = 16;  // ZIP_COMPRESSION's chunk height

struct ChunkChannel {
  const char* base;
  size_t x_stride, y_stride, bytes;  // bytes per value: 2 (half) or 4 (float)
};

// OpenEXR sets LONG_NAMES_FLAG when a name or type name is longer than 31 characters.
bool uses_long_names(const Imf::Header& h) {
  for (auto a = h.begin(); a != h.end(); ++a)
    if (std::strlen(a.name()) > 31 || std::strlen(a.attribute().typeName()) > 31) return true;
  for (auto c = h.channels().begin(); c != h.channels().end(); ++c)
    if (std::strlen(c.name()) > 31) return true;
  return false;
}

void put32(std::vector<unsigned char>& out, uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
}

// EXR's ZIP preconditioning (OpenEXR's ImfZip.cpp, which every reader inverts) of the raw bytes of the
// scanlines [y0, y1), in two passes straight from the pixels: first the bytes at even raw offsets then
// those at odd ones (split), then each byte as its difference from the previous one + 128 (out). Every
// channel's scanline has an even number of bytes, so the parity of a value's bytes is their parity
// within the value: a half's low byte is even, a float's bytes 0 and 2 are. Little-endian host.
size_t precondition_chunk(const std::vector<ChunkChannel>& channels, int width, int y0, int y1, unsigned char* split,
                          unsigned char* out) {
  size_t n = 0;
  for (const ChunkChannel& c : channels) n += size_t(width) * c.bytes;
  n *= size_t(y1 - y0);
  unsigned char* even = split;
  unsigned char* odd = split + n / 2;
  for (int y = y0; y < y1; ++y)
    for (const ChunkChannel& c : channels) {
      const char* row = c.base + size_t(y) * c.y_stride;
      if (c.bytes == 2) {
        for (int x = 0; x < width; ++x) {
          uint16_t v;
          std::memcpy(&v, row + size_t(x) * c.x_stride, 2);
          even[x] = static_cast<unsigned char>(v);
          odd[x] = static_cast<unsigned char>(v >> 8);
        }
        even += width, odd += width;
      } else {
        for (int x = 0; x < width; ++x) {
          uint32_t v;
          std::memcpy(&v, row + size_t(x) * c.x_stride, 4);
          even[2 * x] = static_cast<unsigned char>(v), even[2 * x + 1] = static_cast<unsigned char>(v >> 16);
          odd[2 * x] = static_cast<unsigned char>(v >> 8), odd[2 * x + 1] = static_cast<unsigned char>(v >> 24);
        }
        even += 2 * size_t(width), odd += 2 * size_t(width);
      }
    }
  out[0] = split[0];
  for (size_t i = 1; i < n; ++i) out[i] = static_cast<unsigned char>(split[i] - split[i - 1] + 128u);
  return n;
}

// The raw bytes of the scanlines [y0, y1): each channel's values in turn, scanline by scanline (a chunk
// that deflate does not shrink is stored so).
void raw_chunk(const std::vector<ChunkChannel>& channels, int width, int y0, int y1, unsigned char* raw) {
  for (int y = y0; y < y1; ++y)
    for (const ChunkChannel& c : channels) {
      const char* row = c.base + size_t(y) * c.y_stride;
      for (int x = 0; x < width; ++x, raw += c.bytes) std::memcpy(raw, row + size_t(x) * c.x_stride, c.bytes);
    }
}

// A compressing thread's buffers, kept from file to file: fresh ones would cost a page fault every
// 4 kB on every frame.
struct Scratch {
  int level = 0;
  std::unique_ptr<libdeflate_compressor, void (*)(libdeflate_compressor*)> z{nullptr, libdeflate_free_compressor};
  std::vector<unsigned char> split, pre, packed;
};

std::atomic<uint64_t> helper_cpu_ns{0};

uint64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return uint64_t(t.tv_sec) * 1000000000u + uint64_t(t.tv_nsec);
}

std::mutex scratch_mutex;
std::vector<std::unique_ptr<Scratch>> scratch_pool;

std::unique_ptr<Scratch> take_scratch() {
  std::lock_guard<std::mutex> lock(scratch_mutex);
  if (scratch_pool.empty()) return std::make_unique<Scratch>();
  std::unique_ptr<Scratch> s = std::move(scratch_pool.back());
  scratch_pool.pop_back();
  return s;
}

void give_back(std::unique_ptr<Scratch> s) {
  std::lock_guard<std::mutex> lock(scratch_mutex);
  scratch_pool.push_back(std::move(s));
}

}  // namespace

double exr_zip_helper_cpu_seconds() { return 1e-9 * double(helper_cpu_ns.load()); }

void write_zip_exr(const std::string& path, const std::string& shown_path, const Imf::Header& header,
                   const std::vector<ExrZipChannel>& channels, int level, int threads) {
  static_assert(sizeof(float) == 4, "EXR floats are 4 bytes");
  {
    const uint16_t probe = 1;
    unsigned char first;
    std::memcpy(&first, &probe, 1);
    if (first != 1) throw Error("cannot write " + shown_path + ": the ZIP EXR writer needs a little-endian host");
  }
  if (header.compression() != Imf::ZIP_COMPRESSION)
    throw Error("cannot write " + shown_path + ": internal error: write_zip_exr needs a ZIP header");
  header.sanityCheck();
  const Imath::Box2i dw = header.dataWindow();
  const int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;

  // the channels in the header's (name) order, each matched to its pixels
  std::vector<ChunkChannel> order;
  size_t line_bytes = 0;
  for (auto c = header.channels().begin(); c != header.channels().end(); ++c) {
    const auto given = std::find_if(channels.begin(), channels.end(),
                                    [&](const ExrZipChannel& g) { return g.name == c.name(); });
    if (given == channels.end() || (c.channel().type != Imf::HALF && c.channel().type != Imf::FLOAT) ||
        c.channel().xSampling != 1 || c.channel().ySampling != 1)
      throw Error("cannot write " + shown_path + ": internal error: no pixels for channel " + c.name());
    const size_t bytes = c.channel().type == Imf::HALF ? 2 : 4;
    order.push_back({given->base, given->x_stride, given->y_stride, bytes});
    line_bytes += size_t(width) * bytes;
  }
  if (order.size() != channels.size())
    throw Error("cannot write " + shown_path + ": internal error: pixels for a channel the header lacks");

  // compress the chunks, each thread taking the next one
  const int chunks = (height + kLinesPerChunk - 1) / kLinesPerChunk;
  std::vector<std::vector<unsigned char>> data(static_cast<size_t>(chunks));
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  auto work = [&] {
    std::unique_ptr<Scratch> scratch = take_scratch();
    Scratch& S = *scratch;
    if (!S.z || S.level != level) S.z.reset(libdeflate_alloc_compressor(level)), S.level = level;
    const size_t max_raw = line_bytes * kLinesPerChunk;
    if (S.z && S.split.size() < max_raw) {
      S.split.resize(max_raw), S.pre.resize(max_raw);
      S.packed.resize(libdeflate_zlib_compress_bound(S.z.get(), max_raw));
    }
    if (!S.z) failed = true;
    for (int c; !failed && (c = next++) < chunks;) {
      const int y0 = c * kLinesPerChunk, y1 = std::min(height, y0 + kLinesPerChunk);
      const size_t n = precondition_chunk(order, width, y0, y1, S.split.data(), S.pre.data());
      const size_t size = libdeflate_zlib_compress(S.z.get(), S.pre.data(), n, S.packed.data(), S.packed.size());
      std::vector<unsigned char>& out = data[size_t(c)];
      out.reserve(8 + (size == 0 || size >= n ? n : size));
      put32(out, uint32_t(dw.min.y + y0));
      if (size == 0 || size >= n) {  // stored: the scanlines' raw bytes (0: did not fit the bound, cannot happen)
        put32(out, uint32_t(n));
        raw_chunk(order, width, y0, y1, S.split.data());
        out.insert(out.end(), S.split.data(), S.split.data() + n);
      } else {
        put32(out, uint32_t(size));
        out.insert(out.end(), S.packed.data(), S.packed.data() + size);
      }
    }
    give_back(std::move(scratch));
  };
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::max(1, std::min(threads, chunks));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t)
    pool.emplace_back([&] {
      work();
      helper_cpu_ns += thread_cpu_ns();  // a fresh thread: all its CPU time was this work
    });
  work();
  for (std::thread& t : pool) t.join();
  if (failed) throw Error("cannot write " + shown_path + ": out of memory for the ZIP compressor");

  // magic, version, header, offset table, chunks
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw Error("cannot write " + shown_path + ": " + std::strerror(errno));
  {
    Imf::StdOFStream os(file, path.c_str());
    std::vector<unsigned char> head;
    put32(head, uint32_t(Imf::MAGIC));
    put32(head, uint32_t(Imf::EXR_VERSION | (uses_long_names(header) ? Imf::LONG_NAMES_FLAG : 0)));
    os.write(reinterpret_cast<const char*>(head.data()), int(head.size()));
    header.writeTo(os);
    uint64_t at = os.tellp() + uint64_t(chunks) * 8u;
    std::vector<unsigned char> table;
    table.reserve(size_t(chunks) * 8u);
    for (const std::vector<unsigned char>& d : data) {
      for (int k = 0; k < 8; ++k) table.push_back(static_cast<unsigned char>(at >> (8 * k)));
      at += d.size();
    }
    os.write(reinterpret_cast<const char*>(table.data()), int(table.size()));
    for (const std::vector<unsigned char>& d : data) os.write(reinterpret_cast<const char*>(d.data()), int(d.size()));
  }
  file.flush();
  if (!file) throw Error("cannot write " + shown_path + ": " + std::strerror(errno));
}

}  // namespace pmr
