// pmr_view_quality REF.exr IMAGE.exr...: the antialiasing error of another renderer's views (OpenGL's,
// tests/bench/gl_quality.sh) measured as `pmr quality` measures pmr's: REF holds the same views 4x as
// wide and tall (16 samples per pixel there make 64 per pixel here), box-filtered down; each IMAGE is
// compared with it over premultiplied RGBA with colour clamped to [0, 1], over every pixel and over the
// edge pixels (host/quality/samples_quality.h). Files: one part per view, channels R, G, B, A.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "quality/samples_quality.h"

namespace {

struct Views {
  int views = 0, w = 0, h = 0;
  std::vector<float> rgba;  // [view][y][x][4]
};

Views read_views(const std::string& path) {
  Imf::MultiPartInputFile file(path.c_str());
  Views out;
  out.views = file.parts();
  for (int p = 0; p < file.parts(); ++p) {
    Imf::InputPart in(file, p);
    const Imath::Box2i dw = in.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (p == 0) out.w = w, out.h = h, out.rgba.resize(size_t(out.views) * size_t(w) * size_t(h) * 4);
    if (w != out.w || h != out.h) throw std::runtime_error(path + ": views of different sizes");
    float* view = out.rgba.data() + size_t(p) * size_t(w) * size_t(h) * 4;
    char* base = reinterpret_cast<char*>(view) - (size_t(dw.min.x) + size_t(dw.min.y) * size_t(w)) * 16;
    Imf::FrameBuffer fb;
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + 4 * c, 16, size_t(w) * 16));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  }
  for (float& x : out.rgba) x = std::clamp(x, 0.0f, 1.0f);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: pmr_view_quality REF.exr IMAGE.exr...\n");
    return 2;
  }
  try {
    const Views fine = read_views(argv[1]);
    if (fine.w % 4 != 0 || fine.h % 4 != 0) throw std::runtime_error("the reference's views are not 4x the images'");
    const int w = fine.w / 4, h = fine.h / 4;
    const std::vector<float> ref =
        pmr::downsample_2x2(pmr::downsample_2x2(fine.rgba, fine.views, 2 * w, 2 * h), fine.views, w, h);
    std::printf("%-40s %8s %8s %6s\n", "image", "rmse", "edge", "edge%");
    for (int i = 2; i < argc; ++i) {
      const Views img = read_views(argv[i]);
      if (img.views != fine.views || img.w != w || img.h != h)
        throw std::runtime_error(std::string(argv[i]) + ": not the reference's views at a quarter of their size");
      const pmr::ViewDifference d = pmr::compare_views(img.rgba, ref, img.views, w, h);
      std::printf("%-40s %8.5f %8.5f %6.2f\n", argv[i], d.rmse, d.edge_rmse, 100.0 * d.edge_fraction);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmr_view_quality: %s\n", e.what());
    return 2;
  }
}
