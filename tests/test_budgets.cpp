// The budgets of docs/SECURITY.md beyond the files (vertex data, animation keys, JSON size, framing
// work, tile-queue entries, memory) and the buffers no accessor uses, each against the crafted input of
// issue 21 that once cost gigabytes or hours. Every input is generated here; where memory is the
// point the child runs under `prlimit --as` (RLIMIT_AS), so that a regression fails the test instead
// of eating the machine.
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "gltf_builder.h"
#include "pmr/input_files.h"
#include "pmr/memory_budget.h"
#include "test_util.h"

namespace pmr::test {
namespace {

constexpr uint64_t kGiB = uint64_t(1) << 30;

// `pmr ARGS` with its address space capped at `as_bytes` (RLIMIT_AS).
CliRun run_capped(uint64_t as_bytes, const std::string& args) {
  return run_wrapped("prlimit --as=" + std::to_string(as_bytes), args);
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// A GLB of `doc` (its buffers as given) and `bin` as the BIN chunk.
std::vector<uint8_t> glb_of(const json& doc, std::vector<uint8_t> bin) {
  std::string text = doc.dump();
  while (text.size() % 4) text += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::vector<uint8_t> out = {'g', 'l', 'T', 'F'};
  put_le32(out, 2);
  put_le32(out, uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  put_le32(out, uint32_t(text.size()));
  put_le32(out, 0x4E4F534Au);
  out.insert(out.end(), text.begin(), text.end());
  put_le32(out, uint32_t(bin.size()));
  put_le32(out, 0x004E4942u);
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

// One triangle in the file's buffer, drawn by node 0.
GltfFile one_triangle() {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  return g;
}

// A mesh whose POSITION is an accessor without a bufferView: `count` zero vertices from a few bytes.
GltfFile implicit_mesh(uint64_t count) {
  GltfFile g;
  const int pos = g.accessor(-1, kFloat, "VEC3", count);
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}));
  return g;
}

class Budgets : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    fs::remove_all(dir_);
    set_memory_budget(0);
  }
  std::string write(const GltfFile& g, const std::string& name) {
    std::ofstream(dir_ / name) << g.finished("").dump();
    return (dir_ / name).string();
  }
  // No frame of a render was written into `out`.
  void expect_no_frames(const fs::path& out) {
    if (!fs::exists(out)) return;
    for (const auto& e : fs::directory_iterator(out)) {
      const std::string ext = e.path().extension().string();
      EXPECT_TRUE(ext != ".exr" && ext != ".json" && ext != ".png") << "written: " << e.path();
    }
  }
  // A quick render of frame 0 into `out`, the scene's path to follow.
  static std::string render_into(const fs::path& out) {
    return "render --views 2 --view-size 32x16 --display 64x36 --frames 0 -q --out " + out.string() + " ";
  }
  fs::path dir_;
};

// ---- buffers no accessor uses -----------------------------------------------------------------------

// A 5 GiB buffer (a sparse file) that no accessor reads, beside the one that is drawn: never opened,
// in a .gltf and in a .glb (whose JSON chunk is rewritten for tinygltf). A bufferView that overruns
// it is still an error, against the length the file declares.
TEST_F(Budgets, BuffersNoAccessorUsesAreNotRead) {
  const uint64_t five_gib = 5 * kGiB;
  {
    std::ofstream(dir_ / "unused.bin", std::ios::binary).put('x');
    fs::resize_file(dir_ / "unused.bin", five_gib);
  }
  GltfFile g = one_triangle();
  g.doc["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 4096}, {"byteOffset", five_gib - 4096}});
  g.accessor(1, kFloat, "VEC3", 10);  // names the big buffer, but no mesh uses it
  json doc = g.finished("small.bin");
  doc["buffers"].push_back({{"uri", "unused.bin"}, {"byteLength", five_gib}});
  write_bytes(dir_ / "small.bin", g.bin);
  std::ofstream(dir_ / "scene.gltf") << doc.dump();
  json glb_doc = g.finished("");
  glb_doc["buffers"].push_back({{"uri", "unused.bin"}, {"byteLength", five_gib}});
  write_bytes(dir_ / "scene.glb", glb_of(glb_doc, g.bin));
  for (const char* name : {"scene.gltf", "scene.glb"}) {
    SCOPED_TRACE(name);
    const auto t0 = std::chrono::steady_clock::now();
    const CliRun r = run_capped(2 * kGiB, "info " + (dir_ / name).string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "triangles: 1,")) << r.output;
    EXPECT_LT(seconds_since(t0), 10.0);
    const Scene s = load_scene((dir_ / name).string(), InputLimits());
    for (const SceneInputFile& f : s.input_files) EXPECT_NE(f.path, "unused.bin");
  }
  doc["bufferViews"][1]["byteOffset"] = five_gib - 100;
  std::ofstream(dir_ / "overrun.gltf") << doc.dump();
  expect_one_error_line(
      run("info " + (dir_ / "overrun.gltf").string()),
      "bufferView 1 (byteOffset 5368709020, byteLength 4096) overruns buffer 1, which has 5368709120 bytes");
}

