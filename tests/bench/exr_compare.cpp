// pmr_exr_compare A.exr B.exr: whether two EXR files hold the same pixels, bit for bit, whatever their
// headers and compression (the before/after comparisons of a change). Every part and every channel of
// A must be in B with the same size; prints per part and channel the number of values whose half bits
// differ, and exits 0 only when none do (1 when some differ, 2 when the files cannot be compared).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

namespace {

// One channel of one part as raw 32-bit values (halves are widened to float: equal bits stay equal).
std::vector<uint32_t> read_channel(Imf::MultiPartInputFile& file, int part, const std::string& name, int& w, int& h) {
  Imf::InputPart in(file, part);
  const Imath::Box2i dw = in.header().dataWindow();
  w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  std::vector<uint32_t> out(size_t(w) * size_t(h));
  Imf::FrameBuffer fb;
  char* base = reinterpret_cast<char*>(out.data()) - (size_t(dw.min.x) + size_t(dw.min.y) * size_t(w)) * 4;
  fb.insert(name, Imf::Slice(Imf::FLOAT, base, 4, size_t(w) * 4));
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  return out;
}

// The index of the part of `file` named like part `part` of `other` (single-part files: 0).
int matching_part(Imf::MultiPartInputFile& file, Imf::MultiPartInputFile& other, int part) {
  if (file.parts() == 1 && other.parts() == 1) return 0;
  const std::string name = other.header(part).hasName() ? other.header(part).name() : "";
  for (int p = 0; p < file.parts(); ++p)
    if (file.header(p).hasName() && file.header(p).name() == name) return p;
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: pmr_exr_compare A.exr B.exr\n");
    return 2;
  }
  try {
    Imf::MultiPartInputFile a(argv[1]), b(argv[2]);
    size_t differing = 0;
    for (int p = 0; p < a.parts(); ++p) {
      const int q = matching_part(b, a, p);
      if (q < 0) throw std::runtime_error("part " + std::to_string(p) + " of A is not in B");
      for (auto c = a.header(p).channels().begin(); c != a.header(p).channels().end(); ++c) {
        int wa = 0, ha = 0, wb = 0, hb = 0;
        const std::vector<uint32_t> va = read_channel(a, p, c.name(), wa, ha);
        if (!b.header(q).channels().findChannel(c.name()))
          throw std::runtime_error(std::string("channel ") + c.name() + " is not in B");
        const std::vector<uint32_t> vb = read_channel(b, q, c.name(), wb, hb);
        if (wa != wb || ha != hb) throw std::runtime_error(std::string("channel ") + c.name() + ": sizes differ");
        size_t n = 0;
        double sum = 0.0, max = 0.0;  // how far apart (images of other renderers: tests/bench/gl_compare.sh)
        for (size_t i = 0; i < va.size(); ++i) {
          n += va[i] != vb[i];
          float fa, fb;
          std::memcpy(&fa, &va[i], 4), std::memcpy(&fb, &vb[i], 4);
          const double d = std::fabs(double(fa) - double(fb));
          if (std::isfinite(d)) sum += d, max = std::max(max, d);
        }
        std::printf("part %d channel %s: %zu of %zu values differ (mean |A-B| %.3g, max %.3g)\n", p, c.name(), n,
                    va.size(), va.empty() ? 0.0 : sum / double(va.size()), max);
        differing += n;
      }
    }
    return differing == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmr_exr_compare: %s\n", e.what());
    return 2;
  }
}
