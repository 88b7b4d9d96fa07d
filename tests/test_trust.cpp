// "A finished folder can be trusted": pmr verify checks every output a sidecar lists (plain names of
// regular files in the folder only), sidecars record the program version and checksums of what the
// render read, --resume renders frames from another scene again (one line), verify reports them.
// Each test runs the real pmr binary on a tiny scene and display.
#include <gtest/gtest.h>

#include <chrono>
#include <sys/stat.h>
#include <xxhash.h>

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "output/checksum.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "pmr/version.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using test::run;

const std::string kSmall = " --views 4 --view-size 64x32 --display 240x135 ";  // not -q: tests read the summary

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// XXH3-64 of a file's bytes, computed here with libxxhash directly, as 16 hex digits.
std::string xxh3_of(const std::string& path) {
  const std::string bytes = read_bytes(path);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, uint64_t(XXH3_64bits(bytes.data(), bytes.size())));
  return hex;
}

json sidecar(const std::string& path) { return json::parse(read_bytes(path)); }

// A quad in the z = 0 plane, [-s, s]^2, facing +Z, written as dir/quad.gltf + dir/quad.bin. With
// `textured` its material samples dir/tex.png as base colour; a second image (dir/unused.png) is
// referenced only as a diffuse transmission texture (KHR_materials_diffuse_transmission), which pmr
// never samples. With
// `embedded` the buffer is a data: URI.
struct Quad {
  double r = 1, g = 0, b = 0, size = 1;
  bool textured = false, embedded = false;
  std::string bin = "quad.bin";  // the buffer's URI (percent-encoded), relative to the .gltf
};

std::string base64(const std::string& in) {
  static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < in.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16;
    if (i + 1 < in.size()) v |= uint32_t(uint8_t(in[i + 1])) << 8;
    if (i + 2 < in.size()) v |= uint8_t(in[i + 2]);
    out += t[v >> 18 & 63];
    out += t[v >> 12 & 63];
    out += i + 1 < in.size() ? t[v >> 6 & 63] : '=';
    out += i + 2 < in.size() ? t[v & 63] : '=';
  }
  return out;
}

std::string write_quad(const std::string& dir, const Quad& q) {
  fs::create_directories(dir);
  const float s = float(q.size);
  const float pos[] = {-s, -s, 0, s, -s, 0, s, s, 0, -s, s, 0};
  const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uv[] = {0, 1, 1, 1, 1, 0, 0, 0};
  const uint16_t idx[] = {0, 1, 2, 0, 2, 3};
  std::string bin;
  bin.append(reinterpret_cast<const char*>(pos), sizeof pos);
  bin.append(reinterpret_cast<const char*>(nrm), sizeof nrm);
  bin.append(reinterpret_cast<const char*>(uv), sizeof uv);
  bin.append(reinterpret_cast<const char*>(idx), sizeof idx);
  bin.append(4, '\0');  // 4-byte multiple
  json doc = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}}, {"indices", 3}, {"material", 0}}}}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
        {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 48}},
        {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 32}},
        {{"buffer", 0}, {"byteOffset", 128}, {"byteLength", 12}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 4},
         {"type", "VEC3"},
         {"min", {-s, -s, 0}},
         {"max", {s, s, 0}}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
        {{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}},
        {{"bufferView", 3}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
  };
  doc["buffers"] = {{{"byteLength", bin.size()},
                     {"uri", q.embedded ? "data:application/octet-stream;base64," + base64(bin) : q.bin}}};
  json material = {{"pbrMetallicRoughness", {{"baseColorFactor", {q.r, q.g, q.b, 1.0}}}}, {"doubleSided", true}};
  if (q.textured) {
    material["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    material["extensions"]["KHR_materials_diffuse_transmission"] = {
        {"diffuseTransmissionColorTexture", {{"index", 1}}}};
    doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
    doc["images"] = {{{"uri", "tex.png"}}, {{"uri", "unused.png"}}};
    std::vector<uint16_t> px(4 * 4 * 4, 0x3c00);  // half 1.0: white
    write_png_preview(dir + "/tex.png", 4, 4, px.data());
    write_png_preview(dir + "/unused.png", 4, 4, px.data());
  }
  doc["materials"] = {material};
  if (!q.embedded) {
    std::string file = q.bin;  // decoded as tinygltf does (%20 and %FF only, here)
    for (size_t at; (at = file.find("%20")) != std::string::npos;) file.replace(at, 3, " ");
    for (size_t at; (at = file.find("%FF")) != std::string::npos;) file.replace(at, 3, "\xff");
    fs::create_directories(fs::path(dir + "/" + file).parent_path());
    write_bytes(dir + "/" + file, bin);
  }
  write_bytes(dir + "/quad.gltf", doc.dump(1));
  return dir + "/quad.gltf";
}