// ---- vertex data ----------------------------------------------------------------------------------------

// 1000 morph targets all naming one implicit POSITION accessor of 2^24 vertices: a 30 kB file that
// needed about 200 GB. Each target counts in full: refused by the vertex-data budget, from the counts.
TEST_F(Budgets, MorphTargetsOnOneImplicitAccessorAreCountedEach) {
  GltfFile g = implicit_mesh(uint64_t(1) << 24);
  json targets = json::array();
  for (int k = 0; k < 1000; ++k) targets.push_back({{"POSITION", 0}});
  g.doc["meshes"][0]["primitives"][0]["targets"] = targets;
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const std::string scene = write(g, "morph.gltf");
  EXPECT_LT(fs::file_size(scene), 40000u);
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun r = run_capped(kGiB, "info " + scene);
  expect_one_error_line(r,
                        "the scene's meshes decode to 201595027452 bytes of vertex data (every instance and morph "
                        "target counted), more than the vertex-data limit of 68719476736 (raise it with --limit "
                        "vertex-data=N)");
  EXPECT_LT(seconds_since(t0), 10.0);
  // The budget is the key: 2 morph targets of 2^24 vertices pass the default and not 400 MB.
  g.doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 0}}, {{"POSITION", 0}}});
  const std::string small = write(g, "two.gltf");
  expect_one_error_line(run("info " + small + " --limit vertex-data=400M"), "decode to 671088636 bytes of vertex data");
}

// An implicit 2^24-vertex mesh instanced by 23 nodes: 600 bytes, 128 M triangles (under the
// renderer's triangle cap), about 22 GB to flatten. Refused by the memory budget before allocating:
// here the address space of 2 GiB decides it, and says so.
TEST_F(Budgets, ImplicitVerticesInstancedByManyNodesAreRefusedByTheMemoryBudget) {
  GltfFile g = implicit_mesh(uint64_t(1) << 24);
  std::vector<int> roots;
  for (int n = 0; n < 23; ++n) roots.push_back(g.add("nodes", {{"mesh", 0}}));
  g.scene(roots);
  const std::string scene = write(g, "instances.gltf");
  EXPECT_LT(fs::file_size(scene), 1000u);
  const auto t0 = std::chrono::steady_clock::now();
  CliRun r = run_capped(2 * kGiB, "info " + scene);
  expect_one_error_line(r, "out of memory: loading the scene's 128625315 triangles needs ");
  EXPECT_TRUE(contains(r.output, "(RLIMIT_AS, less a margin) (raise it with --limit memory=N)")) << r.output;
  EXPECT_LT(seconds_since(t0), 10.0);
  // the budget given by --limit memory, the same refusal on any machine
  r = run("info " + scene + " --limit memory=1G");
  expect_one_error_line(r,
                        "but the memory budget of 1024 MiB (set by --limit memory) (raise it with --limit memory=N)");
}

// ---- animation keys -------------------------------------------------------------------------------------

