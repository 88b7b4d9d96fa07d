// The lights of --shading pbr in the sidecar (host/output/sidecar.cpp): the shading key records the
// resolved lights of each frame (world space, as used), and --resume (sidecar_config_difference)
// compares them; pmr render and its sequence tools on a file whose light is animated. The kernels'
// lighting itself is tested against the reference in tests/test_pbr.cpp (PbrLights.*).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "environment_maps.h"
#include "gltf_builder.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "shading/lights.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::CliRun;
using test::run;

const std::string kSmall = " --views 4 --view-size 64x32 --display 240x135 ";  // not -q: tests read the summary

SceneLight file_light(SceneLightType type, int index, const glm::dvec3& position) {
  SceneLight l;
  l.name = "light " + std::to_string(index);
  l.light = index, l.node = index + 1;
  l.type = type;
  l.position = position;
  l.direction = glm::normalize(glm::dvec3(0.2, -1.0, -0.3));
  l.intensity = 5.0f;
  l.range = type == SceneLightType::Directional ? 0.0f : 4.0f;
  l.inner_cone = 0.1f, l.outer_cone = 0.6f;
  return l;
}

std::string pbr_sidecar(const Rig& rig, int frame, const std::vector<SceneLight>& lights) {
  SidecarInfo info;
  info.scene = "scene.gltf";
  info.render.shading = Shading::Pbr;
  info.frame = frame;
  info.has_bounds = true;
  info.lights = lights;
  return sidecar_json(rig, Display{}, info);
}

TEST(PbrLightsSidecar, RecordsEachLightAsUsed) {
  const Rig rig = test::sidecar_rig();
  const std::vector<SceneLight> lights = {file_light(SceneLightType::Spot, 0, {1, 2, 3}),
                                          file_light(SceneLightType::Point, 1, {-1, 0, 0}),
                                          default_light(rig.light_world())};
  const json j = json::parse(pbr_sidecar(rig, 0, lights));
  const json& got = j.at("shading").at("lights");
  ASSERT_EQ(got.size(), 3u);
  const json& spot = got[0];
  EXPECT_EQ(spot.at("name"), "light 0");
  EXPECT_EQ(spot.at("source"), "file");
  EXPECT_EQ(spot.at("light"), 0);
  EXPECT_EQ(spot.at("node"), 1);
  EXPECT_EQ(spot.at("type"), "spot");
  EXPECT_EQ(spot.at("color"), json({1.0, 1.0, 1.0}));
  EXPECT_EQ(spot.at("intensity"), 5.0);
  EXPECT_EQ(spot.at("position"), json({1.0, 2.0, 3.0}));
  EXPECT_EQ(spot.at("direction").at(1).get<double>(), lights[0].direction.y);
  EXPECT_EQ(spot.at("range"), 4.0);
  EXPECT_EQ(spot.at("inner_cone_angle"), double(0.1f));
  EXPECT_EQ(spot.at("outer_cone_angle"), double(0.6f));
  // a point light has no direction or cones
  EXPECT_EQ(got[1].at("type"), "point");
  EXPECT_FALSE(got[1].contains("direction"));
  EXPECT_FALSE(got[1].contains("inner_cone_angle"));
  // the default light: directional, toward light_dir_world
  const json& d = got[2];
  EXPECT_EQ(d.at("source"), "default");
  EXPECT_EQ(d.at("type"), "directional");
  EXPECT_FALSE(d.contains("position"));
  EXPECT_FALSE(d.contains("light"));
  EXPECT_EQ(d.at("intensity"), double(float(0.8 * glm::pi<double>())));
  for (int c = 0; c < 3; ++c)
    EXPECT_EQ(d.at("direction").at(c).get<double>(), -j.at("light_dir_world").at(c).get<double>());
  // lambert records no lights (its one light is light_dir_*)
  SidecarInfo lambert;
  lambert.render.shading = Shading::Lambert;
  lambert.lights = lights;
  EXPECT_FALSE(json::parse(sidecar_json(rig, Display{}, lambert)).at("shading").contains("lights"));
}

TEST(PbrLightsSidecar, ConfigDifferenceComparesTheLights) {
  const Rig rig = test::sidecar_rig();
  const std::vector<SceneLight> lights = {file_light(SceneLightType::Spot, 0, {1, 2, 3}),
                                          file_light(SceneLightType::Point, 1, {-1, 0, 0})};
  const std::string here = pbr_sidecar(rig, 5, lights);
  EXPECT_EQ(sidecar_config_difference(here, here), "");
  auto changed = [&](const std::function<void(std::vector<SceneLight>&)>& edit, int frame = 5) {
    std::vector<SceneLight> l = lights;
    edit(l);
    return pbr_sidecar(rig, frame, l);
  };
  // anything about a light, in the same frame
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[1].intensity = 6.0f; })), "shading");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[0].color[2] = 0.5f; })), "shading");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[0].outer_cone = 0.7f; })), "shading");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[1].range = 0.0f; })), "shading");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[1].position.x += 1e-9; })), "shading");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[0].direction = glm::dvec3(0, 0, -1); })),
            "shading");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l.pop_back(); })), "shading");
  // another frame (pmr verify, the folder scan): the poses follow the frame, the rest does not
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[1].position.x += 1.0; }, 6)), "");
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[1].intensity = 6.0f; }, 6)), "shading");
  // another scene: the lights follow from it
  EXPECT_EQ(sidecar_config_difference(here, changed([](auto& l) { l[1].intensity = 6.0f; }), true), "");
  EXPECT_EQ(sidecar_config_difference(here, pbr_sidecar(rig, 5, {}), true), "");
}

