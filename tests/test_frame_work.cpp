// The frame-work budget (--limit frame-work, docs/SECURITY.md): the estimate's parts against counts
// worked out here from the rig (light evaluations exactly, BLEND fragments as the tiles a triangle's
// bounding box covers), and the command line refusing a frame of thousands of lights in one line
// before rendering anything.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "gltf_builder.h"
#include "pipeline/pipeline_config.h"
#include "pmr/error.h"
#include "sequence/frame_work.h"
#include "test_util.h"

namespace pmr {
namespace {

// A BLEND scene with one triangle whose corners sit on the focal plane (the same raster position in
// every view) at the given raster positions.
Scene focal_triangle(const Rig& rig, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  Scene s = test::empty_scene(true);
  s.materials[0].alpha_mode = PMR_ALPHA_BLEND;
  test::add_triangle(s, test::focal_point(rig, a.x, a.y), test::focal_point(rig, b.x, b.y),
                     test::focal_point(rig, c.x, c.y));
  return s;
}

TEST(FrameWork, LightEvaluationsAreEveryViewPixelTimesTheLights) {
  const Rig rig = test::small_rig(8, 64, 32);
  Scene s = test::empty_scene();
  test::add_triangle(s, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});  // opaque: no BLEND fragments
  PipelineConfig config;
  config.samples = 16;
  const FrameWork w = estimate_frame_work(s, rig, 7, config);
  EXPECT_EQ(w.pixels, 8u * 64u * 32u);
  EXPECT_EQ(w.blend_fragments, 0u);
  EXPECT_EQ(w.light_evaluations, 8u * 64u * 32u * 7u) << "once per pixel, whatever the samples";
  EXPECT_EQ(w.units, w.light_evaluations * kUnitsPerLightEvaluation);
}

TEST(FrameWork, BlendFragmentsAreTheTilesOfTheBoundingBoxInEveryView) {
  const Rig rig = test::small_rig(8, 64, 32);
  PipelineConfig config;  // tiles of 16 x 2 pixels
  config.samples = 4;
  // x from 3.3 to 20.5: tile columns 0 and 1 (32 pixels); y from 5.2 to 6.6: tile rows 2 and 3 (4 rows)
  const Scene part = focal_triangle(rig, {3.3, 5.2}, {20.5, 5.2}, {10.0, 6.6});
  const FrameWork w = estimate_frame_work(part, rig, 1, config);
  EXPECT_EQ(w.blend_fragments, 32u * 4u * 8u);
  EXPECT_EQ(w.light_evaluations, w.pixels + w.blend_fragments);
  EXPECT_EQ(w.units, w.light_evaluations * kUnitsPerLightEvaluation +
                         w.blend_fragments * (kUnitsPerBlendFragment + 4 * kUnitsPerBlendSample));
  // beyond the raster on every side: the whole raster, once per view
  const Scene all = focal_triangle(rig, {-50, -50}, {300, -50}, {-50, 300});
  EXPECT_EQ(estimate_frame_work(all, rig, 0, config).blend_fragments, 64u * 32u * 8u);
  // right of the raster in every view: nothing
  const Scene off = focal_triangle(rig, {100, 5}, {120, 5}, {110, 9});
  EXPECT_EQ(estimate_frame_work(off, rig, 0, config).blend_fragments, 0u);
  // a corner behind the camera may reach anywhere once clipped: the whole raster
  Scene behind = focal_triangle(rig, {3.3, 5.2}, {20.5, 5.2}, {10.0, 6.6});
  behind.positions[2] = glm::vec3(glm::inverse(rig.center_view) * glm::dvec4(0, 0, 1, 1));
  EXPECT_EQ(estimate_frame_work(behind, rig, 0, config).blend_fragments, 64u * 32u * 8u);
}

// 500 stacked BLEND layers filling every view of paper-8k (a frame of about 7 minutes at 4 samples,
// issue 48) stay within the default budget; at 16 samples (over 14 minutes) they do not.
TEST(FrameWork, TheDefaultBudgetKeepsAboutTenMinutes) {
  RigConfig rc;
  const Rig rig = make_rig(rc, Display(), glm::dvec3(-1), glm::dvec3(1));
  const uint64_t layer = uint64_t(rig.views) * uint64_t(rig.view_w) * uint64_t(rig.view_h);
  const Scene one = focal_triangle(rig, {-5000, -5000}, {30000, -5000}, {-5000, 30000});  // covers the raster
  Scene s = one;
  for (int q = 1; q < 500; ++q) test::add_triangle(s, one.positions[0], one.positions[1], one.positions[2]);
  PipelineConfig config;
  config.samples = 4;
  const FrameWork four = estimate_frame_work(s, rig, 0, config);  // the studio's default: no light
  EXPECT_EQ(four.blend_fragments, 500 * layer);
  EXPECT_LE(four.units, InputLimits().frame_work);
  config.samples = 16;
  EXPECT_GT(estimate_frame_work(s, rig, 0, config).units, InputLimits().frame_work);
  // 1000 point lights over every pixel (about 3 minutes) stay within it; 100,000 do not
  Scene opaque = test::empty_scene();
  test::add_triangle(opaque, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
  EXPECT_LE(estimate_frame_work(opaque, rig, 1000, config).units, InputLimits().frame_work);
  EXPECT_GT(estimate_frame_work(opaque, rig, 100000, config).units, InputLimits().frame_work);
}

// 5000 point lights at paper-8k: refused before anything renders, in one line naming the key; a
// small raster of the same file renders.
TEST(FrameWork, ACommandLineRenderIsRefusedBeforeItStarts) {
  using namespace test::gltf_builder_detail;
  const std::string dir = test::temp_dir("frame_work");
  std::filesystem::create_directories(dir);
  GltfFile g;
  const int p = g.data<float>({-1, -1, 0, 1, -1, 0, 0, 1, 0}, kFloat, "VEC3");
  g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", p}}}}}));
  std::vector<int> roots = {g.add("nodes", {{"mesh", 0}})};
  nlohmann::json lights = nlohmann::json::array();
  for (int i = 0; i < 5000; ++i) {
    lights.push_back({{"type", "point"}, {"intensity", 1.0}});
    roots.push_back(
        g.add("nodes", {{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}}));
  }
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  g.scene(roots);
  const std::string file = g.write(dir, "lights");
  // (shadows off: the studio's boxes would add their light evaluations to the file's 5000)
  const test::CliRun r = test::run("render " + file + " --shadows off --out " + dir + "/out");
  test::expect_one_error_line(r, "more than the frame-work limit");
  EXPECT_NE(r.output.find("x 5000 light evaluation(s) a point)"), std::string::npos) << r.output;
  EXPECT_FALSE(test::exists(dir + "/out/frame_0000.exr"));
  const test::CliRun small =
      test::run("render " + file + " -q --views 2 --view-size 32x16 --display 64x36 --out " + dir + "/small");
  EXPECT_EQ(small.status, 0) << small.output;
  const test::CliRun info = test::run("info " + file);
  EXPECT_NE(info.output.find("frame work at paper-8k: "), std::string::npos) << info.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pmr

namespace pmr {
namespace {

// Shadows count (DESIGN section 4d): every shaded point reads one map per sample of each shadowed
// light, and each map is a pass over every triangle.
TEST(FrameWork, ShadowsCountTheirMapReadsAndPasses) {
  SceneLight sun, bulb, soft_sun;
  bulb.type = SceneLightType::Point;
  soft_sun.angle = 0.05f;
  const ShadowSizes sizes;
  const ShadowCost hard = shadow_cost({sun, bulb}, 0, sizes), soft = shadow_cost({soft_sun}, 0, sizes);
  EXPECT_EQ(hard.maps, 1u + 6u);
  EXPECT_EQ(hard.lookups_per_point, 2u);
  EXPECT_EQ(hard.texels, 2048u * 2048u + 6u * 1024u * 1024u);
  // the environment's occlusion: one map of 256 x 256 and one read per direction
  const ShadowCost occluded = shadow_cost({sun, bulb}, 32, sizes);
  EXPECT_EQ(occluded.maps, hard.maps + 32u);
  EXPECT_EQ(occluded.lookups_per_point, hard.lookups_per_point + 32u);
  EXPECT_EQ(occluded.texels, hard.texels + 32u * 256u * 256u);
  EXPECT_EQ(soft.maps, uint64_t(kShadowSamples));
  EXPECT_EQ(soft.lookups_per_point, uint64_t(kShadowSamples));
  Scene s = test::empty_scene(false);
  test::add_triangle(s, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
  const Rig rig = test::small_rig(4, 32, 16);
  PipelineConfig config;
  const FrameWork none = estimate_frame_work(s, rig, 1, config), with = estimate_frame_work(s, rig, 1, config, soft);
  EXPECT_EQ(with.shadow_reads, 4u * 32u * 16u * uint64_t(kShadowSamples));
  EXPECT_EQ(with.shadow_map_triangles, uint64_t(kShadowSamples));
  EXPECT_EQ(with.units - none.units, with.shadow_reads * kUnitsPerShadowRead +
                                         with.shadow_map_triangles * kUnitsPerShadowTriangle + soft.texels);
}

// The ground catcher (--ground shadow) is one more BLEND layer under every view pixel, shaded with the
// lights and read through the shadow maps like any fragment.
TEST(FrameWork, TheGroundCatcherIsABlendLayerOverEveryPixel) {
  Scene s = test::empty_scene(false);
  test::add_triangle(s, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
  const Rig rig = test::small_rig(4, 32, 16);
  PipelineConfig config;
  const ShadowCost shadows = shadow_cost({SceneLight()}, 64, ShadowSizes());
  const FrameWork without = estimate_frame_work(s, rig, 2, config, shadows);
  config.ground_shadow = true;
  const FrameWork with = estimate_frame_work(s, rig, 2, config, shadows);
  EXPECT_EQ(with.blend_fragments - without.blend_fragments, 4u * 32u * 16u);
  EXPECT_EQ(with.light_evaluations - without.light_evaluations, 2u * 4u * 32u * 16u);
  EXPECT_EQ(with.shadow_reads - without.shadow_reads, 65u * 4u * 32u * 16u);
  EXPECT_GT(with.units, without.units);
}

// An area light weighs as the point-like lights its shading costs, and its shadow is sampled like any
// light with a size.
TEST(FrameWork, AreaLightsWeighTheirShading) {
  SceneLight sun, rect, disk;
  rect.type = SceneLightType::Rect, disk.type = SceneLightType::Disk;
  EXPECT_EQ(light_evaluations_per_point({sun, rect, disk}), 1u + kRectLightEvaluations + kDiskLightEvaluations);
  EXPECT_EQ(shadow_cost({rect}, 0, ShadowSizes()).lookups_per_point, uint64_t(kShadowSamples));
  EXPECT_EQ(shadow_cost({rect}, 0, ShadowSizes()).maps, 6u * uint64_t(kShadowSamples));
}

}  // namespace
}  // namespace pmr