// 200 samplers sharing one accessor of 2^18 key times (and one implicit output): 1 MB of data, 800 MB
// decoded, once per sampler. Refused by the animation-data budget.
TEST_F(Budgets, SamplersSharingOneAccessorAreCountedEach) {
  GltfFile g = one_triangle();
  const uint32_t keys = 1u << 18;
  std::vector<float> times(keys);
  for (uint32_t k = 0; k < keys; ++k) times[k] = float(k) / 1024.0f;
  const int input = g.data<float>(times, kFloat, "SCALAR");
  g.doc["accessors"][size_t(input)]["min"] = {0.0};
  g.doc["accessors"][size_t(input)]["max"] = {times.back()};
  const int output = g.accessor(-1, kFloat, "VEC3", keys);
  for (int a = 0; a < 200; ++a)
    g.add("animations",
          {{"samplers", json::array({{{"input", input}, {"output", output}}})},
           {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}})}});
  const std::string scene = g.write(dir_, "samplers");
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun r = run_capped(kGiB, "info " + scene);
  expect_one_error_line(r,
                        "the animations' samplers decode to 838860800 bytes of keys (every sampler counted), more "
                        "than the animation-data limit of 268435456 (raise it with --limit animation-data=N)");
  EXPECT_LT(seconds_since(t0), 10.0);
  EXPECT_EQ(run("info " + scene + " --limit animation-data=800M").status, 0);
}

// ---- JSON -----------------------------------------------------------------------------------------------

// A 40 MB `extras` array of zeros once took 3.85 GB to parse: refused by its size before parsing. A
// smaller one is parsed only when the memory budget holds what parsing it takes.
TEST_F(Budgets, JsonIsBoundedBySizeAndByWhatParsingItTakes) {
  auto extras = [&](size_t zeros, const std::string& name) {
    std::string text = R"({"asset":{"version":"2.0"},"extras":[)";
    text.reserve(2 * zeros + 64);
    for (size_t i = 0; i + 1 < zeros; ++i) text += "0,";
    text += "0]}";
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  };
  const std::string big = extras(20000000, "big.gltf");
  const auto t0 = std::chrono::steady_clock::now();
  expect_one_error_line(run_capped(kGiB, "info " + big),
                        "the JSON text has 40000038 bytes, more than the json-bytes limit of 33554432 (raise it with "
                        "--limit json-bytes=N)");
  EXPECT_LT(seconds_since(t0), 10.0);
  const std::string dense = extras(4000000, "dense.gltf");  // 8 MB, 4 M values: about 800 MB parsed
  expect_one_error_line(run("info " + dense + " --limit memory=256M"),
                        "out of memory: parsing the scene's JSON (4000007 values) needs ");
  const std::string glb = (dir_ / "chunk.glb").string();
  write_bytes(glb, one_triangle().glb());
  expect_one_error_line(run("info " + glb + " --limit json-bytes=64"), "the JSON chunk has ");
}

// The scene's files are in the memory budget before they are read: a 300 MB buffer the mesh reads (a
// sparse file) under --limit memory=256M is refused in one line; nothing of it is read.
TEST_F(Budgets, BufferFilesAreInTheMemoryBudgetBeforeTheyAreRead) {
  GltfFile g = one_triangle();
  const uint64_t big = uint64_t(300) << 20;
  write_bytes(dir_ / "big.bin", g.bin);
  fs::resize_file(dir_ / "big.bin", big);
  json d = g.finished("big.bin");
  d["buffers"][0]["byteLength"] = big;
  std::ofstream(dir_ / "big.gltf") << d.dump();
  const std::string scene = (dir_ / "big.gltf").string();
  expect_one_error_line(run("info " + scene + " --limit memory=256M"),
                        "out of memory: reading the scene's files (buffer 0: file 'big.bin': 314572800 bytes)");
  EXPECT_EQ(run("info " + scene + " --limit memory=1G").status, 0);
}

