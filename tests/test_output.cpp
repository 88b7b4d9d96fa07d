// Output writers (DESIGN section 6): EXR round trips, multi-part views, atomic creation, the sidecar.
#include <gtest/gtest.h>

#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <half.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

// A fresh folder under the system temp folder, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = (fs::temp_directory_path() /
             ("pmr_test_output_" + std::to_string(::getpid()) + "_" + std::to_string(counter++)))
                .string();
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return (fs::path(path_) / name).string(); }
  const std::string& path() const { return path_; }
  // Names of the entries directly in the folder (hidden ones included).
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string path_;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Random half bit patterns, all finite (exponent not all ones); includes zeros, -0, denormals.
std::vector<uint16_t> random_halves(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint16_t> v(n);
  for (auto& h : v) {
    h = uint16_t(rng() & 0xffffu);
    if ((h & 0x7c00u) == 0x7c00u) h &= 0xfbffu;
  }
  return v;
}

uint16_t half_bits(float f) { return half(f).bits(); }

// Runs a command, returns its stdout+stderr.
std::string run(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ::pclose(p);
  return out;
}

// A regular file under which no folder can exist: a reliably unwritable location, even for root.
struct FileAsFolder {
  TempDir dir;
  std::string file = dir / "x.txt";
  FileAsFolder() { write_text(file, "not a folder"); }
};

const ExrCompression kLosslessCompressions[] = {ExrCompression::None, ExrCompression::Zip, ExrCompression::ZipFast,
                                                ExrCompression::Piz, ExrCompression::Rle};
const ExrCompression kAllCompressions[] = {ExrCompression::None, ExrCompression::Zip, ExrCompression::ZipFast,
                                           ExrCompression::Piz,  ExrCompression::Rle, ExrCompression::Dwaa,
                                           ExrCompression::Dwab};

// ---------------------------------------------------------------------------------------------------
TEST(Output, ParseExrCompression) {
  EXPECT_EQ(parse_exr_compression("none"), ExrCompression::None);
  EXPECT_EQ(parse_exr_compression("zip"), ExrCompression::Zip);
  EXPECT_EQ(parse_exr_compression("piz"), ExrCompression::Piz);
  EXPECT_EQ(parse_exr_compression("rle"), ExrCompression::Rle);
  EXPECT_EQ(parse_exr_compression("zip-fast"), ExrCompression::ZipFast);
  for (ExrCompression c : kAllCompressions) EXPECT_EQ(parse_exr_compression(to_string(c)), c);
  EXPECT_THROW(parse_exr_compression("zips"), Error);
  EXPECT_THROW(parse_exr_compression(""), Error);
  EXPECT_THROW(parse_exr_compression("b44"), Error);
}

TEST(Output, RgbaRoundTripIsBitExact) {
  TempDir dir;
  const int sizes[][2] = {{1, 1}, {3, 2}, {17, 5}, {64, 33}};
  uint32_t seed = 1;
  for (ExrCompression c : kLosslessCompressions) {
    for (const auto& s : sizes) {
      const int w = s[0], h = s[1];
      const std::vector<uint16_t> px = random_halves(size_t(w) * h * 4, seed++);
      const std::string path = dir / ("img_" + std::string(to_string(c)) + ".exr");
      write_rgba_exr(path, w, h, px.data(), c, seed % 2 ? 0 : 3);
      int rw = 0, rh = 0;
      std::vector<uint16_t> back;
      read_rgba_exr(path, rw, rh, back);
      ASSERT_EQ(rw, w);
      ASSERT_EQ(rh, h);
      ASSERT_EQ(back.size(), px.size());
      for (size_t k = 0; k < px.size(); ++k)
        ASSERT_EQ(back[k], px[k]) << to_string(c) << " " << w << "x" << h << " element " << k;
    }
  }
  // Only finished files remain, no temporaries.
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"img_none.exr", "img_piz.exr", "img_rle.exr", "img_zip-fast.exr",
                                                     "img_zip.exr"}));
}

