// The encoded image's per-subpixel alpha (docs/OUTPUTS.md): each display subpixel shows one view's
// sample, so it has its own coverage. The EXR stores it as OpenEXR's per-channel alpha AR, AG, AB
// (A is their mean), and compositing the encoded image over an encoded background with them gives
// exactly the encoding of the views composited over that background.
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <half.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cli/options.h"
#include "pipeline/pipeline.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "test_util.h"

namespace pmr {
namespace {

// Every channel of a scanline EXR as floats, by name ([y][x]).
std::map<std::string, std::vector<float>> read_channels(const std::string& path, int& w, int& h) {
  Imf::InputFile in(path.c_str());
  const Imath::Box2i dw = in.header().dataWindow();
  w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  std::map<std::string, std::vector<float>> out;
  Imf::FrameBuffer fb;
  for (auto c = in.header().channels().begin(); c != in.header().channels().end(); ++c) {
    std::vector<float>& v = out[c.name()];
    v.assign(size_t(w) * h, 0.0f);
    fb.insert(c.name(),
              Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()), sizeof(float), sizeof(float) * size_t(w)));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  return out;
}

}  // namespace

// The encoder kernel: subpixel k's alpha is the alpha of the voxel it samples, A their mean.
TEST(EncodedAlpha, EachSubpixelCarriesItsSamplesAlpha) {
  Display display;
  display.width = 96, display.height = 40;
  const int views = 7, vw = 32, vh = 10;
  const std::unique_ptr<Pipeline> pipeline = test::encoder_pipeline(display, views, vw, vh);
  Pipeline& p = *pipeline;
  const size_t plane = size_t(vw) * vh;
  std::vector<uint16_t> vol(plane * views * 4), enc, sub;
  auto alpha_of = [&](int v, int x, int y) { return float((v * 5 + x * 3 + y) % 4) / 4.0f; };  // 0, 1/4, 1/2, 3/4
  for (int v = 0; v < views; ++v)
    for (int y = 0; y < vh; ++y)
      for (int x = 0; x < vw; ++x) {
        const float a = alpha_of(v, x, y);
        for (int c = 0; c < 4; ++c)
          vol[((v * plane) + size_t(y) * vw + x) * 4 + c] = half(c == 3 ? a : 0.5f * a).bits();
      }
  p.encode_volume(vol);
  p.read_display(enc);
  p.read_sub_alpha(sub);
  ASSERT_EQ(sub.size(), size_t(display.width) * display.height * 3);
  size_t mixed = 0;
  for (int i = 0; i < display.height; ++i)
    for (int j = 0; j < display.width; ++j) {
      const size_t px = size_t(i) * display.width + j;
      float sum = 0.0f;
      for (int k = 0; k < 3; ++k) {
        const double u = (j + (k + 0.5) / 3.0) / display.width, t = (i + 0.5) / display.height;
        const float want =
            alpha_of(encode_view_index(display, views, j, i, k), int(std::floor(u * vw)), int(std::floor(t * vh)));
        ASSERT_EQ(test::half_value(sub[px * 3 + size_t(k)]), want) << "subpixel " << j << "," << i << "," << k;
        sum += want;
      }
      EXPECT_NEAR(test::half_value(enc[px * 4 + 3]), sum / 3.0f, 1e-3f) << "pixel " << j << "," << i;
      mixed += test::half_value(sub[px * 3]) != test::half_value(sub[px * 3 + 1]) ||
               test::half_value(sub[px * 3 + 1]) != test::half_value(sub[px * 3 + 2]);
    }
  EXPECT_GT(mixed, size_t(display.width) * display.height / 4);  // the subpixels' alphas do differ
}

