// pmr_exr_writer_bench FRAME.exr [REPEATS]: the EXR writers of docs/SEQUENCES.md ("The ZIP writer") side
// by side on one encoded frame that pmr wrote (R, G, B, A and, when present, AR, AG, AB). Per channel
// set, one compressing thread, CPU time (best of REPEATS, default 3) and file size of:
//   - OpenEXR's own ZIP writer (zlib at its level 4): what `zip` was before pmr's writer;
//   - pmr's writer with zip (libdeflate 4) and zip-fast (ISA-L igzip 2), as `pmr render` calls it;
//   - the deflate encoders alone on the same preconditioned 16-scanline chunks (the floor of a writer).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfThreading.h>
#include <isa-l/igzip_lib.h>
#include <libdeflate.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "pmr/output.h"

namespace {

// The process's CPU time: OpenEXR may compress on its own pool thread (pmr's writer sets its thread
// count), and every thread's time counts.
double process_cpu() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double best_cpu(int repeats, const std::function<void()>& f) {
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = process_cpu();
    f();
    best = std::min(best, process_cpu() - t0);
  }
  return best;
}

// The frame's channels as planes of halves, in EXR name order.
struct Frame {
  int width = 0, height = 0;
  std::vector<std::string> names;
  std::vector<std::vector<uint16_t>> planes;
};

