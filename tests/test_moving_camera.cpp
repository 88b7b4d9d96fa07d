// A glTF camera that moves: every frame of the sequence renders from that frame's own rig (view matrix,
// focal distance, near and far), exactly as the same pose rendered as a still. Static geometry, a
// camera that dollies in depth, moves sideways and turns; a last key turns it around, so that the
// scene's center lies behind it.
#include <gtest/gtest.h>

#include <filesystem>

#include "gltf_builder.h"
#include "reference/reference.h"
#include "sequence/frame_renderer.h"
#include "test_util.h"

namespace pmr {
namespace {

using namespace test;

// Key times 0, 0.5, 1 and 1.5 s: frames 0, 12, 24 and 36 at 24 fps.
const std::vector<float> kKeyTimes = {0.0f, 0.5f, 1.0f, 1.5f};

// Three quads at different depths (z = 0.6, 0, -0.8), each facing +z, and camera 0 on a node that
// starts at (0, 0, 4) looking down -z.
std::string dolly_file(const std::string& dir) {
  GltfFile g;
  std::vector<float> pos, nrm;
  std::vector<uint16_t> idx;
  const float quads[3][4] = {{-0.5f, -0.4f, 0.3f, 0.6f}, {-1.0f, -1.0f, 1.0f, 0.0f}, {-0.2f, -1.5f, 1.6f, -0.8f}};
  for (const auto& q : quads) {  // x0, y0, half-size, z
    const uint16_t base = uint16_t(pos.size() / 3);
    const float x0 = q[0], y0 = q[1], s = 2.0f * q[2], z = q[3];
    const float corners[4][2] = {{x0, y0}, {x0 + s, y0}, {x0 + s, y0 + s}, {x0, y0 + s}};
    for (const auto& c : corners) pos.insert(pos.end(), {c[0], c[1], z}), nrm.insert(nrm.end(), {0.0f, 0.0f, 1.0f});
    for (uint16_t k : {0, 1, 2, 0, 2, 3}) idx.push_back(uint16_t(base + k));
  }
  const int p = g.data<float>(pos, kFloat, "VEC3"), n = g.data<float>(nrm, kFloat, "VEC3");
  const int i = g.data<uint16_t>(idx, kUShort, "SCALAR");
  g.mesh(json::array({{{"attributes", {{"POSITION", p}, {"NORMAL", n}}}, {"indices", i}}}));
  g.add("nodes", {{"mesh", 0}});
  g.add("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.05}}}});
  g.add("nodes", {{"name", "Dolly"}, {"camera", 0}, {"translation", {0, 0, 4}}});
  const int times = g.data<float>(kKeyTimes, kFloat, "SCALAR");
  // in depth, sideways and up, then held while the camera turns around (yaw 180 degrees)
  const int moves = g.data<float>({0, 0, 4, 0.5f, 0.2f, 3, 0.1f, -0.1f, 2.2f, 0.1f, -0.1f, 2.2f}, kFloat, "VEC3");
  const float s4 = std::sin(glm::radians(4.0f)), c4 = std::cos(glm::radians(4.0f));
  const float s3 = std::sin(glm::radians(3.0f)), c3 = std::cos(glm::radians(3.0f));
  // x y z w: identity, yaw 8 degrees, pitch 6 degrees, yaw 180 degrees
  const int turns = g.data<float>({0, 0, 0, 1, 0, s4, 0, c4, s3, 0, 0, c3, 0, 1, 0, 0}, kFloat, "VEC4");
  g.doc["animations"] = {{{"name", "dolly"},
                          {"samplers", {{{"input", times}, {"output", moves}}, {{"input", times}, {"output", turns}}}},
                          {"channels",
                           {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}},
                            {{"sampler", 1}, {"target", {{"node", 1}, {"path", "rotation"}}}}}}}};
  g.scene({0, 1});
  return g.write(dir, "dolly");
}

RigConfig dolly_rig_config() {
  RigConfig rc;
  rc.views = 8, rc.view_w = 48, rc.view_h = 24, rc.camera = 0;
  return rc;
}

PipelineConfig debug_config() {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.debug_outputs = true;
  return pc;
}

struct FrameImage {
  Rig rig;
  std::vector<uint32_t> key, count;
  std::vector<float> depth;
  std::vector<uint16_t> volume;
};

FrameImage read_back(const Pipeline& p, const Rig& rig) {
  FrameImage f;
  f.rig = rig;
  p.read_debug(f.key, f.depth, f.count);
  p.read_volume(f.volume);
  return f;
}

// Frame `frame` of the animated camera through the frame loop.
FrameImage sequence_frame(const Scene& scene, long frame) {
  SequenceSpec spec;
  select_animation(scene, "", spec);
  FrameRenderer renderer(scene, spec, dolly_rig_config(), Display(), nullptr);
  Pipeline p(runtime(), debug_config());
  renderer.attach(p, nullptr);
  const FrameRenderer::Frame fr = renderer.render(frame);
  return read_back(p, fr.rig);
}

// The same pose as a still: the scene without its animation, its camera placed where frame `frame` puts
// it (posed independently of the frame loop, by pose_scene).
FrameImage still_frame(const Scene& scene, long frame) {
  Scene posed;
  PoseRequest r;
  r.time = double(frame) / 24.0;
  r.animation = 0;
  pose_scene(scene, r, posed);
  Scene still = scene;
  still.animations.clear();
  still.motion.reset();
  still.cameras[0].world_from_camera = posed.cameras[0].world_from_camera;
  SequenceSpec spec;
  select_animation(still, "none", spec);
  FrameRenderer renderer(still, spec, dolly_rig_config(), Display(), nullptr);
  Pipeline p(runtime(), debug_config());
  renderer.attach(p, nullptr);
  const FrameRenderer::Frame fr = renderer.render(0);
  return read_back(p, fr.rig);
}

TEST(MovingCamera, EveryFrameRendersAsTheSamePoseStillAndAsTheReference) {
  const std::string dir = temp_dir("moving_camera");
  std::filesystem::create_directories(dir);
  const Scene scene = load_scene(dolly_file(dir));
  ASSERT_EQ(scene.cameras.size(), 1u);
  std::vector<FrameImage> frames;
  for (long f : {0L, 6L, 12L, 18L, 24L}) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const FrameImage got = sequence_frame(scene, f), still = still_frame(scene, f);
    EXPECT_EQ(got.rig.focal, still.rig.focal);
    EXPECT_EQ(got.rig.near_eff, still.rig.near_eff);
    EXPECT_EQ(got.rig.far, still.rig.far);
    EXPECT_TRUE(got.volume == still.volume) << "the frame differs from its pose rendered as a still";
    EXPECT_TRUE(got.key == still.key);
    // against the C++ reference rasterizer with the still's rig (independent of the frame loop)
    const ref::RasterResult want = ref::render(params_for(still.rig), scene);
    size_t covered = 0;
    ASSERT_EQ(got.key.size(), want.key.size());
    for (size_t v = 0; v < want.key.size(); ++v) {
      ASSERT_EQ(got.key[v], want.key[v]) << "voxel " << v;
      if (want.key[v] == PMR_NO_KEY) continue;
      ASSERT_EQ(got.depth[v], want.depth[v]) << "voxel " << v;
      ++covered;
    }
    EXPECT_GT(covered, want.key.size() / 10) << "the quads should fill a good part of every frame";
    frames.push_back(got);
  }
  // the camera really moves: focal distance, near and far change, and so do the images
  EXPECT_LT(frames.back().rig.focal, 0.7 * frames.front().rig.focal);
  EXPECT_NE(frames.back().rig.near, frames.front().rig.near);
  for (size_t i = 1; i < frames.size(); ++i) EXPECT_FALSE(frames[i].volume == frames[i - 1].volume) << "frame " << i;
}