// Decoded textures count against the memory budget before each is decoded, with what the decoder holds
// meanwhile: four 16-bit 2048x2048 images (8 MB files, 32 MB decoded each) under --limit memory=96M
// are refused in one line naming the image, the same scene loads under the default budget.
TEST_F(Budgets, DecodedTexturesAreInTheMemoryBudget) {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
  const int uv = g.data<float>({0, 0, 1, 0, 0, 1}, kFloat, "VEC2");
  const std::vector<uint8_t> grey(size_t(2048) * 2048 * 2, 0x80);
  for (int k = 0; k < 4; ++k) {
    write_bytes(dir_ / ("t" + std::to_string(k) + ".png"), make_png(2048, 2048, 0, 16, grey));
    g.add("images", {{"uri", "t" + std::to_string(k) + ".png"}});
    g.add("textures", {{"source", k}});
  }
  g.add("materials",
        {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 1}}}}},
         {"occlusionTexture", {{"index", 2}}},
         {"emissiveTexture", {{"index", 3}}}});
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  write_bytes(dir_ / "textures.bin", g.bin);
  std::ofstream(dir_ / "textures.gltf") << g.finished("textures.bin").dump();
  const std::string scene = (dir_ / "textures.gltf").string();
  // Each takes 72 MiB while it decodes: 32 kept, 32 in the decoder's RGBA buffer it is copied from, 8
  // of inflated 16-bit grey rows. The first fits in 96 MiB, the second not in the 64 left.
  expect_one_error_line(run("info " + scene + " --limit memory=96M"),
                        "image 1 't1.png': 2048x2048 16-bit decodes to 32 MiB (72 MiB while decoding), more than the "
                        "memory budget leaves the scene's decoded images (64 MiB; raise it with --limit memory=N)");
  EXPECT_EQ(run("info " + scene).status, 0);
}

// ---- framing ----------------------------------------------------------------------------------------------

// The 994-byte hang: implicit vertices and a translation 41,666 s long. The framing would pose the
// scene at each of a million frames before the first one renders; refused at once, nothing written.
// (2^20 vertices here rather than 2^24: the load stays quick, the work is still 10^12 units.)
TEST_F(Budgets, FramingWorkIsBounded) {
  GltfFile g = implicit_mesh(uint64_t(1) << 20);
  const int input = g.data<float>({0.0f, 41666.0f}, kFloat, "SCALAR");
  g.doc["accessors"][size_t(input)]["min"] = {0.0};
  g.doc["accessors"][size_t(input)]["max"] = {41666.0};
  const int output = g.data<float>({0, 0, 0, 1, 0, 0}, kFloat, "VEC3");
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  g.add("animations",
        {{"samplers", json::array({{{"input", input}, {"output", output}}})},
         {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}})}});
  const std::string scene = g.write(dir_, "hang");
  const fs::path out = dir_ / "out";
  const auto t0 = std::chrono::steady_clock::now();
  expect_one_error_line(run(render_into(out) + scene),
                        "framing the animation poses the scene 999987 times (every frame of its keys at 24.000000 "
                        "fps), ");
  EXPECT_LT(seconds_since(t0), 20.0);
  expect_no_frames(out);
}

// The units at the edge. A triangle moving for 1 s at 24 fps is framed by 27 poses (frames 0..24, and
// the first and last key). One pose costs 42 units: its 3 vertices copied, 32 for its node, the 3
// animated values, its 3 vertices moved (no morph targets) and its triangle's normal.
TEST_F(Budgets, PoseAndFramingWorkAreCountedInUnits) {
  GltfFile t = one_triangle();
  const int in1 = t.data<float>({0.0f, 1.0f}, kFloat, "SCALAR");
  t.doc["accessors"][size_t(in1)]["min"] = {0.0};
  t.doc["accessors"][size_t(in1)]["max"] = {1.0};
  const int out1 = t.data<float>({0, 0, 0, 1, 0, 0}, kFloat, "VEC3");
  t.add("animations",
        {{"samplers", json::array({{{"input", in1}, {"output", out1}}})},
         {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}})}});
  const std::string moving = t.write(dir_, "moving");
  const fs::path out = dir_ / "out";
  expect_one_error_line(run(render_into(out) + moving + " --limit pose-work=41"),
                        "posing one frame of the scene takes 42 units (docs/SECURITY.md, \"Posing\"), more than the "
                        "pose-work limit of 41 (raise it with --limit pose-work=N)");
  expect_one_error_line(run(render_into(out) + moving + " --limit framing-work=1133"),
                        "poses the scene 27 times (every frame of its keys at 24.000000 fps), 42 units "
                        "(docs/SECURITY.md, \"Posing\") each, more than the framing-work limit of 1133");
  expect_no_frames(out);
  const CliRun ok = run(render_into(out) + moving + " --limit framing-work=1134,pose-work=42");
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(exists((out / "frame_0000.json").string()));
}