size_t count_of(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

// The hash and its text: XXH3-64 of nothing is 2d06800538d394c2 (xxhsum -H3 /dev/null).
TEST(Trust, ChecksumIsXxh3In16HexDigits) {
  EXPECT_EQ(checksum_hex("", 0), "2d06800538d394c2");
  EXPECT_EQ(checksum_hex(uint64_t(0xab)), "00000000000000ab");
  const std::string abc = "abc";
  EXPECT_EQ(checksum64(abc.data(), abc.size()), XXH3_64bits(abc.data(), abc.size()));
}

// Without --write, verify checks every output the sidecar lists: a deleted views file and a truncated
// quilt make their frames broken (they passed before: only the encoded image was checked).
TEST(Trust, VerifyChecksEveryListedOutput) {
  const std::string dir = test::temp_dir("trust_listed");
  const std::string scene = write_quad(dir + "/scene", {});
  const std::string out = dir + "/out";
  const test::CliRun r = run("render " + scene + " --frames 0:2 --write encoded,views,quilt" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  test::CliRun v = run("verify " + out + " --frames 0:2");
  EXPECT_EQ(v.status, 0) << v.output;
  const json j = sidecar(out + "/frame_0001.json");
  fs::remove(out + "/frame_0000.views.exr");
  const std::string quilt = out + "/" + j["outputs"]["quilt"].get<std::string>();
  fs::resize_file(quilt, fs::file_size(quilt) / 2);
  v = run("verify " + out + " --frames 0:2");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 0: frame_0000.views.exr is missing"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("frame 1: " + j["outputs"]["quilt"].get<std::string>() + " is truncated"), std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("1 of 3 frame(s) complete"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("0:1\n"), std::string::npos) << v.output;
  // --write names the kinds to check, as before
  v = run("verify " + out + " --frames 0:2 --write encoded");
  EXPECT_EQ(v.status, 0) << v.output;
  // --resume renders both again; then the folder verifies
  const test::CliRun again =
      run("render " + scene + " --frames 0:2 --resume --write encoded,views,quilt" + kSmall + "--out " + out);
  EXPECT_EQ(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("--resume: 2 frame(s) are incomplete (a file missing, cut short or not the one their "
                              "sidecar lists) (frame_0000.json, frame_0001.json): rendering them"),
            std::string::npos)
      << again.output;
  EXPECT_EQ(run("verify " + out + " --frames 0:2").status, 0);
}

// A sidecar listing one file under many output kinds, without checksums, makes verify decode that file
// once, not once per kind (issue 31: 300k kinds took about 5 hours). 2000 kinds of a 16-view file
// decoded each time take tens of seconds; once, well under a second.
TEST(Trust, VerifyChecksEachFileOnce) {
  const std::string out = test::temp_dir("trust_kinds");
  ASSERT_EQ(
      run("render --frames 0 --views 16 --view-size 256x128 --display 240x135 -q --write encoded,views --out " + out)
          .status,
      0);
  json j = sidecar(out + "/frame_0000.json");
  j.erase("output_checksums");
  for (int k = 0; k < 2000; ++k) j["outputs"]["kind" + std::to_string(k)] = "frame_0000.views.exr";
  write_bytes(out + "/frame_0000.json", j.dump());
  const auto start = std::chrono::steady_clock::now();
  const test::CliRun v = run("verify " + out + " --frames 0");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(v.status, 0) << v.output;
  EXPECT_LT(seconds, 10.0) << "the views file was decoded once per listed kind";
}

// A listed output must be a plain file name of a regular file in the frame's folder.
TEST(Trust, VerifyRefusesOutputsOutsideTheFolderAndSymlinks) {
  const std::string dir = test::temp_dir("trust_names");
  const std::string scene = write_quad(dir + "/scene", {});
  const std::string out = dir + "/out";
  ASSERT_EQ(run("render " + scene + " --frames 0:1" + kSmall + "--out " + out).status, 0);
  const std::string good = read_bytes(out + "/frame_0000.json");
  auto relist = [&](const std::string& name) {
    json j = json::parse(good);
    j["outputs"]["encoded"] = name;
    write_bytes(out + "/frame_0000.json", j.dump(1));
  };
  // a complete EXR one folder up, named through ..
  fs::copy_file(out + "/frame_0000.exr", dir + "/x.exr");
  relist("../x.exr");
  test::CliRun v = run("verify " + out + " --frames 0:1");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 0: frame_0000.json lists encoded output '../x.exr', which is not a plain file name"),
            std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("\n0\n"), std::string::npos) << v.output;
  for (const std::string& bad :
       std::vector<std::string>{"..", ".", "", "a\\b.exr", std::string("a\0b", 3), dir + "/x.exr"}) {
    relist(bad);
    v = run("verify " + out + " --frames 0");
    EXPECT_EQ(v.status, 1) << "'" << bad << "': " << v.output;
    EXPECT_NE(v.output.find("not a plain file name"), std::string::npos) << v.output;
  }
  // control characters are not printed as such
  relist("\x1b]0;owned\x07.exr");
  v = run("verify " + out + " --frames 0");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_EQ(v.output.find('\x1b'), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("\\x1b]0;owned\\x07.exr"), std::string::npos) << v.output;
  // a symbolic link to a complete image (its own name), a folder, a FIFO
  write_bytes(out + "/frame_0000.json", good);
  fs::rename(out + "/frame_0000.exr", dir + "/real.exr");
  fs::create_symlink(dir + "/real.exr", out + "/frame_0000.exr");
  v = run("verify " + out + " --frames 0:1");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 0: frame_0000.exr is not a regular file (a symbolic link)"), std::string::npos)
      << v.output;
  fs::remove(out + "/frame_0000.exr");
  fs::create_directory(out + "/frame_0000.exr");
  v = run("verify " + out + " --frames 0:1");
  EXPECT_NE(v.output.find("frame_0000.exr is not a regular file (a folder)"), std::string::npos) << v.output;
  fs::remove(out + "/frame_0000.exr");
  ASSERT_EQ(mkfifo((out + "/frame_0000.exr").c_str(), 0600), 0);
  v = run("verify " + out + " --frames 0:1");  // must not block opening the FIFO
  EXPECT_NE(v.output.find("frame_0000.exr is not a regular file (a special file)"), std::string::npos) << v.output;
  fs::remove(out + "/frame_0000.exr");
  fs::rename(dir + "/real.exr", out + "/frame_0000.exr");
  EXPECT_EQ(run("verify " + out + " --frames 0:1").status, 0);
}

// The sidecar records the program version and the checksums of the scene file and of every file the
// render read: a .gltf's external buffer and the texture it samples (not the image nothing samples);
// a data: URI and a .glb are the scene file alone; the --display-config file's checksum.
TEST(Trust, SidecarRecordsVersionAndChecksums) {
  const std::string dir = test::temp_dir("trust_sums");
  Quad q;
  q.textured = true;
  const std::string scene = write_quad(dir + "/scene", q);
  ASSERT_EQ(run("render " + scene + kSmall + "--out " + dir + "/o").status, 0);
  json j = sidecar(dir + "/o/frame_0000.json");
  EXPECT_EQ(j["program_version"], program_version());
  EXPECT_EQ(j["checksums"]["algorithm"], "XXH3-64");
  EXPECT_EQ(j["checksums"]["scene"], xxh3_of(scene));
  const json want = {{"quad.bin", xxh3_of(dir + "/scene/quad.bin")}, {"tex.png", xxh3_of(dir + "/scene/tex.png")}};
  EXPECT_EQ(j["checksums"]["scene_files"], want) << j["checksums"].dump();
  EXPECT_FALSE(j["checksums"].contains("display_config"));
  // the buffer in a subfolder, its URI percent-encoded: the path relative to the scene's folder, decoded
  Quad sub;
  sub.bin = "data/my%20quad.bin";
  const std::string in_sub = write_quad(dir + "/sub", sub);
  ASSERT_EQ(run("render " + in_sub + kSmall + "--out " + dir + "/s").status, 0);
  EXPECT_EQ(sidecar(dir + "/s/frame_0000.json")["checksums"]["scene_files"],
            json({{"data/my quad.bin", xxh3_of(dir + "/sub/data/my quad.bin")}}));
  // a data: URI is no file
  Quad e;
  e.embedded = true;
  const std::string embedded = write_quad(dir + "/embedded", e);
  ASSERT_EQ(run("render " + embedded + kSmall + "--out " + dir + "/e").status, 0);
  j = sidecar(dir + "/e/frame_0000.json");
  EXPECT_EQ(j["checksums"]["scene"], xxh3_of(embedded));
  EXPECT_EQ(j["checksums"]["scene_files"], json::object());
  // the bundled default scene (.glb, one file) and a calibration file
  fs::create_directories(dir + "/cal");
  write_bytes(dir + "/cal/visual.json", R"({"serial": "LKG-P0", "pitch": {"value": 52.1}, "slope": {"value": -7.1},
    "center": {"value": 0.56}, "DPI": {"value": 324}, "screenW": {"value": 1536}, "screenH": {"value": 2048},
    "viewCone": {"value": 40}})");
  const test::CliRun r =
      run("render --display-config " + dir + "/cal/visual.json --view-size 42x56 -q --out " + dir + "/d");
  ASSERT_EQ(r.status, 0) << r.output;
  j = sidecar(dir + "/d/frame_0000.json");
  EXPECT_EQ(j["checksums"]["scene"], xxh3_of(j["scene"].get<std::string>()));
  EXPECT_EQ(j["checksums"]["scene_files"], json::object());
  EXPECT_EQ(j["checksums"]["display_config"], xxh3_of(dir + "/cal/visual.json"));
}