// Frame 36 turns the camera away: that frame fails with the rig's message, alone or in a sequence, and
// the frames before it render and are written.
TEST(MovingCamera, AFrameFacingAwayFailsAndTheOthersRender) {
  const std::string dir = temp_dir("moving_camera_cli");
  std::filesystem::create_directories(dir);
  const std::string file = dolly_file(dir);
  const std::string common =
      " --camera '#0' --views 8 --view-size 48x24 --display 96x54 --shading lambert --write encoded";
  const CliRun far_frame = run("render " + file + common + " --frames 24 --out " + dir + "/one");
  EXPECT_EQ(far_frame.status, 0) << far_frame.output;
  EXPECT_EQ(far_frame.output.find("nothing visible"), std::string::npos) << far_frame.output;
  const CliRun away = run("render " + file + common + " --frames 36 --out " + dir + "/away");
  expect_one_error_line(away, "looks away from the scene");
  const CliRun seq = run("render " + file + common + " --frames 0,24,36 --out " + dir + "/seq");
  expect_one_error_line(seq, "looks away from the scene");
  EXPECT_TRUE(exists(dir + "/seq/frame_0000.exr"));
  EXPECT_TRUE(exists(dir + "/seq/frame_0024.exr"));
  EXPECT_FALSE(exists(dir + "/seq/frame_0036.exr"));
}

}  // namespace
}  // namespace pmr