// Sidecars written before the lights were recorded: lambert ones as before, pbr ones were lit by the
// default light.
TEST(PbrLightsSidecar, OlderSidecarsCompareAsBefore) {
  const Rig rig = test::sidecar_rig();
  json old = json::parse(pbr_sidecar(rig, 2, {}));
  old["shading"].erase("lights");
  const std::string with_default = pbr_sidecar(rig, 2, {default_light(rig.light_world())});
  EXPECT_EQ(sidecar_config_difference(old.dump(), with_default), "");
  EXPECT_EQ(
      sidecar_config_difference(old.dump(), pbr_sidecar(rig, 2, {file_light(SceneLightType::Point, 0, {0, 1, 0})})),
      "shading");
  EXPECT_EQ(sidecar_config_difference(old.dump(), pbr_sidecar(rig, 2, {})), "shading") << "no light at all";
  json damaged = old;
  damaged.erase("light_dir_world");
  EXPECT_EQ(sidecar_config_difference(damaged.dump(), with_default), "shading");
  // with an environment image there was no default light
  json old_image = old, unlit = json::parse(pbr_sidecar(rig, 2, {}));
  old_image["shading"]["environment"] = unlit["shading"]["environment"] = {{"kind", "image"}, {"file", "sky.exr"}};
  EXPECT_EQ(sidecar_config_difference(old_image.dump(), unlit.dump()), "");
  json lit = json::parse(with_default);
  lit["shading"]["environment"] = old_image["shading"]["environment"];
  EXPECT_EQ(sidecar_config_difference(old_image.dump(), lit.dump()), "shading");
  // before --shading: lambert at exposure 0
  SidecarInfo lambert;
  lambert.render.shading = Shading::Lambert;
  lambert.has_bounds = true;
  json older = json::parse(sidecar_json(rig, Display{}, lambert));
  older.erase("shading");
  EXPECT_EQ(sidecar_config_difference(older.dump(), sidecar_json(rig, Display{}, lambert)), "");
}

