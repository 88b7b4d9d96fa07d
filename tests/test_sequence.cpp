// Sequences as a user runs them (DESIGN section 7): frame lists, exactly the expected files, a frame
// alone equal to the same frame of a sequence, turntable frame 0 equal to the static render, --resume
// after an interrupt (the signal sent from here), configuration changes refused, empty frames.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "pmr/error.h"
#include "pmr/output.h"
#include "sequence/frame_list.h"
#include "sequence/frame_renderer.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::listing;
using test::run;
using test::temp_dir;

const std::string kSmall = " --views 4 --view-size 64x32 --display 240x135 ";

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<uint16_t> pixels(const std::string& path) {
  int w = 0, h = 0;
  std::vector<uint16_t> px;
  read_rgba_exr(path, w, h, px);
  return px;
}

nlohmann::json sidecar(const std::string& path) { return nlohmann::json::parse(read_text(path)); }

}  // namespace

TEST(FrameList, ParsesRangesStepsAndLists) {
  EXPECT_EQ(parse_frame_list("7"), (std::vector<long>{7}));
  EXPECT_EQ(parse_frame_list("0:3"), (std::vector<long>{0, 1, 2, 3}));
  EXPECT_EQ(parse_frame_list("1:10:4"), (std::vector<long>{1, 5, 9}));
  EXPECT_EQ(parse_frame_list("0:2,120,1,130:131"), (std::vector<long>{0, 1, 2, 120, 130, 131}));
  for (const char* bad : {"", "a", "3:1", "1:3:0", "1:", ":3", "1,,2", "1,", "-1", "1:2:3:4", "+3", "99999999"})
    EXPECT_THROW(parse_frame_list(bad), Error) << bad;
}

TEST(FrameList, FormatReadsBackAsTheSameFrames) {
  EXPECT_EQ(format_frame_list({0, 1, 2, 3, 7, 9, 11}), "0:3,7:11:2");
  EXPECT_EQ(format_frame_list({5}), "5");
  EXPECT_EQ(format_frame_list({4, 2, 2, 9}), "2,4,9");
  std::mt19937 rng(3);
  for (int k = 0; k < 200; ++k) {
    std::set<long> s;
    const int n = int(rng() % 40);
    for (int i = 0; i < n; ++i) s.insert(long(rng() % 100));
    const std::vector<long> frames(s.begin(), s.end());
    if (frames.empty()) continue;
    EXPECT_EQ(parse_frame_list(format_frame_list(frames)), frames) << format_frame_list(frames);
  }
}