// DWAA and DWAB (review renders of views and quilts): a smooth image, as renders are, comes back within
// 1% mean relative error in R, G and B at the library's default level; A (half) and Z (float) exactly,
// as OpenEXR keeps every channel but R, G, B (and luminance / chroma) lossless.
TEST(Output, DwaKeepsColourWithinOnePercentAndAlphaAndDepthExactly) {
  TempDir dir;
  const int w = 96, h = 64, views = 2;
  std::vector<uint16_t> vol(size_t(w) * h * 4 * views);
  std::vector<float> depth(size_t(w) * h * views);
  for (int v = 0; v < views; ++v)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = (size_t(v) * h + y) * w + x;
        const float a = (x * 7 + y * 3) % 5 == 0 ? 0.25f : 1.0f;  // alpha with high-frequency content
        const float r = 0.2f + 0.6f * float(x) / w, g = 0.3f + 0.2f * std::sin(0.1f * float(x + y + v)),
                    b = 0.1f + 0.8f * float(y) / h;
        const float rgb[3] = {r * a, g * a, b * a};
        for (int c = 0; c < 3; ++c) vol[i * 4 + size_t(c)] = half_bits(rgb[c]);
        vol[i * 4 + 3] = half_bits(a);
        depth[i] = 1.0f + 0.013f * float(x * y) + (a < 1.0f ? 1e10f : 0.0f);
      }
  for (ExrCompression c : {ExrCompression::Dwaa, ExrCompression::Dwab}) {
    const std::string path = dir / (std::string(to_string(c)) + ".exr");
    write_views_exr(path, w, h, views, vol.data(), depth.data(), c);
    double rel = 0.0;
    size_t n = 0;
    for (int v = 0; v < views; ++v) {
      int rw = 0, rh = 0;
      std::vector<uint16_t> back;
      std::vector<float> z;
      read_views_exr_part(path, v, rw, rh, back, &z);
      ASSERT_EQ(rw, w);
      ASSERT_EQ(rh, h);
      for (size_t p = 0; p < size_t(w) * h; ++p) {
        const size_t i = size_t(v) * w * h + p;
        ASSERT_EQ(back[p * 4 + 3], vol[i * 4 + 3]) << to_string(c) << " alpha at " << p;
        ASSERT_EQ(z[p], depth[i]) << to_string(c) << " depth at " << p;
        for (int k = 0; k < 3; ++k) {
          half a, b;
          a.setBits(vol[i * 4 + size_t(k)]);
          b.setBits(back[p * 4 + size_t(k)]);
          rel += std::abs(double(float(b)) - double(float(a))) / double(float(a));
          ++n;
        }
      }
    }
    EXPECT_LT(rel / double(n), 0.01) << to_string(c);
    EXPECT_GT(rel / double(n), 0.0) << to_string(c) << " is lossy: an exact image means it was not applied";
  }
}

// Row 0 of the caller's buffer is EXR's top scanline (y = dataWindow.min.y), checked with OpenEXR
// directly rather than with our own reader (which could be flipped the same way).
TEST(Output, RowZeroIsTop) {
  TempDir dir;
  const int w = 5, h = 7;
  std::vector<uint16_t> px(size_t(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint16_t* p = &px[(size_t(y) * w + x) * 4];
      p[0] = half_bits(float(y));
      p[1] = half_bits(float(x));
      p[2] = half_bits(0.5f);
      p[3] = half_bits(1.0f);
    }
  const std::string path = dir / "grad.exr";
  write_rgba_exr(path, w, h, px.data(), ExrCompression::Zip);

  Imf::MultiPartInputFile file(path.c_str());
  ASSERT_EQ(file.parts(), 1);
  Imf::InputPart in(file, 0);
  const Imath::Box2i dw = in.header().dataWindow();
  EXPECT_EQ(dw.min.x, 0);
  EXPECT_EQ(dw.min.y, 0);
  EXPECT_EQ(dw.max.x, w - 1);
  EXPECT_EQ(dw.max.y, h - 1);
  EXPECT_EQ(in.header().lineOrder(), Imf::INCREASING_Y);
  std::vector<half> r(size_t(w) * h, half(-1.0f)), g(size_t(w) * h, half(-1.0f));
  Imf::FrameBuffer fb;
  fb.insert("R", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(r.data()), sizeof(half), sizeof(half) * w));
  fb.insert("G", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(g.data()), sizeof(half), sizeof(half) * w));
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.min.y);  // only the top scanline
  for (int x = 0; x < w; ++x) {
    EXPECT_EQ(float(r[size_t(x)]), 0.0f) << "top scanline must be row 0";
    EXPECT_EQ(float(g[size_t(x)]), float(x)) << "column 0 must be on the left";
  }
  // And our reader agrees: first row is y = 0, last row is y = h - 1.
  int rw = 0, rh = 0;
  std::vector<uint16_t> back;
  read_rgba_exr(path, rw, rh, back);
  ASSERT_EQ(rh, h);
  EXPECT_EQ(back[0], half_bits(0.0f));
  EXPECT_EQ(back[(size_t(h - 1) * w) * 4], half_bits(float(h - 1)));
}

