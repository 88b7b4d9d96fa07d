// The ZIP-compressed scanline EXR writer (exr_zip.h). Layout of a single-part scanline file: magic and
// version, the header's attributes (Imf::Header::writeTo, ending in an empty name), the offset table
// (one 64-bit file offset per chunk), then per chunk its first y (int32), its data size (int32) and its
// data: for each of its scanlines, each channel in name order, the scanline's values (little-endian).
// A multi-part file (version flag MULTI_PART_FILE_FLAG) has every part's header, then one more empty
// name, then every part's offset table in turn, and each chunk starts with its part number (int32).
// ZIP data is the chunk's block preconditioned (precondition_chunk) and zlib-compressed (ISA-L, and for
// zip libdeflate where it matters: compress_chunk); a chunk that does not shrink is stored as it is,
// which readers recognise by its size.
#include "output/exr_zip.h"

#include <ImfChannelList.h>
#include <ImfStdIO.h>
#include <ImfVersion.h>
#include <isa-l/igzip_lib.h>
#include <libdeflate.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include "pmr/error.h"
#include "pmr/output.h"

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

// How the preconditioner walks a scanline. A run of half channels interleaved in one pixel array (the
// readback's R G B A, the encoder's AR AG AB) is split in one pass over the row; any other channel
// alone. `dest` is each component's offset within the scanline's share of the even (or odd) bytes.
struct SplitRun {
  const char* base;                  // component 0's first value
  size_t x_stride, y_stride, bytes;  // bytes: 2 (half) or 4 (float, always alone)
  int count = 1;                     // components: 1, or 3 or 4 interleaved halves (x_stride 2 * count)
  size_t dest[4] = {};
};

// One pass of a row of 4 (or 3) interleaved halves into each one's low (e) and high (o) bytes. Fixed
// counts and restrict pointers let the compiler vectorize the byte deinterleave.
void split4(const unsigned char* __restrict p, int width, unsigned char* __restrict e0, unsigned char* __restrict e1,
            unsigned char* __restrict e2, unsigned char* __restrict e3, unsigned char* __restrict o0,
            unsigned char* __restrict o1, unsigned char* __restrict o2, unsigned char* __restrict o3) {
  for (int x = 0; x < width; ++x, p += 8) {
    e0[x] = p[0], o0[x] = p[1], e1[x] = p[2], o1[x] = p[3];
    e2[x] = p[4], o2[x] = p[5], e3[x] = p[6], o3[x] = p[7];
  }
}

void split3(const unsigned char* __restrict p, int width, unsigned char* __restrict e0, unsigned char* __restrict e1,
            unsigned char* __restrict e2, unsigned char* __restrict o0, unsigned char* __restrict o1,
            unsigned char* __restrict o2) {
  for (int x = 0; x < width; ++x, p += 6)
    e0[x] = p[0], o0[x] = p[1], e1[x] = p[2], o1[x] = p[3], e2[x] = p[4], o2[x] = p[5];
}