// Issue 31's three posing bombs, each refused within seconds by the default budgets, where each would
// have posed for hours: 2000 morph targets sharing one accessor on 10k vertices with keys over 200 s
// (a 40 KB file), a chain of 200k nodes whose root moves for 2000 s, and a skin of 60k chained joints
// moving for 2000 s.
TEST_F(Budgets, PosingBombsAreRefusedBeforePosing) {
  const int frames = 2000 * 24 + 1 + 2;  // frames 0..48000 and the first and last key
  const auto animated = [](GltfFile& g, int node, const char* path, float seconds, const std::vector<float>& values) {
    const int in = g.data<float>({0.0f, seconds}, kFloat, "SCALAR");
    g.doc["accessors"][size_t(in)]["min"] = {0.0};
    g.doc["accessors"][size_t(in)]["max"] = {double(seconds)};
    const int value = g.data<float>(values, kFloat, path == std::string("weights") ? "SCALAR" : "VEC3");
    g.add("animations", {{"samplers", json::array({{{"input", in}, {"output", value}}})},
                         {"channels", json::array({{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}})}});
  };
  GltfFile morph = implicit_mesh(10002);
  const int zero = morph.accessor(-1, kFloat, "VEC3", 10002);
  morph.doc["meshes"][0]["primitives"][0]["targets"] = json::array();
  for (int k = 0; k < 2000; ++k) morph.doc["meshes"][0]["primitives"][0]["targets"].push_back({{"POSITION", zero}});
  morph.add("nodes", {{"mesh", 0}});
  morph.scene({0});
  animated(morph, 0, "weights", 200.0f, std::vector<float>(4000, 0.5f));
  GltfFile chain = one_triangle();
  chain.doc["scenes"][0]["nodes"] = {1};
  for (int n = 1; n <= 200000; ++n)
    chain.add("nodes", n < 200000 ? json{{"children", {n + 1}}} : json{{"children", {0}}});
  animated(chain, 1, "translation", 2000.0f, {0, 0, 0, 1, 0, 0});
  GltfFile skin = one_triangle();
  skin.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
      skin.data<uint16_t>(std::vector<uint16_t>(12, 0), kUShort, "VEC4");
  skin.doc["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] =
      skin.data<float>({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, kFloat, "VEC4");
  skin.doc["nodes"][0]["skin"] = 0;
  json joints = json::array();
  for (int n = 1; n <= 60000; ++n) {
    skin.add("nodes", n < 60000 ? json{{"children", {n + 1}}} : json::object());
    joints.push_back(n);
  }
  skin.add("skins", {{"joints", joints}});
  skin.doc["scenes"][0]["nodes"] = {0, 1};
  animated(skin, 1, "translation", 2000.0f, {0, 0, 0, 1, 0, 0});
  const fs::path out = dir_ / "out";
  // Units of one pose, by hand: the chain's 3 vertices, 200001 nodes of 32, 3 animated values, 3
  // vertices moved and 1 triangle; the skin's 3 vertices, 60001 nodes of 32, 60000 joints of 8, 3
  // values, 3 vertices and 1 triangle.
  const std::pair<const GltfFile*, std::string> bombs[] = {
      {&morph, "poses the scene 4803 times"},
      {&chain, "poses the scene " + std::to_string(frames) + " times (every frame of its keys at 24.000000 fps), " +
                   std::to_string(3 + 32 * 200001 + 3 + 3 + 1) + " units"},
      {&skin, "poses the scene " + std::to_string(frames) + " times (every frame of its keys at 24.000000 fps), " +
                  std::to_string(3 + 32 * 60001 + 8 * 60000 + 3 + 3 + 1) + " units"}};
  for (const auto& [file, expected] : bombs) {
    const std::string scene = file->write(dir_, "bomb");
    const auto t0 = std::chrono::steady_clock::now();
    expect_one_error_line(run(render_into(out) + scene), expected);
    EXPECT_LT(seconds_since(t0), 20.0) << expected;
    expect_no_frames(out);
  }
}

// ---- tile queue -----------------------------------------------------------------------------------------

// 10^4 large overlapping triangles are a legal scene: rendered, each covering most tiles of every
// view. The tile-queue budget refuses a frame that would need more entries, naming the key.
TEST_F(Budgets, ManyLargeTrianglesRenderUnlessTheTileQueueBudgetSaysNo) {
  GltfFile g;
  std::vector<float> pos;
  for (int i = 0; i < 10000; ++i) {
    const float z = -0.0001f * float(i);
    pos.insert(pos.end(), {-1, -1, z, 1, -1, z, 0, 1, z});
  }
  const int p = g.data<float>(pos, kFloat, "VEC3");
  g.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"material", 0}}}));
  g.add("materials", {{"doubleSided", true}});
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const std::string scene = g.write(dir_, "overlap");
  const fs::path out = dir_ / "out";
  // (shadows off: the studio's 128 shadow maps would each rasterize the 10,000 full-screen triangles)
  const std::string render =
      "render --views 8 --view-size 64x32 --display 64x36 --frames 0 --shadows off -q --out " + out.string() + " ";
  const CliRun r = run("render --views 8 --view-size 64x32 --display 64x36 --frames 0 --shadows off -v --out " +
                       out.string() + " " + scene);
  ASSERT_EQ(r.status, 0) << r.output;
  // the entries the frame took, as --verbose reports them
  const size_t at = r.output.find(" tile-queue entries");
  ASSERT_NE(at, std::string::npos) << r.output;
  const size_t start = r.output.rfind(' ', at - 1) + 1;
  const uint64_t entries = std::stoull(r.output.substr(start, at - start));
  EXPECT_GT(entries, 10000u * 4u) << "each triangle covers many tiles";
  fs::remove_all(out);
  expect_one_error_line(run(render + scene + " --limit tile-queue=" + std::to_string(entries - 1)),
                        "the frame's tile raster produces " + std::to_string(entries) +
                            " tile-queue entries, more "
                            "than the tile-queue limit of " +
                            std::to_string(entries - 1) + " (raise it with --limit tile-queue=N)");
  expect_no_frames(out);
  EXPECT_FALSE(fs::exists(out)) << "the refused run left the folder it created";
}