TEST(Output, ExrheaderReadsWrittenFiles) {
  const char* tool = "/usr/bin/exrheader";
  if (::access(tool, X_OK) != 0) GTEST_SKIP() << tool << " is not installed (package openexr); skipped";
  TempDir dir;
  const std::vector<uint16_t> px = random_halves(17 * 5 * 4, 7);
  const std::string img = dir / "img.exr";
  write_rgba_exr(img, 17, 5, px.data(), ExrCompression::Piz);
  const std::string out = run(std::string(tool) + " '" + img + "'");
  EXPECT_NE(out.find("dataWindow (type box2i): (0 0) - (16 4)"), std::string::npos) << out;
  EXPECT_NE(out.find("displayWindow (type box2i): (0 0) - (16 4)"), std::string::npos) << out;
  EXPECT_NE(out.find("piz"), std::string::npos) << out;

  const int w = 6, h = 4, n = 3;
  const std::vector<uint16_t> vol = random_halves(size_t(w) * h * 4 * n, 8);
  const std::string views = dir / "views.exr";
  write_views_exr(views, w, h, n, vol.data(), nullptr, ExrCompression::Zip);
  const std::string vout = run(std::string(tool) + " '" + views + "'");
  EXPECT_NE(vout.find("dataWindow (type box2i): (0 0) - (5 3)"), std::string::npos) << vout;
  EXPECT_NE(vout.find("\"view_000\""), std::string::npos) << vout;
  EXPECT_NE(vout.find("\"view_002\""), std::string::npos) << vout;
  EXPECT_EQ(vout.find("\"view_003\""), std::string::npos) << vout;
}

void check_views_round_trip(bool with_depth, ExrCompression c) {
  SCOPED_TRACE(std::string(with_depth ? "with Z, " : "without Z, ") + to_string(c));
  TempDir dir;
  const int w = 9, h = 4, n = 5;
  const size_t plane = size_t(w) * h;
  const std::vector<uint16_t> vol = random_halves(plane * 4 * n, with_depth ? 11 : 12);
  std::vector<float> depth(plane * n);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& z : depth) z = u(rng);
  const std::string path = dir / "f.views.exr";
  write_views_exr(path, w, h, n, vol.data(), with_depth ? depth.data() : nullptr, c, 2);

  const std::vector<std::string> names = read_exr_part_names(path);
  ASSERT_EQ(names.size(), size_t(n));
  for (int i = 0; i < n; ++i) EXPECT_EQ(names[size_t(i)], "view_00" + std::to_string(i));

  for (int i = 0; i < n; ++i) {
    int rw = 0, rh = 0;
    std::vector<uint16_t> px;
    std::vector<float> z{-1.0f};
    read_views_exr_part(path, i, rw, rh, px, &z);
    ASSERT_EQ(rw, w);
    ASSERT_EQ(rh, h);
    ASSERT_EQ(px.size(), plane * 4);
    for (size_t k = 0; k < plane * 4; ++k)
      ASSERT_EQ(px[k], vol[size_t(i) * plane * 4 + k]) << "part " << i << " element " << k;
    if (with_depth) {
      ASSERT_EQ(z.size(), plane);
      for (size_t k = 0; k < plane; ++k) ASSERT_EQ(z[k], depth[size_t(i) * plane + k]) << "part " << i << " Z " << k;
    } else {
      EXPECT_TRUE(z.empty()) << "a file written without depth must have no Z channel";
    }
  }
  // Part 0 is view 0, and within a part row 0 is the top (OpenEXR read of the top scanline only).
  Imf::MultiPartInputFile file(path.c_str());
  Imf::InputPart part(file, 0);
  EXPECT_EQ(part.header().dataWindow().min.y, 0);
  std::vector<uint16_t> top(size_t(w), 0);
  Imf::FrameBuffer fb;
  fb.insert("G", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(top.data()), sizeof(uint16_t), 0));
  part.setFrameBuffer(fb);
  part.readPixels(0, 0);
  for (int x = 0; x < w; ++x) EXPECT_EQ(top[size_t(x)], vol[size_t(x) * 4 + 1]);
  int rw = 0, rh = 0;
  EXPECT_THROW(read_views_exr_part(path, n, rw, rh, top), Error);
}

