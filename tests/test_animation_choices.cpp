// Which frames and poses an animated scene renders (docs/SEQUENCES.md): --animation none is the rest
// pose; --frames all covers the frames whose times lie inside the keys, ceil(start x fps) to
// floor(end x fps); with --turntable it is one turn, the animation holding its first and last pose
// outside its keys; the out-of-range warning names the same range.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "pmr/error.h"
#include "pmr/output.h"
#include "sequence/frame_renderer.h"
#include "sequence/range_warning.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::expect_one_error_line;
using test::run;
using test::temp_dir;

const std::string kSmall = " --views 4 --view-size 64x32 --display 240x135 ";

// One triangle; with `animated`, the clip "Slide" moves it from x = 1 at t0 to x = 2 at t1 (its rest
// pose, at the origin, is no pose of the clip).
std::string slide_gltf(const std::string& dir, const std::string& name, bool animated, float t0, float t1) {
  fs::create_directories(dir);
  const float data[] = {0,  0,  0, 1, 0, 0, 0, 1, 0,  // positions
                        t0, t1,                       // key times
                        1,  0,  0, 2, 0, 0};          // translations
  std::ofstream(dir + "/" + name + ".bin", std::ios::binary).write(reinterpret_cast<const char*>(data), sizeof data);
  char times[96];
  std::snprintf(times, sizeof times, "\"min\": [%.9g], \"max\": [%.9g]", double(t0), double(t1));
  const std::string animation = animated ? R"(, "animations": [{"name": "Slide", "channels": [{"sampler": 0,
      "target": {"node": 0, "path": "translation"}}], "samplers": [{"input": 1, "output": 2}]}])"
                                         : "";
  std::ofstream(dir + "/" + name + ".gltf") << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"uri": ")" + name + R"(.bin", "byteLength": 68}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 44, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", )" +
                                                   times + R"(},
                  {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"}])" +
                                                   animation + "}";
  return " '" + dir + "/" + name + ".gltf' ";
}

std::set<std::string> exr_files(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".exr") names.insert(e.path().filename().string());
  return names;
}

std::set<std::string> frame_files(long first, long last) {
  std::set<std::string> names;
  char buf[32];
  for (long f = first; f <= last; ++f) {
    std::snprintf(buf, sizeof buf, "frame_%04ld.exr", f);
    names.insert(buf);
  }
  return names;
}

std::vector<uint16_t> pixels(const std::string& path) {
  int w = 0, h = 0;
  std::vector<uint16_t> px;
  read_rgba_exr(path, w, h, px);
  return px;
}

nlohmann::json sidecar(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

std::string frame(const std::string& dir, long f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "/frame_%04ld.exr", f);
  return dir + buf;
}

}  // namespace

TEST(AnimationChoices, KeyFramesLieInsideTheKeys) {
  Scene s;
  // CesiumMan's clip: the first key at 1/24 s as a float (a hair above 1/24)
  s.animations = {{"late", double(1.0f / 24.0f), 2.0, 1}, {"between", 0.01, 0.03, 1}, {"exact", 0.5, 1.0, 1}};
  SequenceSpec spec;
  spec.fps = 24;
  long first = 0, last = 0;
  spec.animation = 0;
  ASSERT_TRUE(animation_key_frames(s, spec, first, last));
  EXPECT_EQ(first, 1);  // frame 0 (t = 0) lies before the first key
  EXPECT_EQ(last, 48);
  spec.animation = 2;
  ASSERT_TRUE(animation_key_frames(s, spec, first, last));
  EXPECT_EQ(first, 12);
  EXPECT_EQ(last, 24);
  spec.fps = 10;  // keys 0.5 and 1.0 s: frames 5 and 10
  ASSERT_TRUE(animation_key_frames(s, spec, first, last));
  EXPECT_EQ(first, 5);
  EXPECT_EQ(last, 10);
  spec.fps = 7;  // 3.5 to 7: frames 4 to 7
  ASSERT_TRUE(animation_key_frames(s, spec, first, last));
  EXPECT_EQ(first, 4);
  EXPECT_EQ(last, 7);
  // no frame time between 0.01 and 0.03 s at 24 fps (0.24 and 0.72 frames): --frames all says so
  spec.fps = 24;
  spec.animation = 1;
  EXPECT_FALSE(animation_key_frames(s, spec, first, last));
  EXPECT_THROW(animation_frame_range(s, spec, first, last), Error);
  // with a turntable, --frames all is one turn, however long the animation
  spec.turntable = true, spec.turntable_deg = 360, spec.turntable_frames = 96;
  for (int a : {0, 1, 2}) {
    spec.animation = a;
    animation_frame_range(s, spec, first, last);
    EXPECT_EQ(first, 0);
    EXPECT_EQ(last, 95);
  }
  // the warning names the key frames, with or without the turntable
  spec.animation = 0, spec.animation_label = "late";
  EXPECT_EQ(frames_outside_animation(s, spec, {0, 1, 48}, false),
            "frame 0 lies outside the animation 'late' (frames 1:48 at 24 fps): it repeats its first pose (the "
            "turntable still turns)");
  spec.turntable = false;
  EXPECT_EQ(frames_outside_animation(s, spec, {1, 48}, false), "");
  spec.animation = 1, spec.animation_label = "between";
  EXPECT_NE(frames_outside_animation(s, spec, {0, 1}, false).find("no frame at 24 fps lies inside its keys"),
            std::string::npos);
  // none: the rest pose
  select_animation(s, "none", spec);
  EXPECT_EQ(spec.animation, kNoAnimation);
  animation_frame_range(s, spec, first, last);
  EXPECT_EQ(first, 0);
  EXPECT_EQ(last, 0);
  select_animation(Scene{}, "none", spec);  // a still scene has its rest pose too
  EXPECT_EQ(spec.animation, kNoAnimation);
}