// A short sequence writes exactly its frames' files, named by --name, and each sidecar says which
// frame, time and turntable angle it holds.
TEST(Sequence, WritesExactlyTheExpectedFiles) {
  const std::string out = temp_dir("seqfiles");
  const CliRun r = run("render --frames 0:2,5 --turntable 360:8 --fps 30 --name shot_%03d" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  std::set<std::string> expected;
  for (int f : {0, 1, 2, 5})
    for (const char* ext : {".exr", ".json"}) expected.insert("shot_00" + std::to_string(f) + ext);
  EXPECT_EQ(listing(out), expected);
  const nlohmann::json j = sidecar(out + "/shot_005.json");
  EXPECT_EQ(j["frame"], 5);
  EXPECT_DOUBLE_EQ(j["time"].get<double>(), 5.0 / 30.0);
  EXPECT_DOUBLE_EQ(j["fps"].get<double>(), 30.0);
  EXPECT_DOUBLE_EQ(j["turntable"]["angle_deg"].get<double>(), 225.0);
  EXPECT_EQ(j["outputs"]["encoded"], "shot_005.exr");
  EXPECT_TRUE(j["animation"].is_null());
  EXPECT_NE(r.output.find("4 frame(s)"), std::string::npos) << r.output;
}

// Turntable frame 0 is the static render framed as turntables are (--framing sphere), bit for bit; a
// frame rendered alone equals the same frame of a longer sequence (pixels and sidecar).
TEST(Sequence, FramesAreIndependentOfTheSequence) {
  const std::string a = temp_dir("seq_alone"), b = temp_dir("seq_long"), s = temp_dir("seq_static");
  ASSERT_EQ(run("render --turntable 90:4 --frames 0:3" + kSmall + "--out " + b).status, 0);
  ASSERT_EQ(run("render --turntable 90:4 --frames 2" + kSmall + "--out " + a).status, 0);
  ASSERT_EQ(run("render --framing sphere" + kSmall + "--out " + s).status, 0);
  EXPECT_EQ(pixels(a + "/frame_0002.exr"), pixels(b + "/frame_0002.exr"));
  EXPECT_EQ(read_text(a + "/frame_0002.json"), read_text(b + "/frame_0002.json"));
  EXPECT_EQ(pixels(s + "/frame_0000.exr"), pixels(b + "/frame_0000.exr"));
  EXPECT_NE(pixels(b + "/frame_0001.exr"), pixels(b + "/frame_0000.exr")) << "the turntable turns";

  // an animated, skinned model from the corpus: frame 17 alone and inside 0:20
  const std::string dir = test::corpus_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/gltf not found: animated part skipped";
  const std::string model = " '" + dir + "/CesiumMan/glTF/CesiumMan.gltf' ";
  const std::string c = temp_dir("seq_anim_long"), d = temp_dir("seq_anim_alone");
  ASSERT_EQ(run("render" + model + "--frames 0:20:1" + kSmall + "--out " + c).status, 0);
  ASSERT_EQ(run("render" + model + "--frames 17" + kSmall + "--out " + d).status, 0);
  EXPECT_EQ(pixels(c + "/frame_0017.exr"), pixels(d + "/frame_0017.exr"));
  EXPECT_EQ(read_text(c + "/frame_0017.json"), read_text(d + "/frame_0017.json"));
  EXPECT_NE(pixels(c + "/frame_0017.exr"), pixels(c + "/frame_0000.exr")) << "the figure moves";
  const nlohmann::json j = sidecar(d + "/frame_0017.json");
  EXPECT_EQ(j["animation"]["index"], 0);
}

// Interrupted with SIGINT from here: exit 130, only whole frames on disk, and the log's progress counts
// exactly those (a frame is counted once its files are written, not when it is rendered); --resume then
// renders exactly the missing frames; a changed configuration is refused unless --overwrite.
TEST(Sequence, ResumeAfterInterruptRendersOnlyTheMissingFrames) {
  const std::string out = temp_dir("seq_resume");
  // (shadows off: the studio's 128 shadow maps, rendered again in every frame of a turntable, would
  // make each frame several times longer; what is tested here is the sequence's bookkeeping)
  const std::string args =
      " --turntable 360:10 --frames 0:9 --views 32 --view-size 512x256 --display 1920x1080 --shadows off --out " + out;
  const pid_t pid = test::start("render" + args, out + ".log");
  ASSERT_GE(pid, 0);
  // wait for two finished frames, then interrupt
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (test::exists(out + "/frame_0001.exr")) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  const bool finished_first = WEXITSTATUS(status) == 0;  // a very fast machine may finish before the signal
  if (!finished_first) {
    EXPECT_EQ(WEXITSTATUS(status), 130);
  }
  std::set<std::string> before = listing(out);
  size_t complete = 0;
  for (const std::string& n : before) {
    EXPECT_NE(n[0], '.') << "temporary file left: " << n;
    const std::string stem = n.substr(0, n.find('.'));
    EXPECT_TRUE(before.count(stem + ".exr") && before.count(stem + ".json")) << "partial frame: " << n;
    complete += n.size() > 4 && n.substr(n.size() - 4) == ".exr";
  }
  EXPECT_GE(complete, 2u);
  // the log: "pmr: frame F written (k/10)" for each frame on disk, in order, and its summary agrees
  std::istringstream log(read_text(out + ".log"));
  size_t counted = 0;
  for (std::string line; std::getline(log, line);) {
    long frame = -1, k = -1, n = -1;
    if (std::sscanf(line.c_str(), "pmr: frame %ld written (%ld/%ld)", &frame, &k, &n) != 3) continue;
    EXPECT_EQ(size_t(k), ++counted) << line;
    char stem[32];
    std::snprintf(stem, sizeof stem, "frame_%04ld", frame);
    EXPECT_TRUE(before.count(std::string(stem) + ".json")) << line << ": not on disk";
  }
  EXPECT_EQ(counted, complete) << read_text(out + ".log");
  if (!finished_first) {
    EXPECT_NE(read_text(out + ".log").find(std::to_string(complete) + " of 10 frame(s) written"), std::string::npos)
        << read_text(out + ".log");
  }
  const auto mtime = fs::last_write_time(out + "/frame_0000.exr");
  const CliRun r = run("render --resume" + args);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(std::to_string(complete) + " already complete"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(std::to_string(10 - complete) + " frame(s) in"), std::string::npos) << r.output;
  // one line per reason says which frames are rendered again: here only missing ones
  EXPECT_NE(r.output.find("--resume: " + std::to_string(10 - complete) + " frame(s) are missing ("), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("are incomplete"), std::string::npos) << r.output;
  EXPECT_EQ(fs::last_write_time(out + "/frame_0000.exr"), mtime) << "a complete frame was rendered again";
  EXPECT_EQ(listing(out).size(), 20u);

  expect_one_error_line(run("render --resume --fps 30" + args), "different configuration (fps");
  const CliRun again = run("render --resume --overwrite --fps 30 --frames 3" + args);
  EXPECT_EQ(again.status, 0) << again.output;
  EXPECT_DOUBLE_EQ(sidecar(out + "/frame_0003.json")["fps"].get<double>(), 30.0);
}

// A scene with nothing to draw renders transparent frames with a warning instead of failing.
TEST(Sequence, EmptySceneRendersTransparentFrames) {
  const std::string out = temp_dir("seq_empty");
  fs::create_directories(out);
  const std::string scene = out + "_empty.gltf";
  std::ofstream(scene) << R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]})";
  const CliRun r = run("render '" + scene + "' --frames 0:1 --write encoded,views" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("nothing visible"), std::string::npos) << r.output;
  for (uint16_t v : pixels(out + "/frame_0001.exr")) ASSERT_EQ(v, 0u);
  EXPECT_EQ(read_exr_part_names(out + "/frame_0001.views.exr").size(), 4u);
  fs::remove(scene);
}