// The runs of a part's channels (given in the header's name order) for a scanline of `width` values.
std::vector<SplitRun> split_runs(const std::vector<ChunkChannel>& channels, int width) {
  std::vector<size_t> dest(channels.size());
  size_t at = 0;
  for (size_t i = 0; i < channels.size(); ++i) dest[i] = at, at += size_t(width) * channels[i].bytes / 2;
  std::vector<bool> taken(channels.size(), false);
  std::vector<SplitRun> runs;
  for (size_t i = 0; i < channels.size(); ++i) {
    if (taken[i]) continue;
    const ChunkChannel& c = channels[i];
    SplitRun run{c.base, c.x_stride, c.y_stride, c.bytes};
    run.dest[0] = dest[i];
    taken[i] = true;
    const int k = int(c.x_stride / 2);
    if (c.bytes == 2 && (c.x_stride == 6 || c.x_stride == 8)) {
      // the run's components: halves at origin, origin + 2, ... with the same strides, where origin is
      // the lowest address among them (channels come in name order: A before R)
      auto interleaved_with = [&](size_t j) {
        const ChunkChannel& d = channels[j];
        return !taken[j] && d.bytes == 2 && d.x_stride == c.x_stride && d.y_stride == c.y_stride &&
               std::abs(d.base - c.base) < ptrdiff_t(c.x_stride) && (d.base - c.base) % 2 == 0;
      };
      const char* origin = c.base;
      for (size_t j = 0; j < channels.size(); ++j)
        if (interleaved_with(j)) origin = std::min(origin, channels[j].base);
      std::vector<size_t> parts(size_t(k), channels.size());
      parts[size_t((c.base - origin) / 2)] = i;
      for (size_t j = 0; j < channels.size(); ++j) {
        const ptrdiff_t off = channels[j].base - origin;
        if (interleaved_with(j) && off < ptrdiff_t(c.x_stride)) parts[size_t(off / 2)] = j;
      }
      if (std::all_of(parts.begin(), parts.end(), [&](size_t j) { return j < channels.size(); })) {
        run.base = origin;
        run.count = k;
        for (int m = 0; m < k; ++m) run.dest[m] = dest[parts[size_t(m)]], taken[parts[size_t(m)]] = true;
      }
    }
    runs.push_back(run);
  }
  return runs;
}