// End to end through `pmr render`: on the views path, the fused path and --sampling subpixel the EXR has
// AR, AG, AB; over an encoded background they composite to the encoding of the views composited over
// that background, which the single mean alpha A does not.
TEST(EncodedAlpha, CompositesLikeTheViewsOverABackground) {
  const std::string out = test::temp_dir("encoded_alpha");
  // one sample per pixel: a subpixel's alpha is then its one sample's coverage, 0 or 1 (checked below)
  const std::string rig = " -q --views 6 --view-size 96x48 --display 300x160 --frames 0 --samples 1";
  ASSERT_EQ(test::run("render" + rig + " --write encoded,views --name views --out " + out).status, 0);
  ASSERT_EQ(test::run("render" + rig + " --write encoded --name fused --out " + out).status, 0);
  ASSERT_EQ(test::run("render" + rig + " --write encoded --sampling subpixel --name subpixel --out " + out).status, 0);
  int w = 0, h = 0, vw = 0, vh = 0;
  const auto enc = read_channels(out + "/views.exr", w, h);
  for (const char* c : {"R", "G", "B", "A", "AR", "AG", "AB"}) ASSERT_EQ(enc.count(c), 1u) << c;
  // the fused path writes the same image, alpha channels included
  int fw = 0, fh = 0;
  const auto fused = read_channels(out + "/fused.exr", fw, fh);
  for (const char* c : {"R", "G", "B", "A", "AR", "AG", "AB"}) EXPECT_EQ(fused.at(c), enc.at(c)) << c;
  // the views, one part each
  const std::vector<std::string> parts = read_exr_part_names(out + "/views.views.exr");
  ASSERT_EQ(parts.size(), 6u);
  std::vector<std::vector<uint16_t>> views(parts.size());
  for (size_t v = 0; v < parts.size(); ++v) read_views_exr_part(out + "/views.views.exr", int(v), vw, vh, views[v]);
  // the display as `render` made it from these options (the lens offset follows the view count)
  RenderOptions o = parse_render_options({"--views", "6", "--view-size", "96x48", "--display", "300x160"});
  finalize_render_options(o);
  const Display& display = o.job.display;
  ASSERT_EQ(display.width, w);
  const float bg[3] = {0.2f, 0.7f, 0.4f};  // an opaque background, the same in every view
  const char* colour[3] = {"R", "G", "B"};
  const char* alpha[3] = {"AR", "AG", "AB"};
  size_t partial = 0, mean_alpha_wrong = 0;
  for (int i = 0; i < h; ++i)
    for (int j = 0; j < w; ++j) {
      const size_t px = size_t(i) * w + j;
      float mean = 0.0f;
      for (int k = 0; k < 3; ++k) {
        const double u = (j + (k + 0.5) / 3.0) / w, t = (i + 0.5) / h;
        const int v = encode_view_index(display, 6, j, i, k);
        const size_t at = (size_t(std::floor(t * vh)) * vw + size_t(std::floor(u * vw))) * 4;
        const float c = test::half_value(views[size_t(v)][at + size_t(k)]),
                    a = test::half_value(views[size_t(v)][at + 3]);
        const float want = c + (1.0f - a) * bg[k];  // the view over the background, premultiplied
        const float got = enc.at(colour[k])[px] + (1.0f - enc.at(alpha[k])[px]) * bg[k];
        ASSERT_NEAR(got, want, 1e-3f) << "subpixel " << j << "," << i << "," << k;
        mean += enc.at(alpha[k])[px] / 3.0f;
        const float with_mean = enc.at(colour[k])[px] + (1.0f - enc.at("A")[px]) * bg[k];
        mean_alpha_wrong += std::fabs(with_mean - want) > 0.05f;
      }
      EXPECT_NEAR(enc.at("A")[px], mean, 1e-3f);
      partial += enc.at("A")[px] > 0.0f && enc.at("A")[px] < 1.0f;
    }
  EXPECT_GT(partial, 0u) << "no silhouette pixel: the test would not see a difference";
  EXPECT_GT(mean_alpha_wrong, 0u) << "the mean alpha composites as well: the test cannot fail";
  // subpixel sampling: each subpixel's alpha is its own sample's coverage, 0 or 1, and A their mean
  int sw = 0, sh = 0;
  const auto sp = read_channels(out + "/subpixel.exr", sw, sh);
  for (const char* c : {"AR", "AG", "AB"}) ASSERT_EQ(sp.count(c), 1u) << c;
  for (size_t px = 0; px < size_t(sw) * sh; ++px) {
    float mean = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const float a = sp.at(alpha[k])[px];
      ASSERT_TRUE(a == 0.0f || a == 1.0f) << a;
      mean += a / 3.0f;
      if (a == 0.0f) {
        ASSERT_EQ(sp.at(colour[k])[px], 0.0f);  // nothing covers it: no colour
      }
    }
    ASSERT_NEAR(sp.at("A")[px], mean, 1e-3f);
  }
}