// The preconditioned ZIP chunks (16 scanlines, channels in name order, bytes split even/odd and delta
// coded) of the first `channels` planes.
std::vector<std::vector<unsigned char>> preconditioned_chunks(const Frame& f, const std::vector<int>& channels) {
  std::vector<std::vector<unsigned char>> chunks;
  for (int y0 = 0; y0 < f.height; y0 += 16) {
    std::vector<unsigned char> raw;
    for (int y = y0; y < std::min(f.height, y0 + 16); ++y)
      for (int c : channels) {
        const auto* p =
            reinterpret_cast<const unsigned char*>(f.planes[size_t(c)].data() + size_t(y) * size_t(f.width));
        raw.insert(raw.end(), p, p + 2 * size_t(f.width));
      }
    const size_t n = raw.size();
    std::vector<unsigned char> split(n), out(n);
    for (size_t i = 0; i < n / 2; ++i) split[i] = raw[2 * i], split[n / 2 + i] = raw[2 * i + 1];
    out[0] = split[0];
    for (size_t i = 1; i < n; ++i) out[i] = static_cast<unsigned char>(split[i] - split[i - 1] + 128u);
    chunks.push_back(std::move(out));
  }
  return chunks;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: pmr_exr_writer_bench FRAME.exr [REPEATS]\n");
    return 2;
  }
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  const std::string out_dir =
      std::filesystem::temp_directory_path() / ("pmr_exr_writer_bench_" + std::to_string(getpid()));
  std::filesystem::create_directories(out_dir);
  Imf::setGlobalThreadCount(0);  // one thread everywhere
  Frame f;
  {
    Imf::InputFile in(argv[1]);
    const Imath::Box2i dw = in.header().dataWindow();
    f.width = dw.max.x - dw.min.x + 1, f.height = dw.max.y - dw.min.y + 1;
    Imf::FrameBuffer fb;
    for (auto c = in.header().channels().begin(); c != in.header().channels().end(); ++c) f.names.push_back(c.name());
    for (const std::string& n : f.names) {
      f.planes.emplace_back(size_t(f.width) * size_t(f.height));
      fb.insert(
          n, Imf::Slice(Imf::HALF,
                        reinterpret_cast<char*>(f.planes.back().data()) - 2 * (dw.min.x + size_t(dw.min.y) * f.width),
                        2, 2 * size_t(f.width)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  }
  auto index = [&](const char* n) {
    const auto it = std::find(f.names.begin(), f.names.end(), n);
    return it == f.names.end() ? -1 : int(it - f.names.begin());
  };
  const int R = index("R"), G = index("G"), B = index("B"), A = index("A");
  if (R < 0 || G < 0 || B < 0 || A < 0) {
    std::fprintf(stderr, "pmr_exr_writer_bench: %s has no half R, G, B, A\n", argv[1]);
    return 1;
  }
  const int c4[4] = {R, G, B, A}, c3[3] = {index("AR"), index("AG"), index("AB")};
  const bool has_sub = c3[0] >= 0 && c3[1] >= 0 && c3[2] >= 0;
  const size_t px = size_t(f.width) * size_t(f.height);
  std::vector<uint16_t> rgba(px * 4), sub(px * 3);
  for (size_t i = 0; i < px; ++i) {
    for (int k = 0; k < 4; ++k) rgba[4 * i + size_t(k)] = f.planes[size_t(c4[k])][i];
    if (has_sub)
      for (int k = 0; k < 3; ++k) sub[3 * i + size_t(k)] = f.planes[size_t(c3[k])][i];
  }
  std::printf("# %s: %dx%d; one thread, CPU seconds (best of %d), file or stream size in MB\n", argv[1], f.width,
              f.height, repeats);
  for (const bool with_sub : {false, true}) {
    if (with_sub && !has_sub) continue;
    std::vector<int> order;  // name order
    for (size_t c = 0; c < f.names.size(); ++c)
      if (with_sub || (f.names[c].size() == 1 && std::string("RGBA").find(f.names[c]) != std::string::npos))
        order.push_back(int(c));
    std::printf("%s\n", with_sub ? "R G B A AR AG AB" : "R G B A");
    const std::string imf_path = out_dir + "/openexr.exr", ours_path = out_dir + "/ours.exr";
    const double imf = best_cpu(repeats, [&] {
      Imf::Header h(f.width, f.height);
      h.compression() = Imf::ZIP_COMPRESSION;
      Imf::FrameBuffer fb;
      for (int c : order) {
        h.channels().insert(f.names[size_t(c)], Imf::Channel(Imf::HALF));
        fb.insert(f.names[size_t(c)],
                  Imf::Slice(Imf::HALF, reinterpret_cast<char*>(f.planes[size_t(c)].data()), 2, 2 * size_t(f.width)));
      }
      Imf::OutputFile out(imf_path.c_str(), h);
      out.setFrameBuffer(fb);
      out.writePixels(f.height);
    });
    const double imf_mb = double(std::filesystem::file_size(imf_path)) / 1e6;
    std::printf("  %-36s %7.3f s %8.2f MB\n", "OpenEXR ZIP (zlib 4)", imf, imf_mb);
    for (const pmr::ExrCompression c : {pmr::ExrCompression::Zip, pmr::ExrCompression::ZipFast}) {
      const double t = best_cpu(repeats, [&] {
        pmr::write_rgba_exr(ours_path, f.width, f.height, rgba.data(), c, 1, nullptr, 1.0f, nullptr,
                            pmr::ExrImage::Encoded, with_sub ? sub.data() : nullptr);
      });
      const double mb = double(std::filesystem::file_size(ours_path)) / 1e6;
      std::printf("  %-36s %7.3f s %8.2f MB  (%.2fx CPU, %.3fx size)\n",
                  (std::string("pmr writer, ") + pmr::to_string(c)).c_str(), t, mb, t / imf, mb / imf_mb);
    }
    const std::vector<std::vector<unsigned char>> chunks = preconditioned_chunks(f, order);
    size_t raw = 0;
    for (const auto& ch : chunks) raw += ch.size();
    std::vector<unsigned char> dst(chunks[0].size() * 2 + 1024);
    for (const int level : {1, 4}) {
      libdeflate_compressor* z = libdeflate_alloc_compressor(level);
      size_t total = 0;
      const double t = best_cpu(repeats, [&] {
        total = 0;
        for (const auto& ch : chunks)
          total += libdeflate_zlib_compress(z, ch.data(), ch.size(), dst.data(), dst.size());
      });
      libdeflate_free_compressor(z);
      std::printf("  %-36s %7.3f s %8.2f MB  (%.0f MB/s of chunk data)\n",
                  ("deflate alone: libdeflate " + std::to_string(level)).c_str(), t, double(total) / 1e6,
                  double(raw) / 1e6 / t);
    }
    const uint32_t buf_size[4] = {0, ISAL_DEF_LVL1_DEFAULT, ISAL_DEF_LVL2_DEFAULT, ISAL_DEF_LVL3_DEFAULT};
    for (uint32_t level = 1; level <= 3; ++level) {
      std::vector<uint8_t> level_buf(buf_size[level]);
      size_t total = 0;
      const double t = best_cpu(repeats, [&] {
        total = 0;
        for (const auto& ch : chunks) {
          isal_zstream s;
          isal_deflate_stateless_init(&s);
          s.next_in = const_cast<uint8_t*>(ch.data()), s.avail_in = uint32_t(ch.size());
          s.next_out = dst.data(), s.avail_out = uint32_t(dst.size());
          s.level = level, s.level_buf = level_buf.data(), s.level_buf_size = uint32_t(level_buf.size());
          s.end_of_stream = 1, s.flush = NO_FLUSH, s.gzip_flag = IGZIP_ZLIB;
          if (isal_deflate_stateless(&s) == COMP_OK) total += s.total_out;
        }
      });
      std::printf("  %-36s %7.3f s %8.2f MB  (%.0f MB/s of chunk data)\n",
                  ("deflate alone: ISA-L igzip " + std::to_string(level)).c_str(), t, double(total) / 1e6,
                  double(raw) / 1e6 / t);
    }
  }
  std::filesystem::remove_all(out_dir);
  return 0;
}