// EXR's ZIP preconditioning (OpenEXR's ImfZip.cpp, which every reader inverts) of the raw bytes of the
// scanlines [y0, y1), in two passes straight from the pixels: first the bytes at even raw offsets then
// those at odd ones (split), then each byte as its difference from the previous one + 128 (out). Every
// channel's scanline has an even number of bytes, so the parity of a value's bytes is their parity
// within the value: a half's low byte is even, a float's bytes 0 and 2 are. Little-endian host.
size_t precondition_chunk(const std::vector<SplitRun>& runs, size_t line_bytes, int width, int y0, int y1,
                          unsigned char* split, unsigned char* out) {
  const size_t n = line_bytes * size_t(y1 - y0), half_line = line_bytes / 2;
  for (int y = y0; y < y1; ++y) {
    unsigned char* even = split + size_t(y - y0) * half_line;
    unsigned char* odd = even + n / 2;
    for (const SplitRun& r : runs) {
      const unsigned char* row = reinterpret_cast<const unsigned char*>(r.base) + size_t(y) * r.y_stride;
      const size_t* d = r.dest;
      if (r.count == 4) {
        split4(row, width, even + d[0], even + d[1], even + d[2], even + d[3], odd + d[0], odd + d[1], odd + d[2],
               odd + d[3]);
      } else if (r.count == 3) {
        split3(row, width, even + d[0], even + d[1], even + d[2], odd + d[0], odd + d[1], odd + d[2]);
      } else if (r.bytes == 2) {
        for (int x = 0; x < width; ++x) {
          uint16_t v;
          std::memcpy(&v, row + size_t(x) * r.x_stride, 2);
          even[d[0] + size_t(x)] = static_cast<unsigned char>(v);
          odd[d[0] + size_t(x)] = static_cast<unsigned char>(v >> 8);
        }
      } else {
        for (int x = 0; x < width; ++x) {
          uint32_t v;
          std::memcpy(&v, row + size_t(x) * r.x_stride, 4);
          unsigned char* e = even + d[0] + 2 * size_t(x);
          unsigned char* o = odd + d[0] + 2 * size_t(x);
          e[0] = static_cast<unsigned char>(v), e[1] = static_cast<unsigned char>(v >> 16);
          o[0] = static_cast<unsigned char>(v >> 8), o[1] = static_cast<unsigned char>(v >> 24);
        }
      }
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
  std::unique_ptr<libdeflate_compressor, void (*)(libdeflate_compressor*)> z{nullptr, libdeflate_free_compressor};
  std::vector<uint8_t> isal_level_buf;  // ISA-L's per-level work area
  std::vector<unsigned char> split, pre, packed;
};

constexpr int kDefaultLevel = 4;                                           // libdeflate: OpenEXR's own zlib level
constexpr uint32_t kFastLevel = 2, kFastLevelBuf = ISAL_DEF_LVL2_DEFAULT;  // ISA-L igzip
// zip keeps ISA-L's stream of a chunk it shrinks at least this much: on such chunks (background,
// alpha runs) libdeflate saves few bytes for 7-8x the time. Measured over three rendered paper-8k frames:
// files 1.000-1.018x of libdeflate-only ones for 0.62-0.66x of its deflate time (docs/SEQUENCES.md).
constexpr size_t kKeepFastRatio = 16;

// Zeroed bytes after a chunk's input (compress_fast): ISA-L's encoder may look up to ISAL_LOOK_AHEAD
// (288) bytes past a position, plus a vector load, so the whole look-ahead is defined. (Once, under
// ctest -j2, a views file came out 3 bytes longer than the same file rendered again, same pixels;
// stale bytes past 64 are one suspect, not proven: ExrZip.TheSamePixelsGiveTheSameBytesWhateverCameBefore
// does not reproduce it with 64.)
constexpr size_t kInputSlack = ISAL_LOOK_AHEAD + 64;

// Room for the compressed chunk of `n` raw bytes; a chunk that needs more is stored raw.
size_t packed_bound(size_t n) { return n + n / 8 + 1024; }

// ISA-L's zlib stream of n bytes of `in` in S.packed: its size, or 0 when it does not fit.
size_t compress_fast(Scratch& S, unsigned char* in, size_t n) {
  // The same chunk must give the same bytes (files of two identical renders are identical, tested):
  // ISA-L's work area is reused from chunk to chunk, so it starts cleared, and the bytes just past the
  // input, which a hashing encoder may look at, are zeros rather than what the buffer held before.
  std::memset(S.isal_level_buf.data(), 0, S.isal_level_buf.size());
  std::memset(in + n, 0, kInputSlack);
  isal_zstream s;
  std::memset(&s, 0, sizeof s);  // every field defined (hist_bits, flags), whatever the init below leaves
  isal_deflate_stateless_init(&s);
  s.next_in = in;
  s.avail_in = uint32_t(n);
  s.next_out = S.packed.data();
  s.avail_out = uint32_t(S.packed.size());
  s.level = kFastLevel;
  s.level_buf = S.isal_level_buf.data();
  s.level_buf_size = uint32_t(S.isal_level_buf.size());
  s.end_of_stream = 1;
  s.flush = NO_FLUSH;
  s.gzip_flag = IGZIP_ZLIB;
  return isal_deflate_stateless(&s) == COMP_OK ? size_t(s.total_out) : 0;
}

// Compresses n bytes of `in` into S.packed as a zlib stream; returns its size, or 0 when it does not fit
// (the caller then stores the chunk raw). zip-fast: ISA-L. zip: ISA-L first, then libdeflate for a
// chunk ISA-L does not shrink kKeepFastRatio-fold.
size_t compress_chunk(Scratch& S, ZipEncoder encoder, unsigned char* in, size_t n) {
  const size_t fast = compress_fast(S, in, n);
  if (encoder == ZipEncoder::Fast || (fast > 0 && fast * kKeepFastRatio <= n)) return fast;
  return libdeflate_zlib_compress(S.z.get(), in, n, S.packed.data(), S.packed.size());
}

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

namespace {

// A part as the compressing threads see it: the channels in the header's (name) order.
struct PartLayout {
  std::vector<ChunkChannel> order;
  std::vector<SplitRun> runs;
  int width = 0, height = 0, min_y = 0, chunks = 0;
  size_t line_bytes = 0;
};

PartLayout layout_of(const ExrZipPart& part, const std::string& shown_path) {
  const Imf::Header& header = part.header;
  if (header.compression() != Imf::ZIP_COMPRESSION)
    throw InternalError("cannot write " + shown_path + ": write_zip_exr needs a ZIP header");
  const Imath::Box2i dw = header.dataWindow();
  PartLayout L;
  L.width = dw.max.x - dw.min.x + 1, L.height = dw.max.y - dw.min.y + 1, L.min_y = dw.min.y;
  L.chunks = (L.height + kLinesPerChunk - 1) / kLinesPerChunk;
  for (auto c = header.channels().begin(); c != header.channels().end(); ++c) {
    const auto given = std::find_if(part.channels.begin(), part.channels.end(),
                                    [&](const ExrZipChannel& g) { return g.name == c.name(); });
    if (given == part.channels.end() || (c.channel().type != Imf::HALF && c.channel().type != Imf::FLOAT) ||
        c.channel().xSampling != 1 || c.channel().ySampling != 1)
      throw InternalError("cannot write " + shown_path + ": no pixels for channel " + c.name());
    const size_t bytes = c.channel().type == Imf::HALF ? 2 : 4;
    L.order.push_back({given->base, given->x_stride, given->y_stride, bytes});
    L.line_bytes += size_t(L.width) * bytes;
  }
  if (L.order.size() != part.channels.size())
    throw InternalError("cannot write " + shown_path + ": pixels for a channel the header lacks");
  L.runs = split_runs(L.order, L.width);
  return L;
}

void check_little_endian(const std::string& shown_path) {
  static_assert(sizeof(float) == 4, "EXR floats are 4 bytes");
  const uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  if (first != 1) throw Error("cannot write " + shown_path + ": the ZIP EXR writer needs a little-endian host");
}

struct FileLayout {
  bool multi = false, long_names = false;
  std::vector<Imf::Header> headers;  // as written: a multi-part file's with their chunk counts
  std::vector<PartLayout> parts;
  size_t max_raw = 0;  // the largest chunk's raw bytes: the size of every thread's buffers
};

FileLayout file_layout(const std::vector<ExrZipPart>& parts, const std::string& shown_path) {
  if (parts.empty()) throw InternalError("cannot write " + shown_path + ": an EXR file without parts");
  FileLayout F;
  F.multi = parts.size() > 1;
  for (const ExrZipPart& part : parts) {
    F.parts.push_back(layout_of(part, shown_path));
    F.headers.push_back(part.header);
    if (F.multi) F.headers.back().setChunkCount(F.parts.back().chunks);  // required in a multi-part file
    F.headers.back().sanityCheck(false, F.multi);
    F.long_names = F.long_names || uses_long_names(part.header);
    F.max_raw = std::max(F.max_raw, F.parts.back().line_bytes * kLinesPerChunk);
  }
  return F;
}

struct ChunkJob {
  int part, chunk;
};

// false when the compressor cannot be allocated.
bool prepare_scratch(Scratch& S, ZipEncoder encoder, size_t max_raw) {
  if (encoder == ZipEncoder::Default && !S.z) {
    S.z.reset(libdeflate_alloc_compressor(kDefaultLevel));
    if (!S.z) return false;
  }
  if (S.isal_level_buf.size() < kFastLevelBuf) S.isal_level_buf.resize(kFastLevelBuf);
  if (S.split.size() < max_raw)
    S.split.resize(max_raw), S.pre.resize(max_raw + kInputSlack), S.packed.resize(packed_bound(max_raw));
  return true;
}

// A chunk as stored in the file: its part number (multi-part files), first y, data size and data.
std::vector<unsigned char> encode_chunk(Scratch& S, const FileLayout& F, ChunkJob job, ZipEncoder encoder) {
  const PartLayout& L = F.parts[size_t(job.part)];
  const int y0 = job.chunk * kLinesPerChunk, y1 = std::min(L.height, y0 + kLinesPerChunk);
  const size_t n = precondition_chunk(L.runs, L.line_bytes, L.width, y0, y1, S.split.data(), S.pre.data());
  const size_t size = compress_chunk(S, encoder, S.pre.data(), n);
  const bool stored = size == 0 || size >= n;  // the scanlines' raw bytes (0: did not fit)
  std::vector<unsigned char> out;
  out.reserve(12 + (stored ? n : size));
  if (F.multi) put32(out, uint32_t(job.part));
  put32(out, uint32_t(L.min_y + y0));
  if (stored) {
    put32(out, uint32_t(n));
    raw_chunk(L.order, L.width, y0, y1, S.split.data());
    out.insert(out.end(), S.split.data(), S.split.data() + n);
  } else {
    put32(out, uint32_t(size));
    out.insert(out.end(), S.packed.data(), S.packed.data() + size);
  }
  return out;
}

// Every part's chunks in job order (part by part), each thread taking the next one.
std::vector<std::vector<unsigned char>> encode_chunks(const FileLayout& F, ZipEncoder encoder, int threads,
                                                      const std::string& shown_path) {
  std::vector<ChunkJob> jobs;
  for (size_t p = 0; p < F.parts.size(); ++p)
    for (int c = 0; c < F.parts[p].chunks; ++c) jobs.push_back({int(p), c});
  std::vector<std::vector<unsigned char>> data(jobs.size());
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  auto work = [&] {
    std::unique_ptr<Scratch> scratch = take_scratch();
    if (!prepare_scratch(*scratch, encoder, F.max_raw)) failed = true;
    for (size_t j; !failed && (j = next++) < jobs.size();) data[j] = encode_chunk(*scratch, F, jobs[j], encoder);
    give_back(std::move(scratch));
  };
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  threads = int(std::max<size_t>(1, std::min(size_t(threads), jobs.size())));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t)
    pool.emplace_back([&] {
      work();
      helper_cpu_ns += thread_cpu_ns();  // a fresh thread: all its CPU time was this work
    });
  work();
  for (std::thread& t : pool) t.join();
  if (failed) throw Error("cannot write " + shown_path + ": out of memory for the ZIP compressor");
  return data;
}

// Magic, version, headers, offset tables, chunks.
void write_file(const std::string& path, const std::string& shown_path, const FileLayout& F,
                const std::vector<std::vector<unsigned char>>& chunks) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw Error("cannot write " + shown_path + ": " + write_failure(errno));
  {
    Imf::StdOFStream os(file, path.c_str());
    std::vector<unsigned char> head;
    put32(head, uint32_t(Imf::MAGIC));
    put32(head, uint32_t(Imf::EXR_VERSION | (F.multi ? Imf::MULTI_PART_FILE_FLAG : 0) |
                         (F.long_names ? Imf::LONG_NAMES_FLAG : 0)));
    os.write(reinterpret_cast<const char*>(head.data()), int(head.size()));
    for (const Imf::Header& h : F.headers) h.writeTo(os);
    if (F.multi) os.write("", 1);  // the empty header that ends the list
    uint64_t at = os.tellp() + uint64_t(chunks.size()) * 8u;
    std::vector<unsigned char> table;
    table.reserve(chunks.size() * 8u);
    for (const std::vector<unsigned char>& d : chunks) {
      for (int k = 0; k < 8; ++k) table.push_back(static_cast<unsigned char>(at >> (8 * k)));
      at += d.size();
    }
    os.write(reinterpret_cast<const char*>(table.data()), int(table.size()));
    for (const std::vector<unsigned char>& d : chunks) os.write(reinterpret_cast<const char*>(d.data()), int(d.size()));
  }
  file.flush();
  if (!file) throw Error("cannot write " + shown_path + ": " + write_failure(errno));
}

}  // namespace

void write_zip_exr(const std::string& path, const std::string& shown_path, const std::vector<ExrZipPart>& parts,
                   ZipEncoder encoder, int threads) {
  check_little_endian(shown_path);
  const FileLayout layout = file_layout(parts, shown_path);
  write_file(path, shown_path, layout, encode_chunks(layout, encoder, threads, shown_path));
}

}  // namespace pmr