// A frame still rendering after `slow_frame_seconds` reports how long it has run and its tile-queue
// entries, again each interval (pmr render prints it); a frame done sooner reports nothing.
TEST(SlowFrame, ReportsWhileTheFrameRenders) {
  const Scene scene = random_scene(3000, 7, true);
  const Rig rig = small_rig(16, 128, 64);
  for (const double interval : {1e-5, 1000.0}) {
    PipelineConfig pc;
    std::vector<std::pair<double, uint64_t>> calls;
    pc.slow_frame = [&](double s, uint64_t entries) { calls.push_back({s, entries}); };
    pc.slow_frame_seconds = interval;
    Pipeline p(runtime(), pc);
    p.set_scene(scene);
    p.configure(rig, nullptr);
    const StageTimes t = p.render(rig);
    ASSERT_GT(t.bin_entries, 0u);
    if (interval > 1.0) {
      EXPECT_TRUE(calls.empty()) << "a fast frame is not reported";
      continue;
    }
    ASSERT_FALSE(calls.empty());
    EXPECT_EQ(calls[0].second, t.bin_entries);
    EXPECT_GE(calls[0].first, interval);
    EXPECT_LE(calls.back().first, t.wall / 1000.0);
  }
}

// ---- memory ---------------------------------------------------------------------------------------------