// --animation none renders the rest pose: the same pixels as the file without its animation.
TEST(AnimationChoices, NoneRendersTheRestPose) {
  const std::string dir = temp_dir("anim_none");
  const std::string animated = slide_gltf(dir + "/in", "animated", true, 0.5f, 1.0f);
  const std::string still = slide_gltf(dir + "/in", "still", false, 0.5f, 1.0f);
  CliRun r = run("render" + animated + "--animation none --frames 18" + kSmall + "--out " + dir + "/none");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;  // no range to leave
  ASSERT_EQ(run("render" + still + "--frames 18" + kSmall + "--out " + dir + "/still").status, 0);
  ASSERT_EQ(run("render" + animated + "--frames 18" + kSmall + "--out " + dir + "/slide").status, 0);
  EXPECT_EQ(pixels(frame(dir + "/none", 18)), pixels(frame(dir + "/still", 18)));
  EXPECT_NE(pixels(frame(dir + "/none", 18)), pixels(frame(dir + "/slide", 18))) << "the clip moves it";
  EXPECT_TRUE(sidecar(dir + "/none/frame_0018.json")["animation"].is_null());
  EXPECT_EQ(sidecar(dir + "/slide/frame_0018.json")["animation"]["name"], "Slide");
  // --resume tells the two apart
  expect_one_error_line(run("render" + animated + "--frames 18 --resume" + kSmall + "--out " + dir + "/none"),
                        "different configuration (animation");
}

// --frames all: the key frames alone; with a turntable one turn, the clip holding its first and last
// pose outside its keys; explicit frames outside the keys warn with the same range.
TEST(AnimationChoices, FramesAllFromTheCommandLine) {
  const std::string dir = temp_dir("anim_all");
  // keys at 0.5 and 1.0 s: frames 4 to 8 at 8 fps
  const std::string scene = slide_gltf(dir + "/in", "slide", true, 0.5f, 1.0f) + "--fps 8" + kSmall;
  CliRun r = run("render" + scene + "--frames all --out " + dir + "/all");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(exr_files(dir + "/all"), frame_files(4, 8));
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;

  r = run("render" + scene + "--turntable 360:6 --frames all --out " + dir + "/turn");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(exr_files(dir + "/turn"), frame_files(0, 5)) << "one turn, not the animation's range";
  EXPECT_EQ(r.output.find("outside the animation"), std::string::npos) << r.output;

  // a turntable that does not turn (0 degrees), 16 frames: the clip's time runs on with the frames
  r = run("render" + scene + "--turntable 0:16 --frames all --out " + dir + "/hold");
  ASSERT_EQ(r.status, 0) << r.output;
  ASSERT_EQ(exr_files(dir + "/hold"), frame_files(0, 15));
  EXPECT_DOUBLE_EQ(sidecar(dir + "/hold/frame_0015.json")["time"].get<double>(), 15.0 / 8.0);
  const std::vector<uint16_t> first_pose = pixels(frame(dir + "/hold", 4)), last_pose = pixels(frame(dir + "/hold", 8));
  EXPECT_NE(first_pose, last_pose);
  for (long f = 0; f < 4; ++f) EXPECT_EQ(pixels(frame(dir + "/hold", f)), first_pose) << "frame " << f;
  for (long f = 5; f < 8; ++f) EXPECT_NE(pixels(frame(dir + "/hold", f)), last_pose) << "frame " << f;
  for (long f = 9; f < 16; ++f) EXPECT_EQ(pixels(frame(dir + "/hold", f)), last_pose) << "frame " << f;

  r = run("render" + scene + "--frames 3:4 --out " + dir + "/outside");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("pmr: warning: frame 3 lies outside the animation 'Slide' (frames 4:8 at 8 fps): it "
                          "repeats its first pose"),
            std::string::npos)
      << r.output;

  // keys at 0.51 and 0.52 s lie between frames 12 (0.5 s) and 13 (0.54 s) at 24 fps: no frame inside
  const std::string narrow = slide_gltf(dir + "/in", "narrow", true, 0.51f, 0.52f);
  expect_one_error_line(run("render" + narrow + "--frames all" + kSmall + "--out " + dir + "/narrow"), "no frame time");
}

// CesiumMan's first key is at 1/24 s: --frames all starts at frame 1 (frame 0 would repeat it).
TEST(AnimationChoices, CesiumManStartsAtItsFirstKey) {
  const std::string corpus = test::corpus_dir();
  if (corpus.empty()) GTEST_SKIP() << "../shared/gltf not found: CesiumMan skipped";
  const std::string model = " '" + corpus + "/CesiumMan/glTF/CesiumMan.gltf' ";
  const CliRun info = run("info" + model);
  ASSERT_EQ(info.status, 0) << info.output;
  EXPECT_NE(info.output.find("--frames all at 24 fps: 1:48\n"), std::string::npos) << info.output;
  // at 2 fps the keys (1/24 to 2 s) hold frames 1 to 4
  const std::string out = temp_dir("anim_cesium");
  const CliRun r = run("render" + model + "--frames all --fps 2" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(exr_files(out), frame_files(1, 4));
}

}  // namespace pmr