// A material colour changed in the scene: --resume renders the frames from the old scene again and says
// so in one line; frames from another scene are reported by verify. A change that moves the framing
// bounds is no configuration refusal either; a sidecar without checksums counts as another scene; a
// program version change is reported, not rendered again.
TEST(Trust, ResumeRendersFramesFromAnotherSceneAgain) {
  const std::string dir = test::temp_dir("trust_resume");
  const std::string out = dir + "/out";
  const std::string scene = write_quad(dir + "/scene", {});
  const std::string args = " --frames 0:3 --turntable 360:8" + kSmall + "--out " + out;
  ASSERT_EQ(run("render " + scene + args).status, 0);
  const std::string red = read_bytes(out + "/frame_0000.exr");
  // the same scene: everything kept
  test::CliRun r = run("render " + scene + " --resume" + args);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("different scene"), std::string::npos) << r.output;
  // green: every old frame again, one line
  Quad green;
  green.r = 0, green.g = 1;
  write_quad(dir + "/scene", green);
  r = run("render " + scene + " --resume --frames 0:5 --turntable 360:8" + kSmall + "--out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count_of(r.output, "different scene"), 1u) << r.output;
  EXPECT_NE(r.output.find("pmr: --resume: 4 frame(s) were rendered from a different scene (frame_0000.json, "
                          "frame_0001.json, frame_0002.json, ...): rendering them again\n"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("6 frame(s) in"), std::string::npos) << r.output;
  EXPECT_NE(read_bytes(out + "/frame_0000.exr"), red);
  EXPECT_EQ(sidecar(out + "/frame_0003.json")["checksums"]["scene"], xxh3_of(scene));
  EXPECT_EQ(run("verify " + out + " --frames 0:5").status, 0);
  // the scene red again and frames 6 and 7 rendered from it: the scene as it is now decides, so the six
  // green frames are the stale ones, however many they are (not the two red ones)
  write_quad(dir + "/scene", {});
  ASSERT_EQ(run("render " + scene + " --frames 6:7 --turntable 360:8" + kSmall + "--out " + out).status, 0);
  test::CliRun v = run("verify " + out + " --frames 0:7");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 0: frame_0000.json was rendered from another version of the scene"), std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("2 of 8 frame(s) complete"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("\n0:5\n"), std::string::npos) << v.output;
  // a bigger quad: the framing bounds and the turntable pivot change with it, no refusal, all again
  Quad big;
  big.size = 2;
  write_quad(dir + "/scene", big);
  r = run("render " + scene + " --resume --frames 0:7 --turntable 360:8" + kSmall + "--out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("8 frame(s) were rendered from a different scene"), std::string::npos) << r.output;
  EXPECT_EQ(run("verify " + out + " --frames 0:7").status, 0);
  // no checksums recorded (an older pmr): rendered again; another version: kept, one line
  json j = sidecar(out + "/frame_0001.json");
  j.erase("checksums");
  write_bytes(out + "/frame_0001.json", j.dump(1));
  j = sidecar(out + "/frame_0002.json");
  j["program_version"] = "0.15.0+gabcdef0";
  write_bytes(out + "/frame_0002.json", j.dump(1));
  v = run("verify " + out + " --frames 0:7");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 1: frame_0001.json records no scene checksum"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("note: the frames were rendered by 2 pmr versions"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("\n1\n"), std::string::npos) << v.output;  // the version alone is no problem
  r = run("render " + scene + " --resume --frames 0:7 --turntable 360:8" + kSmall + "--out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("1 frame(s) were rendered from a different scene; 1 of them record no scene checksum "
                          "(frame_0001.json): rendering them again"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(count_of(r.output, "another pmr version"), 1u) << r.output;
  EXPECT_NE(r.output.find("1 kept frame(s) were rendered by another pmr version (0.15.0+gabcdef0; this is " +
                          std::string(program_version()) + ")"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("1 frame(s) in"), std::string::npos) << r.output;
  EXPECT_EQ(sidecar(out + "/frame_0002.json")["program_version"], "0.15.0+gabcdef0");
  EXPECT_EQ(run("verify " + out + " --frames 0:7").status, 0);
}

// Names that are not UTF-8 (an output pattern, a buffer's file name) are recorded byte-exact beside
// their readable text, so verify finds the files --resume keeps, and sees a changed buffer.
TEST(Trust, NamesThatAreNotUtf8AreRecordedByteExact) {
  const std::string dir = test::temp_dir("trust_bytes"), out = dir + "/out";
  Quad q;
  q.bin = "data%FF.bin";
  const std::string scene = write_quad(dir + "/scene", q);
  const std::string args =
      " --name \"$(printf '\\377\\376_%%04d')\" --frames 0:1 --turntable 360:4" + kSmall + "--out " + out;
  ASSERT_EQ(run("render -q " + scene + args).status, 0);
  const json j = sidecar(out + "/\xff\xfe_0000.json");
  EXPECT_EQ(j["outputs_hex"]["encoded"], "fffe5f303030302e657872") << j.dump();
  EXPECT_EQ(j["checksums"]["scene_files_hex"].size(), 1u) << j["checksums"].dump();
  EXPECT_TRUE(j["checksums"]["scene_files_hex"].contains("64617461ff2e62696e")) << j["checksums"].dump();
  const std::string name = " --name \"$(printf '\\377\\376_%%04d')\"";
  test::CliRun v = run("verify " + out + name + " --frames 0:1");
  EXPECT_EQ(v.status, 0) << v.output;
  test::CliRun r = run("render " + scene + " --resume" + args);
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  // the buffer changes: both see it
  std::string bin = read_bytes(dir + "/scene/data\xff.bin");
  bin[0] ^= 1;
  write_bytes(dir + "/scene/data\xff.bin", bin);
  v = run("verify " + out + name + " --frames 0:1");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("rendered from another version of the scene"), std::string::npos) << v.output;
  r = run("render " + scene + " --resume" + args);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("2 frame(s) were rendered from a different scene"), std::string::npos) << r.output;
}

// verify hashes each scene file once, however many spellings of it the sidecars list: its reading is
// bounded by the bytes on disk (it says how many it read).
TEST(Trust, VerifyHashesEachSceneFileOnceWhateverItsSpelling) {
  const std::string dir = test::temp_dir("trust_spellings"), out = dir + "/out";
  const std::string scene = write_quad(dir + "/scene", {});
  ASSERT_EQ(run("render -q " + scene + " --frames 0:1 --turntable 360:4" + kSmall + "--out " + out).status, 0);
  const std::string sum = xxh3_of(dir + "/scene/quad.bin");
  for (const char* frame : {"/frame_0000.json", "/frame_0001.json"}) {
    json j = sidecar(out + frame);
    std::string spelling = "quad.bin";
    for (int k = 0; k < 500; ++k, spelling = "./" + spelling) j["checksums"]["scene_files"][spelling] = sum;
    write_bytes(out + frame, j.dump());
  }
  const test::CliRun v = run("verify " + out + " --frames 0:1");
  EXPECT_EQ(v.status, 0) << v.output;
  const uint64_t bytes = fs::file_size(scene) + fs::file_size(dir + "/scene/quad.bin");
  EXPECT_NE(v.output.find("read 2 scene file(s), " + std::to_string(bytes) + " bytes"), std::string::npos) << v.output;
}

// A sidecar nested 100,000 deep, or with 300,000 keys, neither crashes nor stalls verify and --resume:
// the frame is unreadable (rendered again), and no lock is left.
TEST(Trust, HostileSidecarsAreUnreadableFramesNotCrashes) {
  const std::string dir = test::temp_dir("trust_hostile"), out = dir + "/out";
  const std::string args = " --frames 0:1 --turntable 360:4" + kSmall + "--out " + out;
  ASSERT_EQ(run("render -q" + args).status, 0);
  write_bytes(out + "/frame_0000.json", std::string(100000, '[') + std::string(100000, ']'));
  json j = sidecar(out + "/frame_0001.json");
  for (int k = 0; k < 300000; ++k) j["extra"]["k" + std::to_string(k)] = k;
  write_bytes(out + "/frame_0001.json", j.dump());
  const auto start = std::chrono::steady_clock::now();
  const test::CliRun v = run("verify " + out + " --frames 0:1");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 0: frame_0000.json is truncated or unreadable"), std::string::npos) << v.output;
  EXPECT_EQ(v.output.find("frame 1:"), std::string::npos) << "extra keys are no damage: " << v.output;
  const test::CliRun r = run("render --resume" + args);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_LT(seconds, 30.0) << "300,000 keys took verify 68 s to parse when lookups were linear";
  for (const std::string& name : test::listing(out)) EXPECT_NE(name[0], '.') << "left behind: " << name;
  // a sidecar of another frame nested 200,000 deep in "format" beside a plain render of frame 2
  json k = sidecar(out + "/frame_0001.json");
  k["frame"] = 3;
  std::string text = k.dump();
  text.replace(text.find("\"pmr-sidecar-1\""), 15, std::string(200000, '[') + std::string(200000, ']'));
  write_bytes(out + "/frame_0003.json", text);
  const test::CliRun plain = run("render --frames 2 --turntable 360:4" + kSmall + "--out " + out);
  EXPECT_TRUE(plain.status == 0 || plain.status == 1) << "no crash: " << plain.status << " " << plain.output;
}

// A sidecar lists at most 256 lights (names cut to about 256 bytes) and a digest of all of them: 300
// lights named with 4 kB each stay a readable sidecar, which --resume and verify agree on.
TEST(Trust, SidecarsOfManyLongNamedLightsStayReadable) {
  const std::string dir = test::temp_dir("trust_lights"), out = dir + "/out";
  const std::string scene = write_quad(dir + "/scene", {});
  json doc = json::parse(read_bytes(scene));
  doc["extensionsUsed"] = {"KHR_lights_punctual"};
  for (int i = 0; i < 300; ++i) {
    doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(
        {{"type", "point"}, {"name", std::string(4000, 'a') + std::to_string(i)}});
    doc["nodes"].push_back({{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}});
    doc["scenes"][0]["nodes"].push_back(i + 1);
  }
  write_bytes(scene, doc.dump());
  const std::string args = " --frames 0:1 --turntable 360:4" + kSmall + "--out " + out;
  ASSERT_EQ(run("render -q " + scene + args).status, 0);
  const json j = sidecar(out + "/frame_0000.json");
  ASSERT_EQ(j["shading"]["lights"].size(), 256u);
  EXPECT_EQ(j["shading"]["lights_total"], 304);  // and the studio's four boxes (shadows on)
  EXPECT_LT(j["shading"]["lights"][0]["name"].get<std::string>().size(), 300u);
  EXPECT_EQ(run("verify " + out + " --frames 0:1").status, 0);
  EXPECT_NE(run("render " + scene + " --resume" + args).output.find("nothing to do"), std::string::npos);
}

// Beyond the lights a sidecar lists, their digest is compared: a change in the 300th light is a
// difference of configuration, as one in the first is.
TEST(Trust, TheLightsDigestComparesTheLightsNotListed) {
  SidecarInfo a;
  a.render.shading = Shading::Pbr;
  a.has_bounds = true;
  for (int i = 0; i < 300; ++i) {
    SceneLight l;
    l.type = SceneLightType::Point;
    l.name = "light " + std::to_string(i);
    a.lights.push_back(l);
  }
  SidecarInfo b = a;
  b.lights[299].intensity = 2.0f;
  const Rig rig = test::sidecar_rig();
  const std::string ta = sidecar_json(rig, Display(), a), tb = sidecar_json(rig, Display(), b);
  EXPECT_EQ(sidecar_config_difference(ta, ta), "");
  EXPECT_EQ(sidecar_config_difference(ta, tb), "shading");
  EXPECT_EQ(json::parse(ta)["shading"]["lights"].size(), 256u);
}

}  // namespace pmr