TEST(Output, ViewsRoundTripWithoutDepth) {
  check_views_round_trip(false, ExrCompression::Zip);
  check_views_round_trip(false, ExrCompression::None);
}

TEST(Output, ViewsRoundTripWithDepth) {
  check_views_round_trip(true, ExrCompression::Piz);
  check_views_round_trip(true, ExrCompression::Rle);
}

TEST(Output, ViewPartNamesWidenPastOneThousandViews) {
  EXPECT_EQ(view_part_name(0, 1), "view_000");
  EXPECT_EQ(view_part_name(95, 96), "view_095");
  EXPECT_EQ(view_part_name(999, 1000), "view_999");
  EXPECT_EQ(view_part_name(0, 1001), "view_0000");
  EXPECT_EQ(view_part_name(1000, 1001), "view_1000");
  EXPECT_EQ(view_part_name(7, 10001), "view_00007");

  TempDir dir;
  const int n = 1001;
  std::vector<uint16_t> vol(size_t(n) * 4);
  for (int i = 0; i < n; ++i) vol[size_t(i) * 4] = half_bits(float(i));
  const std::string path = dir / "many.exr";
  write_views_exr(path, 1, 1, n, vol.data(), nullptr, ExrCompression::None);
  const std::vector<std::string> names = read_exr_part_names(path);
  ASSERT_EQ(names.size(), size_t(n));
  EXPECT_EQ(names.front(), "view_0000");
  EXPECT_EQ(names.back(), "view_1000");
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end())) << "names must sort in view order";
  int w = 0, h = 0;
  std::vector<uint16_t> px;
  read_views_exr_part(path, 1000, w, h, px);
  EXPECT_EQ(px[0], half_bits(1000.0f));
}

TEST(Output, ViewsPixelAspectIsStored) {
  TempDir dir;
  const std::vector<uint16_t> vol = random_halves(4 * 2 * 4 * 2, 3);
  const std::string path = dir / "v.exr";
  write_views_exr(path, 4, 2, 2, vol.data(), nullptr, ExrCompression::Zip, 0, 0.8925f);
  Imf::MultiPartInputFile file(path.c_str());
  for (int i = 0; i < 2; ++i) EXPECT_FLOAT_EQ(file.header(i).pixelAspectRatio(), 0.8925f);
  EXPECT_THROW(write_views_exr(path, 4, 2, 2, vol.data(), nullptr, ExrCompression::Zip, 0, 0.0f), Error);
}

// ---------------------------------------------------------------------------------------------------
TEST(Output, AtomicFileWithoutCommitLeavesNothing) {
  TempDir dir;
  const std::string final_path = dir / "a.txt";
  std::string temp;
  {
    AtomicFile f(final_path);
    temp = f.temp_path();
    EXPECT_NE(temp, final_path);
    EXPECT_EQ(fs::path(temp).parent_path(), fs::path(dir.path())) << "temporary must be in the same folder";
    write_text(temp, "partial");
    EXPECT_TRUE(fs::exists(temp));
    EXPECT_FALSE(fs::exists(final_path));
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(final_path));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Output, AtomicFileCommitRenamesAndReplaces) {
  TempDir dir;
  const std::string final_path = dir / "a.txt";
  write_text(final_path, "old");
  {
    AtomicFile f(final_path);
    write_text(f.temp_path(), "new");
    EXPECT_EQ(read_text(final_path), "old") << "the final file must not change before commit";
    f.commit();
    EXPECT_TRUE(f.committed());
    EXPECT_FALSE(fs::exists(f.temp_path()));
  }
  EXPECT_EQ(read_text(final_path), "new");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.txt"});
  // Two files in flight for the same final path get distinct temporaries.
  AtomicFile a(final_path), b(final_path);
  EXPECT_NE(a.temp_path(), b.temp_path());
}