// A full disk stops the job with one line and exit code 1; the frames before stay whole and the frame
// that did not fit leaves nothing (not even its sidecar). Needs a small tmpfs: skipped where mounting
// is not allowed.
TEST(Sequence, FullDiskStopsCleanly) {
  const std::string mnt = temp_dir("seq_full");
  fs::create_directories(mnt);
  if (std::system(("mount -t tmpfs -o size=600k tmpfs '" + mnt + "' 2>/dev/null").c_str()) != 0) {
    fs::remove_all(mnt);
    GTEST_SKIP() << "cannot mount a small tmpfs here: skipped";
  }
  const CliRun r = run("render --frames 0:9 --views 8 --view-size 128x64 --display 960x540 --out " + mnt + "/o");
  const std::set<std::string> names = listing(mnt + "/o");
  std::system(("umount '" + mnt + "'").c_str());
  fs::remove_all(mnt);
  expect_one_error_line(r, "No space left on device");
  EXPECT_GE(names.size(), 2u);
  for (const std::string& n : names) {
    EXPECT_NE(n[0], '.') << "temporary file left: " << n;
    const std::string stem = n.substr(0, n.find('.'));
    EXPECT_TRUE(names.count(stem + ".exr") && names.count(stem + ".json")) << "partial frame: " << n;
  }
}

// Key times near float's maximum (a malformed but schema-valid file) or hours of animation: one clear
// error instead of posing billions of frames for the framing.
TEST(Sequence, AbsurdAnimationRangesAreRefused) {
  Scene s;
  s.animations = {{"long", 0.0, 1e30, 1}, {"ok", 0.5, 2.0, 1}};
  SequenceSpec spec;
  long first = 0, last = 0;
  spec.animation = 0;
  EXPECT_THROW(animation_frame_range(s, spec, first, last), Error);
  spec.animation = 1;
  animation_frame_range(s, spec, first, last);
  EXPECT_EQ(first, 12);
  EXPECT_EQ(last, 48);
  spec.animation = kAllAnimations;
  EXPECT_THROW(animation_frame_range(s, spec, first, last), Error);
  expect_one_error_line(run("render --turntable 360:100000000 --frames all" + kSmall + "--out " + temp_dir("seq_long")),
                        "give a range");
  // keys wholly beyond every frame number, or wholly before frame 0, even beyond a long's range (the
  // posing fuzzer's find: the frame numbers were converted from doubles out of range): no frame inside
  s.animations = {{"far", 1e30, 1e30, 1}, {"past", -1e30, -1e29, 1}, {"late", 9999998.0 / 24.0, 10000005.0 / 24.0, 1}};
  for (int a : {0, 1}) {
    spec.animation = a;
    EXPECT_FALSE(animation_key_frames(s, spec, first, last)) << a;
  }
  spec.animation = 2;  // from frame 9999998 to the last frame number
  ASSERT_TRUE(animation_key_frames(s, spec, first, last));
  EXPECT_EQ(first, 9999998);
  EXPECT_EQ(last, kMaxFrame);
}

TEST(Sequence, BadSequenceOptionsFailWithOneLine) {
  const std::string out = temp_dir("seq_bad");
  expect_usage_error(run("render --frames 5:2 --out " + out), "--frames");
  expect_usage_error(run("render --fps 0 --out " + out), "--fps");
  expect_usage_error(run("render --turntable 360:0 --out " + out), "--turntable");
  expect_usage_error(run("render --name frame --frames 0:1 --out " + out), "--name");  // one name, two frames
  expect_usage_error(run("render --name a/%d --out " + out), "--name");
  expect_one_error_line(run("render --animation walk" + kSmall + "--out " + out), "no animations");
}

}  // namespace pmr