// --background: the encoded image composited per subpixel equals the no-background image composited
// with its AR, AG, AB; views opaque; the sidecar records it and --resume refuses another one.
TEST(EncodedAlpha, BackgroundIsCompositedPerSubpixel) {
  const std::string out = test::temp_dir("background");
  const std::string rig =
      " -q --views 6 --view-size 96x48 --display 300x160 --frames 0 --write encoded,views --out " + out;
  ASSERT_EQ(test::run("render" + rig + " --name plain").status, 0);
  ASSERT_EQ(test::run("render" + rig + " --name bg --background 0.2,0.7,0.4").status, 0);
  int w = 0, h = 0;
  const auto plain = read_channels(out + "/plain.exr", w, h);
  const auto bg = read_channels(out + "/bg.exr", w, h);
  const float b[3] = {0.2f, 0.7f, 0.4f};
  const char* colour[3] = {"R", "G", "B"};
  const char* alpha[3] = {"AR", "AG", "AB"};
  for (size_t px = 0; px < size_t(w) * h; ++px) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_NEAR(bg.at(colour[k])[px], plain.at(colour[k])[px] + (1.0f - plain.at(alpha[k])[px]) * b[k], 2e-3f);
      ASSERT_EQ(bg.at(alpha[k])[px], 1.0f);
    }
    ASSERT_EQ(bg.at("A")[px], 1.0f);
  }
  std::vector<uint16_t> view;
  int vw = 0, vh = 0;
  read_views_exr_part(out + "/bg.views.exr", 0, vw, vh, view);
  for (size_t i = 0; i < view.size(); i += 4) ASSERT_EQ(test::half_value(view[i + 3]), 1.0f);
  test::CliRun r = test::run("render" + rig + " --name bg --background 0,0,0 --resume");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("background"), std::string::npos) << r.output;
  test::expect_usage_error(test::run("render --background 1,2 --out " + out), "--background");
  test::expect_usage_error(test::run("render --background 0,0,0,2 --out " + out), "--background");
  test::expect_usage_error(test::run("render --background 0,nan,0 --out " + out), "--background");
}

// The Looking Glass presets' quilt PNG is opaque black unless a background is given; paper-8k's keeps
// its transparency.
TEST(EncodedAlpha, LookingGlassQuiltPreviewIsOpaque) {
  const std::string out = test::temp_dir("quilt_opaque");
  const std::string small =
      " -q --views 4 --view-size 64x48 --frames 0 --write quilt --preview --quilt 2x2 --out " + out;
  ASSERT_EQ(test::run("render --preset lg-portrait --camera-spacing linear --name lg" + small).status, 0);
  ASSERT_EQ(test::run("render --name paper" + small).status, 0);
  auto alphas = [&](const std::string& prefix) {
    for (const auto& e : std::filesystem::directory_iterator(out)) {
      const std::string name = e.path().filename().string();
      if (name.rfind(prefix + "_qs", 0) == 0 && e.path().extension() == ".png") {
        int pw = 0, ph = 0;
        std::vector<uint8_t> px;
        read_png_rgba8(e.path().string(), pw, ph, px);
        size_t transparent = 0;
        for (size_t i = 3; i < px.size(); i += 4) transparent += px[i] != 255;
        return transparent;
      }
    }
    ADD_FAILURE() << "no quilt PNG " << prefix;
    return size_t(0);
  };
  EXPECT_EQ(alphas("lg"), 0u);
  EXPECT_GT(alphas("paper"), 0u);
}

}  // namespace pmr