// --views 1400 --write views: a 5.9 GB view volume, which PoCL once allocated lazily and then
// aborted on. Checked against the memory budget before anything is created or allocated.
TEST_F(Budgets, ViewVolumeBeyondTheMemoryBudgetIsRefusedBeforeAllocating) {
  const fs::path out = dir_ / "out";
  const std::string scene = std::string(PMR_SOURCE_DIR) + "/data/default_scene.glb";
  CliRun r = run_capped(3 * kGiB, "render " + scene + " --views 1400 --write views --out " + out.string());
  expect_one_error_line(r,
                        "out of memory: 1400 views of 1024x512 (5600 MiB a view volume, on the device and in up to "
                        "four copies being written) needs ");
  EXPECT_TRUE(contains(r.output, "(RLIMIT_AS, less a margin)")) << r.output;
  expect_no_frames(out);
  r = run("render " + scene + " --views 1400 --write views --limit memory=4G --out " + out.string());
  expect_one_error_line(r, "but the memory budget of 4096 MiB (set by --limit memory)");
  expect_no_frames(out);
}

// Device buffers are checked as they are allocated, counting those alive.
TEST_F(Budgets, DeviceBuffersAreCheckedAgainstTheMemoryBudget) {
  set_memory_budget(uint64_t(1) << 20);
  try {
    runtime().buffer(uint64_t(2) << 20, "test buffer");
    ADD_FAILURE() << "allocated beyond the budget";
  } catch (const Error& e) {
    EXPECT_TRUE(contains(e.what(),
                         "out of memory: test buffer needs 2 MiB, but the memory budget of 1 MiB (set by "
                         "--limit memory)"))
        << e.what();
  }
  set_memory_budget(uint64_t(64) << 20);
  const uint64_t before = device_bytes_in_use();
  {
    const ClBuffer b = runtime().buffer(uint64_t(2) << 20, "test buffer");
    EXPECT_EQ(device_bytes_in_use(), before + (uint64_t(2) << 20));
  }
  EXPECT_EQ(device_bytes_in_use(), before);
}

// The automatic budget: the smallest of what the machine, the cgroup and the address space leave, less
// an eighth and 64 MiB.
TEST(MemoryBudget, AutomaticBudgetIsTheSmallestLimitLessAMargin) {
  MemoryFacts f;
  f.mem_available = 16 * kGiB;
  std::string source;
  EXPECT_EQ(automatic_memory_budget(f, &source), 14 * kGiB - (uint64_t(64) << 20));
  EXPECT_EQ(source, "MemAvailable, less a margin");
  f.cgroup_left = 8 * kGiB;
  EXPECT_EQ(automatic_memory_budget(f, &source), 7 * kGiB - (uint64_t(64) << 20));
  EXPECT_EQ(source, "the cgroup's memory.max, less a margin");
  f.address_left = 2 * kGiB;
  EXPECT_EQ(automatic_memory_budget(f, &source), (uint64_t(7) << 28) - (uint64_t(64) << 20));
  EXPECT_EQ(source, "RLIMIT_AS, less a margin");
  // read from this process: MemAvailable at least
  EXPECT_GT(read_memory_facts().mem_available, 0u);
}

// --help lists every key with its default; every key is accepted by --limit.
TEST(BudgetKeys, HelpListsEveryKey) {
  const CliRun r = run("render --help");
  for (const char* key : {"file-bytes:", "texture-pixels:", "vertex-data:", "animation-data:", "json-bytes:",
                          "pose-work:", "framing-work:", "tile-queue:", "memory:"})
    EXPECT_TRUE(contains(r.output, key)) << key << " in " << r.output;
  InputLimits l;
  parse_limits("vertex-data=1G,animation-data=2M,json-bytes=3K,framing-work=4,tile-queue=5,memory=6G,pose-work=7", l);
  EXPECT_EQ(l.vertex_data, kGiB);
  EXPECT_EQ(l.animation_data, uint64_t(2) << 20);
  EXPECT_EQ(l.json_bytes, 3072u);
  EXPECT_EQ(l.framing_work, 4u);
  EXPECT_EQ(l.pose_work, 7u);
  EXPECT_EQ(l.tile_queue, 5u);
  EXPECT_EQ(l.memory, 6 * kGiB);
}

}  // namespace
}  // namespace pmr::test