TEST(Output, UnwritableFolderThrows) {
  TempDir dir;
  FileAsFolder blocked;
  const std::string missing = dir / "missing/a.exr";
  const std::string under_file = blocked.file + "/sub/a.exr";
  for (const std::string& p : {missing, under_file}) {
    try {
      AtomicFile f(p);
      ADD_FAILURE() << "no error for " << p;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
    const std::vector<uint16_t> px(4, 0);
    EXPECT_THROW(write_rgba_exr(p, 1, 1, px.data(), ExrCompression::Zip), Error);
    EXPECT_THROW(write_views_exr(p, 1, 1, 1, px.data(), nullptr, ExrCompression::Zip), Error);
    EXPECT_THROW(write_sidecar(p, Rig{}, Display{}, SidecarInfo{}), Error);
  }
  EXPECT_TRUE(dir.entries().empty());
}

// A writer that fails after it started writing keeps the previous file and removes its temporary.
TEST(Output, FailedWriteLeavesNoPartialFile) {
  TempDir dir;
  const std::string path = dir / "frame.exr";
  write_text(path, "previous");
  const std::vector<uint16_t> px(4 * 4, 0);
  EXPECT_THROW(write_rgba_exr(path, 2, 2, px.data(), ExrCompression(42)), Error);
  EXPECT_THROW(write_views_exr(path, 1, 2, 2, px.data(), nullptr, ExrCompression(42)), Error);
  EXPECT_THROW(write_rgba_exr(path, 0, 2, px.data(), ExrCompression::Zip), Error);
  EXPECT_THROW(write_rgba_exr(path, 2, 2, nullptr, ExrCompression::Zip), Error);
  EXPECT_EQ(read_text(path), "previous");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"frame.exr"});
  // Reading something that is not an EXR is a pmr::Error naming the file.
  int w, h;
  std::vector<uint16_t> back;
  try {
    read_rgba_exr(path, w, h, back);
    ADD_FAILURE() << "no error reading a non-EXR file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(Output, PrepareOutputDir) {
  TempDir dir;
  const std::string nested = dir / "a/b/c";
  prepare_output_dir(nested);
  EXPECT_TRUE(fs::is_directory(nested));
  EXPECT_TRUE(fs::is_empty(nested)) << "the write probe must be removed";
  prepare_output_dir(nested);  // existing folder: fine

  FileAsFolder blocked;
  for (const std::string& bad : {blocked.file, blocked.file + "/sub"}) {
    try {
      prepare_output_dir(bad);
      ADD_FAILURE() << "no error for " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("cannot write to output folder " + bad + ": "), std::string::npos)
          << e.what();
    }
  }
  EXPECT_THROW(prepare_output_dir(""), Error);
}

