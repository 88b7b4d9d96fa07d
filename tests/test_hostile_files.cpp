// Small crafted files that once crashed pmr or made it allocate without a budget (issue 48): texture
// coordinate set numbers far beyond what any primitive holds, on used and unused materials, directly
// and through KHR_texture_transform.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "gltf_builder.h"
#include "pmr/error.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pmr::test::gltf_builder_detail;

class HostileFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir("hostile_files");
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

// One textured quad drawn with material 0; material 1 is unused. `textures` holds each material's
// base colour textureInfo. The quad carries TEXCOORD_0 and, when `extra_set` >= 0, TEXCOORD_<extra_set>.
std::string quad_file(const std::string& dir, const std::string& name, const json& used, const json& unused,
                      int extra_set = -1) {
  GltfFile g;
  const int pos = g.data<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, kFloat, "VEC3");
  const int uv = g.data<float>({0, 0, 1, 0, 1, 1, 0, 1}, kFloat, "VEC2");
  const int idx = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, kUShort, "SCALAR");
  const std::vector<uint8_t> texel = {255, 0, 0, 255};
  g.add("images", {{"uri", png_uri(make_png(1, 1, 6, 8, texel))}});
  g.add("textures", {{"source", 0}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", used}}}});
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", unused}}}});
  json attributes = {{"POSITION", pos}, {"TEXCOORD_0", uv}};
  if (extra_set >= 0) attributes["TEXCOORD_" + std::to_string(extra_set)] = uv;
  g.mesh(json::array({{{"attributes", attributes}, {"indices", idx}, {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  const std::string path = dir + "/" + name + ".glb";
  write_bytes(path, g.glb());
  return path;
}

// texCoord 2^31 - 1 on the drawn material: the loader once computed set + 1 in int (overflow) and
// indexed past its array. Now it is a set the primitive lacks: one line naming it.
TEST_F(HostileFiles, LargestTexCoordOnADrawnMaterialIsOneRefusal) {
  const json transform = {{"KHR_texture_transform", {{"texCoord", 2147483647}}}};
  for (const json& info : {json{{"index", 0}, {"texCoord", 2147483647}}, json{{"index", 0}, {"extensions", transform}}}) {
    const std::string path = quad_file(dir_, "max", info, {{"index", 0}});
    const std::string why = load_error(path);
    EXPECT_TRUE(contains(why, "samples TEXCOORD_2147483647")) << why;
    EXPECT_TRUE(contains(why, "does not have")) << why;
    const test::CliRun r = test::run("info " + path);
    test::expect_one_error_line(r, "TEXCOORD_2147483647");
  }
}

// An unused material naming set 100,000,000 costs nothing: the scene holds the one set the drawn
// material samples, and the run fits a small memory budget (it once asked for 8 GB).
TEST_F(HostileFiles, AnUnusedMaterialsTexCoordCostsNothing) {
  const std::string path = quad_file(dir_, "unused", {{"index", 0}}, {{"index", 0}, {"texCoord", 100000000}});
  const Scene s = load_scene(path);
  ASSERT_EQ(s.texcoords.size(), 1u);
  EXPECT_EQ(s.texcoords[0].size(), s.positions.size());
  EXPECT_EQ(s.material_inputs[2].slots[kSlotBaseColor].texcoord_set, 100000000);
  EXPECT_EQ(s.material_inputs[2].slots[kSlotBaseColor].texcoord, -1) << "no drawn primitive samples it";
  const test::CliRun r = test::run("info " + path + " --limit memory=256M");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "set 100000000")) << r.output;
}

// A drawn material sampling a high set that the primitive has: the scene holds that set alone, at
// index 0, and it renders (the kernels read the scene's index, not the file's set number).
TEST_F(HostileFiles, AHighSetThePrimitiveHasIsStoredOnce) {
  const std::string path = quad_file(dir_, "high", {{"index", 0}, {"texCoord", 40000}}, {{"index", 0}}, 40000);
  const Scene s = load_scene(path);
  ASSERT_EQ(s.texcoords.size(), 1u);
  EXPECT_EQ(s.texcoords[0][2], glm::vec2(1, 1));
  EXPECT_EQ(s.material_inputs[1].slots[kSlotBaseColor].texcoord_set, 40000);
  EXPECT_EQ(s.material_inputs[1].slots[kSlotBaseColor].texcoord, 0);
  const test::CliRun r = test::run("render " + path + " -q --views 2 --view-size 32x16 --display 120x68 --out " +
                                   dir_ + "/out");
  EXPECT_EQ(r.status, 0) << r.output;
}

// pmr bench --save-scene writes only regular files: a FIFO, a symbolic link or a folder at the path is
// refused and left as it was (a rename replaced them, and /dev/full as root); a write error of --csv is
// an error (a full device once exited 0).
TEST_F(HostileFiles, BenchWritesOnlyRegularFilesAndReportsWriteErrors) {
  const std::string fifo = dir_ + "/fifo.glb", link = dir_ + "/link.glb", target = dir_ + "/target";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  { std::ofstream(target) << "keep"; }
  fs::create_symlink(target, link);
  fs::create_directories(dir_ + "/folder.glb");
  for (const std::string& path : {fifo, link, dir_ + "/folder.glb"}) {
    const test::CliRun r = test::run("bench --synthetic 100 --save-scene " + path);
    test::expect_one_error_line(r, "not a regular file");
  }
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(test::read_file(target), "keep");
  EXPECT_TRUE(fs::is_directory(dir_ + "/folder.glb"));
  EXPECT_EQ(test::run("bench --synthetic 100 --save-scene " + dir_ + "/scene.glb").status, 0);
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  const test::CliRun full = test::run("bench --synthetic 100 --views 2 --view-size 32x16 --display 64x36 --method pmr "
                                      "--frames 1 --no-check --csv /dev/full");
  EXPECT_EQ(full.status, 1) << full.output;
  EXPECT_NE(full.output.find("cannot write /dev/full"), std::string::npos) << full.output;
}

// --name refuses what verify would refuse to read back (control characters, a backslash) before
// anything is written: exit 2, no folder.
TEST_F(HostileFiles, NamesWithControlsAreRefusedUpFront) {
  for (const char* printf_name : {"a\\nb_%%04d", "a\\tb_%%04d", "a\\\\b_%%04d", "\\033[31m_%%04d"}) {
    const test::CliRun r = test::run(std::string("render --name \"$(printf '") + printf_name +
                                     "')\" --views 2 --view-size 32x16 --display 64x36 --out " + dir_ + "/out");
    test::expect_usage_error(r, "invalid --name");
    EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir_ + "/out")) << printf_name;
  }
}

}  // namespace
}  // namespace pmr
