// KHR_materials_variants: --variant draws a primitive with the material its mapping names for that
// variant (the default material where none does); pmr info lists the variants, the sidecar records the
// choice and --resume compares it; a malformed extension is one error line.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "gltf_builder.h"
#include "pmr/error.h"
#include "pmr/input_files.h"
#include "pmr/scene.h"
#include "test_util.h"

namespace pmr {
namespace {

using nlohmann::json;
using test::CliRun;
using test::expect_one_error_line;
using test::run;
using test::temp_dir;

// Two quads, each its own primitive, with the default materials red (0) and white (1); the
// variants 'Green' and 'Blue': quad 0 maps Green -> green (2) and Blue -> blue (3), quad 1 maps Blue
// -> green (2) only. `edit` may break the document.
std::string variants_file(const std::string& dir, const std::function<void(json&)>& edit = {}) {
  test::GltfFile g;
  const int p0 = g.data<float>({-1, -1, 0, 0, -1, 0, 0, 1, 0, -1, 1, 0}, test::kFloat, "VEC3");
  const int p1 = g.data<float>({0, -1, 0, 1, -1, 0, 1, 1, 0, 0, 1, 0}, test::kFloat, "VEC3");
  const int i = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, test::kUShort, "SCALAR");
  for (const auto& c : {std::array{1, 0, 0}, {1, 1, 1}, {0, 1, 0}, {0, 0, 1}})
    g.add("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {c[0], c[1], c[2], 1}}}}});
  auto mapping = [](int material, std::vector<int> variants) {
    return json{{"material", material}, {"variants", variants}};
  };
  g.mesh(
      json::array({{{"attributes", {{"POSITION", p0}}},
                    {"indices", i},
                    {"material", 0},
                    {"extensions", {{"KHR_materials_variants", {{"mappings", {mapping(2, {0}), mapping(3, {1})}}}}}}},
                   {{"attributes", {{"POSITION", p1}}},
                    {"indices", i},
                    {"material", 1},
                    {"extensions", {{"KHR_materials_variants", {{"mappings", {mapping(2, {1})}}}}}}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  g.doc["extensionsUsed"] = {"KHR_materials_variants"};
  g.doc["extensions"]["KHR_materials_variants"]["variants"] = {{{"name", "Green"}}, {{"name", "Blue"}}};
  if (edit) edit(g.doc);
  return g.write(dir, "variants");
}

// The base colour each quad is drawn with (its two triangles agree).
std::vector<std::array<float, 3>> quad_colours(const Scene& s) {
  std::vector<std::array<float, 3>> out;
  for (size_t t = 0; t < s.triangles.size(); t += 2) {
    const PmrMaterial& m = s.materials[s.triangles[t].material];
    out.push_back({m.base_color[0], m.base_color[1], m.base_color[2]});
  }
  return out;
}

using Colours = std::vector<std::array<float, 3>>;
const std::array<float, 3> kRed{1, 0, 0}, kWhite{1, 1, 1}, kGreen{0, 1, 0}, kBlue{0, 0, 1};

TEST(Variants, EachPrimitiveTakesTheMaterialItsMappingNames) {
  const std::string dir = temp_dir("variants_load");
  std::filesystem::create_directories(dir);
  const std::string file = variants_file(dir);
  const Scene none = load_scene(file);
  EXPECT_EQ(none.variants, (std::vector<std::string>{"Green", "Blue"}));
  EXPECT_EQ(none.variant, -1);
  EXPECT_EQ(quad_colours(none), (Colours{kRed, kWhite}));
  for (const char* green : {"Green", "#0"}) {
    const Scene s = load_scene(file, InputLimits(), green);
    EXPECT_EQ(s.variant, 0);
    EXPECT_EQ(quad_colours(s), (Colours{kGreen, kWhite})) << "quad 1 does not map Green: its default material";
  }
  const Scene blue = load_scene(file, InputLimits(), "Blue");
  EXPECT_EQ(quad_colours(blue), (Colours{kBlue, kGreen}));
  for (const std::string& w : none.warnings) EXPECT_EQ(w.find("KHR_materials_variants"), std::string::npos) << w;
}

// Names come first: variants named "1" and "0" are chosen by those names, and "#K" is the index.
TEST(Variants, NumbersAreNamesAndHashKIsTheIndex) {
  const std::string dir = temp_dir("variants_numbers");
  std::filesystem::create_directories(dir);
  const std::string file = variants_file(
      dir, [](json& d) { d["extensions"]["KHR_materials_variants"]["variants"] = {{{"name", "1"}}, {{"name", "0"}}}; });
  EXPECT_EQ(load_scene(file, InputLimits(), "1").variant, 0);
  EXPECT_EQ(load_scene(file, InputLimits(), "0").variant, 1);
  EXPECT_EQ(load_scene(file, InputLimits(), "#1").variant, 1);
  EXPECT_EQ(quad_colours(load_scene(file, InputLimits(), "1")), (Colours{kGreen, kWhite}));
}

TEST(Variants, BadChoicesAndMalformedMappingsAreOneLine) {
  const std::string dir = temp_dir("variants_bad");
  std::filesystem::create_directories(dir);
  const std::string file = variants_file(dir);
  auto error = [&](const std::string& path, const std::string& variant) {
    try {
      load_scene(path, InputLimits(), variant);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  EXPECT_NE(error(file, "Red").find("--variant 'Red': no variant has that name"), std::string::npos);
  EXPECT_NE(error(file, "#2").find("has 2 variant(s)"), std::string::npos) << error(file, "#2");
  EXPECT_NE(error(file, "2").find("an index is written #2"), std::string::npos) << error(file, "2");
  const std::vector<std::pair<std::function<void(json&)>, std::string>> broken = {
      {[](json& d) { d["extensions"]["KHR_materials_variants"]["variants"] = 3; }, "variants is not an array"},
      {[](json& d) { d["extensions"]["KHR_materials_variants"]["variants"][1].erase("name"); },
       "variant 1 has no name"},
      {[](json& d) {
         d["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][0]["material"] = 4;
       },
       "mesh 0 primitive 0 KHR_materials_variants mapping 0 does not name a material"},
      {[](json& d) {
         d["meshes"][0]["primitives"][1]["extensions"]["KHR_materials_variants"]["mappings"][0]["variants"] = {7};
       },
       "names a variant the file does not have"},
      {[](json& d) {
         d["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][1]["variants"] = {0};
       },
       "maps variant 0 a second time"},
      {[](json& d) { d["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"] = "x"; },
       "mappings is not an array"},
  };
  for (size_t k = 0; k < broken.size(); ++k) {
    const std::string sub = dir + "/b" + std::to_string(k);
    std::filesystem::create_directories(sub);
    const std::string e = error(variants_file(sub, broken[k].first), "");
    EXPECT_NE(e.find(broken[k].second), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

// From the command line: pmr info lists the variants, the sidecar records the one drawn, --resume
// compares it, and a wrong name is one line with nothing written.
TEST(Variants, FromTheCommandLine) {
  const std::string dir = temp_dir("variants_cli");
  std::filesystem::create_directories(dir);
  const std::string file = variants_file(dir);
  const std::string info = run("info " + file).output;
  EXPECT_NE(info.find("material variants: 2"), std::string::npos) << info;
  EXPECT_NE(info.find("  1 'Blue'"), std::string::npos) << info;
  const std::string small = " --views 4 --view-size 32x16 --display 96x54 --shading lambert ";
  CliRun r = run("render " + file + small + "--variant Blue --out " + dir + "/blue");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(json::parse(test::read_file(dir + "/blue/frame_0000.json"))["variant"], "Blue");
  expect_one_error_line(run("render " + file + small + "--variant Green --resume --out " + dir + "/blue"),
                        "different configuration (variant");
  expect_one_error_line(run("render " + file + small + "--resume --out " + dir + "/blue"),
                        "different configuration (variant");
  r = run("render " + file + small + "--out " + dir + "/none");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(json::parse(test::read_file(dir + "/none/frame_0000.json")).contains("variant"));
  expect_one_error_line(run("render " + file + small + "--variant Red --out " + dir + "/red"), "--variant 'Red'");
  EXPECT_FALSE(test::exists(dir + "/red"));
}

// The Khronos sample shoe: every variant loads without a warning, and each draws other materials.
TEST(Variants, TheSampleShoeInEveryColourway) {
  const std::string corpus = test::corpus_dir();
  if (corpus.empty()) GTEST_SKIP() << "../shared/gltf not found: the sample shoe is skipped";
  const std::string file = corpus + "/MaterialsVariantsShoe/glTF/MaterialsVariantsShoe.gltf";
  if (!test::exists(file)) GTEST_SKIP() << file << " not found";
  const Scene base = load_scene(file);
  ASSERT_EQ(base.variants.size(), 3u);
  std::set<std::vector<uint32_t>> drawn;
  for (size_t v = 0; v < base.variants.size(); ++v) {
    const Scene s = load_scene(file, InputLimits(), base.variants[v]);
    EXPECT_TRUE(s.warnings.empty()) << base.variants[v] << ": " << s.warnings.front();
    std::vector<uint32_t> materials;
    for (const PmrTriangle& t : s.triangles) materials.push_back(t.material);
    drawn.insert(materials);
  }
  EXPECT_EQ(drawn.size(), 3u) << "each variant draws its own materials";
}

}  // namespace
}  // namespace pmr