// A grey quad, a static spot light and a point light whose node alone is animated: (-1, 0, 1) at
// t = 0, (1, 0, 1) at 1 s, (0, 1, 1) at 2 s.
std::string lights_scene(const std::string& dir, double bulb_intensity) {
  using namespace test;
  GltfFile g;
  const int pos = g.data<float>({-1.5f, -1, 0, 1.5f, -1, 0, 1.5f, 1, 0, -1.5f, 1, 0}, kFloat, "VEC3");
  const int idx = g.data<uint16_t>({0, 1, 2, 0, 2, 3}, kUShort, "SCALAR");
  const int times = g.data<float>({0.0f, 1.0f, 2.0f}, kFloat, "SCALAR");
  const int moves = g.data<float>({-1, 0, 1, 1, 0, 1, 0, 1, 1}, kFloat, "VEC3");
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"name", "Bulb"}, {"type", "point"}, {"intensity", bulb_intensity}, {"range", 5.0}},
      {{"name", "Spot"},
       {"type", "spot"},
       {"color", {1.0, 0.5, 0.25}},
       {"intensity", 8.0},
       {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}}};
  g.add("materials", {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.6}}}});
  g.mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}});
  g.add("nodes",
        {{"name", "BulbNode"}, {"translation", {-1, 0, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  g.add("nodes", {{"translation", {0, 0, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  g.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", moves}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}}}}}};
  g.scene({0, 1, 2});
  return g.write(dir, "lights");
}

json sidecar_at(const std::string& path) { return json::parse(test::read_file(path)); }

// pmr render records each frame's posed lights; --resume keeps what it finds complete, another frame of
// the same job in the folder is no other configuration (its lights stand elsewhere), pmr verify agrees,
// and a light changed in the file renders the frames again.
TEST(PbrLightsSidecar, ResumeComparesTheLightsOfEachFrame) {
  const std::string out = test::temp_dir("pbr_lights_resume"), in = test::temp_dir("pbr_lights_resume_scene");
  fs::create_directories(in);
  const std::string scene = lights_scene(in, 2.0);
  // (shadows off: with them the studio's boxes follow the file's lights, TheDefaultLightAndLambert)
  const std::string args = " '" + scene + "' --shading pbr --shadows off --fps 1" + kSmall + "--out " + out;
  CliRun r = run("render --frames 0:1" + args);
  ASSERT_EQ(r.status, 0) << r.output;
  for (int f : {0, 1}) {
    const json lights = sidecar_at(out + "/frame_000" + std::to_string(f) + ".json").at("shading").at("lights");
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights[0].at("name"), "Bulb");
    EXPECT_EQ(lights[0].at("node"), 1);
    EXPECT_EQ(lights[0].at("intensity"), 2.0);
    EXPECT_EQ(lights[0].at("range"), 5.0);
    EXPECT_EQ(lights[0].at("position"), json({f == 0 ? -1.0 : 1.0, 0.0, 1.0})) << "frame " << f;
    EXPECT_EQ(lights[1].at("type"), "spot");
    EXPECT_EQ(lights[1].at("color"), json({1.0, 0.5, 0.25}));
    EXPECT_EQ(lights[1].at("position"), json({0.0, 0.0, 3.0}));
    EXPECT_EQ(lights[1].at("direction"), json({-0.0, -0.0, -1.0}));
    EXPECT_TRUE(lights[1].at("range").is_null());
    EXPECT_EQ(lights[1].at("outer_cone_angle"), 0.5);
  }
  r = run("render --resume --frames 0:1" + args);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  r = run("render --frames 2" + args);  // frames 0 and 1 beside it: the same configuration
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(sidecar_at(out + "/frame_0002.json")["shading"]["lights"][0]["position"], json({0.0, 1.0, 1.0}));
  r = run("verify " + out + " --frames 0:2");
  EXPECT_EQ(r.status, 0) << r.output;

  lights_scene(in, 3.0);  // a brighter bulb
  r = run("render --resume --frames 0:2" + args);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("3 frame(s) were rendered from a different scene"), std::string::npos) << r.output;
  EXPECT_EQ(sidecar_at(out + "/frame_0001.json")["shading"]["lights"][0]["intensity"], 3.0);
}

// Without lights in the file, pbr records the default light (toward light_dir_world) with the uniform
// environment; with the studio (the default) the four soft boxes it draws as distant lights with
// shadows on, and none with shadows off or an image without a sun; the file's lights stay with an
// image; lambert records none.
TEST(PbrLightsSidecar, TheDefaultLightAndLambert) {
  const std::string out = test::temp_dir("pbr_lights_default");
  CliRun r = run("render --shading pbr" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  const json boxes = sidecar_at(out + "/frame_0000.json").at("shading").at("lights");
  ASSERT_EQ(boxes.size(), 4u);
  for (const json& b : boxes) {
    EXPECT_EQ(b.at("source"), "environment");
    EXPECT_EQ(b.at("distant"), true);
    EXPECT_FALSE(b.contains("node"));
  }
  EXPECT_EQ(boxes[0].at("name"), "studio ceiling");
  EXPECT_EQ(boxes[0].at("type"), "disk");
  EXPECT_EQ(boxes[0].at("position"), json({0.0, 1.0, 0.0}));
  r = run("render --shading pbr --shadows off --overwrite" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(sidecar_at(out + "/frame_0000.json").at("shading").at("lights"), json::array());
  r = run("render --shading pbr --environment uniform --overwrite" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  json j = sidecar_at(out + "/frame_0000.json");
  const json lights = j.at("shading").at("lights");
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_EQ(lights[0].at("source"), "default");
  for (int c = 0; c < 3; ++c)
    EXPECT_EQ(lights[0].at("direction").at(c).get<double>(), -j.at("light_dir_world").at(c).get<double>());
  const std::string in = test::temp_dir("pbr_lights_default_in");
  fs::create_directories(in);
  const std::string sky = in + "/sky.exr";
  test::write_exr(sky, test::make_map(64, 32, test::sun_sky));
  // the sky's sun is taken out as a light with shadows on (test_environment_lights.cpp), not with them off
  r = run("render --shading pbr --environment '" + sky + "'" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  const json sun = sidecar_at(out + "/frame_0000.json").at("shading").at("lights");
  ASSERT_EQ(sun.size(), 1u);
  EXPECT_EQ(sun[0].at("source"), "environment");
  EXPECT_EQ(sun[0].at("name"), "environment light 1");
  r = run("render --shading pbr --shadows off --environment '" + sky + "'" + kSmall + "--overwrite --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(sidecar_at(out + "/frame_0000.json").at("shading").at("lights"), json::array());
  r = run("render '" + lights_scene(in, 2.0) + "' --shading pbr --environment '" + sky + "' --frames 1 --fps 1" +
          kSmall + "--out " + out + "_image");
  ASSERT_EQ(r.status, 0) << r.output;
  const json file_lights = sidecar_at(out + "_image/frame_0001.json").at("shading").at("lights");
  ASSERT_EQ(file_lights.size(), 3u);
  EXPECT_EQ(file_lights[0].at("position"), json({1.0, 0.0, 1.0}));
  EXPECT_EQ(file_lights[2].at("source"), "environment");
  r = run("render '" + lights_scene(in, 2.0) + "' --shading pbr --environment '" + sky +
          "' --frames 1 --fps 1 --resume" + kSmall + "--out " + out + "_image");
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  r = run("render --shading lambert" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(sidecar_at(out + "/frame_0000.json").at("shading").contains("lights"));
}

}  // namespace
}  // namespace pmr