// ---------------------------------------------------------------------------------------------------
glm::dmat4 matrix_from_json(const nlohmann::json& a) {
  EXPECT_TRUE(a.is_array());
  EXPECT_EQ(a.size(), 16u);
  glm::dmat4 m(0.0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = a.at(size_t(c * 4 + r)).get<double>();
  return m;
}

TEST(Output, SidecarMatricesReproduceTheRig) {
  TempDir dir;
  const Rig rig = test::sidecar_rig();
  Display display;
  SidecarInfo info;
  info.scene = "scene.glb";
  info.frame = 7;
  info.render.tile_x = 8;
  info.outputs = {{"encoded", "frame_0007.exr"}, {"views", "frame_0007.views.exr"}};
  info.warnings = {"near plane raised"};
  const std::string path = dir / "frame_0007.json";
  write_sidecar(path, rig, display, info);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"frame_0007.json"});

  const nlohmann::json j = nlohmann::json::parse(read_text(path));
  EXPECT_EQ(j.at("format"), "pmr-sidecar-1");
  EXPECT_EQ(j.at("scene"), "scene.glb");
  EXPECT_EQ(j.at("frame"), 7);
  EXPECT_EQ(j.at("method"), "pmr");
  EXPECT_EQ(j.at("tile").at("x"), 8);
  EXPECT_EQ(j.at("outputs").at("views"), "frame_0007.views.exr");
  EXPECT_EQ(j.at("display").at("tan_slant_fraction"), "1/18");
  EXPECT_EQ(j.at("display").at("offset_fraction"), "-1/12");
  EXPECT_DOUBLE_EQ(j.at("display").at("offset").get<double>(), -1.0 / 12.0);
  EXPECT_EQ(j.at("display").at("sampling"), "nearest");
  EXPECT_EQ(j.at("display").at("size_cm").size(), 2u);
  const auto& jr = j.at("rig");
  EXPECT_EQ(jr.at("views"), 3);
  EXPECT_EQ(jr.at("view_width"), 64);
  EXPECT_EQ(jr.at("near").get<double>(), 3.0);
  EXPECT_EQ(jr.at("near_used").get<double>(), 3.5);
  EXPECT_DOUBLE_EQ(jr.at("yfov_deg").get<double>(), 40.0);
  EXPECT_DOUBLE_EQ(jr.at("disparity_px_per_view_at_infinity").get<double>(), rig.disparity_k() / 2.0);
  EXPECT_DOUBLE_EQ(jr.at("baseline").get<double>(), rig.baseline());
  for (const char* key : {"raster", "ndc_to_raster", "views", "matrices", "depth"})
    EXPECT_TRUE(j.at("conventions").at(key).is_string()) << key;
  EXPECT_EQ(j.at("light_dir_world").size(), 3u);

  // center_view: column-major, bit-exact (doubles are printed with round-trip precision).
  const glm::dmat4 center = matrix_from_json(j.at("center_view"));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_EQ(center[c][r], rig.center_view[c][r]) << "m[" << c << "][" << r << "]";

  const auto& views = j.at("views");
  ASSERT_EQ(views.size(), 3u);
  const glm::dvec4 points[] = {{0.3, -0.2, 0.7, 1.0}, {-1.0, 1.5, -0.5, 1.0}, {2.0, 0.1, 0.0, 1.0}};
  double prev_offset = -1e300;
  for (int i = 0; i < 3; ++i) {
    const auto& v = views.at(size_t(i));
    EXPECT_EQ(v.at("index"), i);
    const double s = v.at("offset").get<double>();
    EXPECT_EQ(s, rig.camera_offset(i));
    EXPECT_GT(s, prev_offset) << "view 0 is the leftmost camera";
    prev_offset = s;
    const glm::dmat4 view = matrix_from_json(v.at("view")), proj = matrix_from_json(v.at("proj"));
    for (const glm::dvec4& p : points) {
      const glm::dvec4 a = proj * view * p, b = rig.projection(i) * rig.view_matrix(i) * p;
      for (int k = 0; k < 4; ++k)
        EXPECT_NEAR(a[k], b[k], 1e-12 * (1.0 + std::abs(b[k]))) << "view " << i << " component " << k;
    }
    // view_i = T(-s_i, 0, 0) * center_view, from the JSON numbers alone.
    const glm::dmat4 expect = glm::translate(glm::dmat4(1.0), glm::dvec3(-s, 0.0, 0.0)) * center;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(view[c][r], expect[c][r], 1e-12) << "view " << i << " m[" << c << "][" << r << "]";
  }
  EXPECT_NEAR(views.at(0).at("offset").get<double>(), -0.5 * rig.baseline(), 1e-12);

  // An independent renderer using only the JSON: a point on the focal plane lands on the same raster
  // position in every view (DESIGN section 2), with the documented NDC-to-raster mapping.
  const glm::dvec4 focal_view(0.4, -0.3, -rig.focal, 1.0);
  const glm::dvec4 world = glm::inverse(center) * focal_view;
  double x0 = 0, y0 = 0;
  for (int i = 0; i < 3; ++i) {
    const glm::dvec4 clip =
        matrix_from_json(views.at(size_t(i)).at("proj")) * matrix_from_json(views.at(size_t(i)).at("view")) * world;
    const double x = (clip.x / clip.w + 1.0) / 2.0 * rig.view_w, y = (1.0 - clip.y / clip.w) / 2.0 * rig.view_h;
    if (i == 0) {
      x0 = x;
      y0 = y;
    }
    EXPECT_NEAR(x, x0, 1e-9) << "view " << i;
    EXPECT_NEAR(y, y0, 1e-9) << "view " << i;
  }
}

TEST(Output, SidecarSingleViewHasNoInfiniteNumbers) {
  Rig rig = test::sidecar_rig();
  rig.views = 1;
  const nlohmann::json j = nlohmann::json::parse(sidecar_json(rig, Display{}, SidecarInfo{}));
  EXPECT_EQ(j.at("views").size(), 1u);
  EXPECT_EQ(j.at("views").at(0).at("offset").get<double>(), 0.0);
  EXPECT_TRUE(j.at("rig").at("disparity_px_per_view_at_infinity").is_number());
}

}  // namespace
}  // namespace pmr
