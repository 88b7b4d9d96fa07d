// One output folder, one configuration (host/sequence/folder_guard.h): finished frames of another
// configuration that a run would not replace refuse it (or, with --overwrite, are counted in a
// warning); a running process of another configuration (its lock held) refuses a second one, the
// same configuration (shards of one job) runs beside it; lock files leave no trace. And the warning
// for frames outside the animation (host/sequence/range_warning.h).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <thread>

#include "output/sidecar.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "sequence/folder_guard.h"
#include "sequence/range_warning.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::expect_one_error_line;
using test::run;
using test::start;
using test::temp_dir;

const std::string kSmall = " --turntable 360:8 --views 4 --view-size 64x32 --display 240x135 -q ";

// name -> last write time, hidden files included
std::map<std::string, fs::file_time_type> snapshot(const std::string& dir) {
  std::map<std::string, fs::file_time_type> s;
  for (const auto& e : fs::directory_iterator(dir)) s[e.path().filename().string()] = e.last_write_time();
  return s;
}

std::vector<std::string> lock_files(const std::string& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(".pmr-lock-", 0) == 0) v.push_back(e.path().filename().string());
  return v;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Holds a lock file (as a running pmr would) with the sidecar `text`; releases it when destroyed.
struct HeldLock {
  int fd = -1;
  std::string path;
  HeldLock(const std::string& dir, const std::string& text) {
    path = dir + "/" + folder_lock_name("frame_%04d", text);
    std::ofstream(path) << text;
    fd = ::open(path.c_str(), O_RDWR);
    EXPECT_EQ(::flock(fd, LOCK_SH), 0) << std::strerror(errno);
  }
  ~HeldLock() { ::close(fd); }
};

// The sidecar of frame 0 rendered with `args` in a scratch folder.
std::string sidecar_of(const std::string& name, const std::string& args) {
  const std::string dir = temp_dir(name);
  EXPECT_EQ(run("render --frames 0" + args + "--out " + dir).status, 0);
  return test::read_file(dir + "/frame_0000.json");
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST(FolderGuard, SidecarNamesFollowThePatternExactly) {
  EXPECT_EQ(sidecar_frame("frame_%04d", "frame_0007.json"), 7);
  EXPECT_EQ(sidecar_frame("frame_%04d", "frame_12345.json"), 12345);
  EXPECT_EQ(sidecar_frame("frame_%04d", "frame_7.json"), -1);  // not what the pattern makes
  EXPECT_EQ(sidecar_frame("frame_%04d", "frame_0007.exr"), -1);
  EXPECT_EQ(sidecar_frame("frame_%04d", "frame_0007.views.json"), -1);
  EXPECT_EQ(sidecar_frame("frame_%04d", "shot_0007.json"), -1);
  EXPECT_EQ(sidecar_frame("frame_%04d", "frame_-007.json"), -1);
  EXPECT_EQ(sidecar_frame("shot_%d_v2", "shot_12_v2.json"), 12);
  EXPECT_EQ(sidecar_frame("shot_%d_v2", "shot_012_v2.json"), -1);
  EXPECT_EQ(sidecar_frame("a%%b%03d", "a%b007.json"), 7);
  EXPECT_EQ(sidecar_frame("f####", "f0042.json"), 42);  // Blender's spelling of f%04d
  EXPECT_EQ(sidecar_frame("f####", "f42.json"), -1);
  EXPECT_EQ(sidecar_frame("duck", "duck.json"), -1);  // no frame field: one frame, always this job's
  const std::string lock = folder_lock_name("frame_%04d", "{}");
  EXPECT_EQ(lock.rfind(".pmr-lock-", 0), 0u);
  EXPECT_EQ(sidecar_frame("frame_%04d", lock), -1);
  EXPECT_EQ(sidecar_frame("frame_%04d", lock + ".json"), -1);
  EXPECT_NE(folder_lock_name("frame_%04d", "{}"), folder_lock_name("shot_%04d", "{}"));
  // two spellings of the same names share one lock: their runs see each other
  EXPECT_EQ(folder_lock_name("frame_####", "{}"), folder_lock_name("frame_%04d", "{}"));
}

// Frames of another configuration outside this run: refused with the key and a frame named, nothing
// written; rendering all of them again proceeds; --overwrite alone renders and counts what remains;
// another shard's frames count as this job's.
TEST(FolderGuard, AnotherConfigurationThisRunWouldNotReplaceIsRefused) {
  const std::string out = temp_dir("guard_refuse");
  const std::string at = " --out " + out;
  ASSERT_EQ(run("render --frames 0:3" + kSmall + at).status, 0);
  const auto before = snapshot(out);
  ASSERT_EQ(before.size(), 8u);  // no lock file left behind

  // the scan compares sidecars without their view matrices: they must not be part of the configuration
  const std::string text = test::read_file(out + "/frame_0001.json");
  const std::string cut = without_view_matrices(text);
  EXPECT_LT(cut.size(), text.size());
  EXPECT_EQ(nlohmann::json::parse(cut).count("views"), 0u);
  nlohmann::ordered_json moved = nlohmann::ordered_json::parse(text);
  moved["views"][0]["view"][12] = 99.0;
  EXPECT_EQ(sidecar_config_difference(moved.dump(), text), "");
  EXPECT_EQ(sidecar_config_difference(cut, text), "");
  EXPECT_EQ(without_view_matrices(moved.dump()), moved.dump()) << "another layout is compared whole";

  const CliRun refused = run("render --frames 0:1 --fps 30" + kSmall + at);
  expect_one_error_line(refused,
                        out +
                            " holds frame_0002.json rendered with another configuration (fps differs) that "
                            "this run would not replace; use another --out, render those frames too, or --overwrite");
  EXPECT_EQ(snapshot(out), before) << "a refused run wrote, removed or left something";
  // the same with --resume (which skips nothing here: every listed frame differs)
  expect_one_error_line(run("render --resume --frames 0:1 --fps 30" + kSmall + at),
                        "frame_0002.json rendered with another");

  // every frame of the other configuration rendered again: allowed
  CliRun r = run("render --frames 0:3 --fps 30" + kSmall + at);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(run("verify " + out + " --frames 0:3").status, 0);

  // --overwrite alone: renders, one warning with the count of frames left in the other configuration
  r = run("render --frames 0:1 --overwrite" + kSmall + at);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count(r.output, "warning: --overwrite"), 1u) << r.output;
  EXPECT_NE(r.output.find("pmr: warning: --overwrite: " + out +
                          " keeps 2 frame(s) of another configuration that this "
                          "run does not replace (frame_0002.json: fps differs)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(nlohmann::json::parse(test::read_file(out + "/frame_0000.json"))["fps"].get<double>(), 24.0);
  EXPECT_EQ(lock_files(out).size(), 0u);

  // frames 0, 1 at 24 fps, 2, 3 at 30. Shard 0/2 of 0:3 renders 0 and 2; 1 and 3 are shard 1's, so
  // the job rewrites every frame of the other configuration: allowed.
  r = run("render --frames 0:3 --shard 0/2" + kSmall + at);
  EXPECT_EQ(r.status, 0) << r.output;
  // shard 0/2 of 0:1 is frame 0 alone; frame 3 (30 fps) is nobody's in this job: refused
  expect_one_error_line(run("render --frames 0:1 --shard 0/2" + kSmall + at),
                        "frame_0003.json rendered with another "
                        "configuration (fps differs)");
  // another --name pattern does not see these frames
  r = run("render --frames 0 --fps 30 --name shot_%04d" + kSmall + at);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(lock_files(out).size(), 0u);
}

// A lock of another configuration held by a live process refuses the run (nothing written); once it
// is released, the stale file is removed and the run proceeds. A held lock of the same configuration
// under another fingerprint (here: other --write) does not refuse.
TEST(FolderGuard, ALiveProcessOfAnotherConfigurationRefusesTheSecond) {
  const std::string out = temp_dir("guard_lock");
  fs::create_directories(out);
  const std::string other = sidecar_of("guard_lock_other", " --fps 30" + kSmall);
  {
    const HeldLock held(out, other);
    const auto before = snapshot(out);
    const CliRun r = run("render --frames 0:1" + kSmall + "--out " + out);
    expect_one_error_line(r, out +
                                 " is being rendered right now by a pmr process with another configuration (fps "
                                 "differs; it holds " +
                                 fs::path(held.path).filename().string() + ")");
    EXPECT_EQ(snapshot(out), before) << "a refused run left something";
    // --overwrite does not override a running process
    expect_one_error_line(run("render --frames 0:1 --overwrite" + kSmall + "--out " + out), "being rendered right now");
  }
  // released: the file is stale and goes away
  CliRun r = run("render --frames 0:1" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(lock_files(out).size(), 0u);
  {
    const HeldLock same(out, sidecar_of("guard_lock_same", " --write encoded,views" + kSmall));
    r = run("render --frames 0:1" + kSmall + "--out " + out);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(lock_files(out).size(), 1u) << "the held lock stays, this run's own is removed";
  }
}

// Planted lock names (docs/SECURITY.md): a symlink to /dev/zero held with flock, a FIFO and a held lock of
// 8 MiB are neither followed, nor waited on, nor read to their end.
TEST(FolderGuard, PlantedLockFilesAreNotFollowedNorReadWithoutBound) {
  const std::string out = temp_dir("guard_planted");
  fs::create_directories(out);
  const std::string other = sidecar_of("guard_planted_other", " --fps 30" + kSmall);
  const std::string name = folder_lock_name("frame_%04d", other);
  const int zero = ::open("/dev/zero", O_RDONLY);
  ASSERT_GE(zero, 0);
  ASSERT_EQ(::flock(zero, LOCK_SH), 0) << std::strerror(errno);
  fs::create_symlink("/dev/zero", out + "/" + name);
  CliRun r = run("render --frames 0" + kSmall + "--out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  ::close(zero);
  fs::remove(out + "/" + name);
  ASSERT_EQ(::mkfifo((out + "/" + name).c_str(), 0644), 0) << std::strerror(errno);
  r = run("render --frames 0 --overwrite" + kSmall + "--out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  fs::remove(out + "/" + name);
  {
    const HeldLock huge(out, other + std::string(size_t(8) << 20, ' '));
    expect_one_error_line(run("render --frames 0 --overwrite" + kSmall + "--out " + out),
                          "being rendered right now by a pmr process with another configuration (unrecorded");
  }
  // this run's own lock name planted as a symlink or a FIFO: refused, not followed, not waited on
  const std::string expected = "{\"a configuration\": 1}";
  const std::string own = out + "/" + folder_lock_name("frame_%04d", expected);
  for (bool fifo : {false, true}) {
    fs::remove(own);
    if (fifo) ASSERT_EQ(::mkfifo(own.c_str(), 0644), 0) << std::strerror(errno);
    else fs::create_symlink("/dev/zero", own);
    try {
      FolderGuard guard(out, "frame_%04d", {0}, expected, false, true);
      ADD_FAILURE() << "a planted own lock was taken";
    } catch (const Error& e) {
      EXPECT_NE(
          std::string(e.what()).find(fifo ? "it is not a regular file" : "it is a symbolic link, not a lock pmr made"),
          std::string::npos)
          << e.what();
    }
  }
}

// Real processes: a slow one of one configuration, then a second of another configuration is refused
// while it runs; two shards of one configuration started together both finish.
TEST(FolderGuard, ConcurrentProcesses) {
  const std::string out = temp_dir("guard_concurrent");
  const pid_t slow = start(
      "render -q --turntable 360:100 --frames 0:99 --views 32 --view-size 512x256 --display 1920x1080 "
      "--out " +
      out);
  ASSERT_GT(slow, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    // its first frame written: past the set-up (a signal then stops it cleanly)
    if (test::exists(out + "/frame_0000.json")) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(lock_files(out).size(), 1u);
  const CliRun second =
      run("render --frames 200 --fps 30 --turntable 360:100 --views 32 --view-size 512x256 "
          "--display 1920x1080 --out " +
          out);
  int status = 0;
  const bool slow_still_running = waitpid(slow, &status, WNOHANG) == 0;
  kill(slow, SIGINT);
  const int slow_exit = slow_still_running ? wait_exit(slow) : (WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  EXPECT_TRUE(slow_exit == 130 || slow_exit == 0) << slow_exit;
  ASSERT_TRUE(slow_still_running) << "the first process finished too early for the test";
  expect_one_error_line(second, "is being rendered right now by a pmr process with another configuration (fps differs");
  EXPECT_FALSE(test::exists(out + "/frame_0200.json"));
  EXPECT_EQ(lock_files(out).size(), 0u) << "the interrupted process removes its lock file";

  // two shards of one job at the same time, into one folder
  const std::string shared = temp_dir("guard_shards");
  const std::string job =
      "render -q --frames 0:5 --turntable 360:6 --views 8 --view-size 128x64 --display 480x270 "
      "--out " +
      shared + " --shard ";
  const pid_t a = start(job + "0/2"), b = start(job + "1/2");
  EXPECT_EQ(wait_exit(a), 0);
  EXPECT_EQ(wait_exit(b), 0);
  EXPECT_EQ(run("verify " + shared + " --frames 0:5").status, 0);
  EXPECT_EQ(lock_files(shared).size(), 0u);
}

TEST(RangeWarning, NamesTheFramesOutsideAndTheRange) {
  Scene s;
  s.animations = {{"Walk", 0.0, 2.0, 1}, {"Run", 0.5, 1.0, 1}};
  SequenceSpec spec;
  spec.fps = 24;
  spec.animation = 0;
  spec.animation_label = "Walk";
  EXPECT_EQ(frames_outside_animation(s, spec, {0, 10, 48}, false), "");
  EXPECT_EQ(frames_outside_animation(s, spec, {40, 49, 50, 51}, false),
            "frames 49:51 lie outside the animation 'Walk' (frames 0:48 at 24 fps): they repeat its last pose");
  EXPECT_EQ(frames_outside_animation(s, spec, {40, 49, 50, 51}, true), "");  // --frames all
  spec.animation = 1;
  spec.animation_label = "Run";
  EXPECT_EQ(frames_outside_animation(s, spec, {3, 12, 30}, false),
            "frames 3,30 lie outside the animation 'Run' (frames 12:24 at 24 fps): they repeat its first or last pose");
  spec.turntable = true, spec.turntable_deg = 360, spec.turntable_frames = 8;
  EXPECT_EQ(frames_outside_animation(s, spec, {3}, false),
            "frame 3 lies outside the animation 'Run' (frames 12:24 at 24 fps): it repeats its first pose (the "
            "turntable still turns)");
  spec.animation = kAllAnimations;
  spec.animation_label = "all";
  EXPECT_NE(frames_outside_animation(s, spec, {60}, false).find("the animations (all) (frames 0:48"),
            std::string::npos);
  // no animation: a still scene or a turntable alone never warns
  spec.animation = kNoAnimation;
  EXPECT_EQ(frames_outside_animation(s, spec, {0, 1000}, false), "");
  // long lists are summarized
  std::vector<long> many;
  for (long f = 100; f < 400; f += 3) many.push_back(f), many.push_back(f + 1);
  spec.animation = 0;
  EXPECT_NE(frames_outside_animation(s, spec, many, false).find("200 frames between 100 and 398"), std::string::npos);
}

// On the command line: one warning per run, none for --frames all or a turntable without animation.
TEST(RangeWarning, OncePerRunNeverForFramesAll) {
  const std::string dir = temp_dir("range_warning");
  fs::create_directories(dir);
  // one triangle sliding along +X from 0 to 1 s ("Slide": frames 0:24 at 24 fps)
  {
    const float data[] = {0, 0, 0, 1, 0, 0, 0, 1, 0,  // positions
                          0, 1,                       // key times
                          0, 0, 0, 1, 0, 0};          // translations
    std::ofstream(dir + "/anim.bin", std::ios::binary).write(reinterpret_cast<const char*>(data), sizeof data);
  }
  std::ofstream(dir + "/anim.gltf") << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"uri": "anim.bin", "byteLength": 68}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 44, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                  {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"}],
    "animations": [{"name": "Slide", "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                    "samplers": [{"input": 1, "output": 2}]}]})";
  const std::string scene = " '" + dir + "/anim.gltf' --views 4 --view-size 64x32 --display 240x135 ";
  CliRun r = run("render --frames 23:26" + scene + "--out " + dir + "/a");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count(r.output, "outside the animation"), 1u) << r.output;
  EXPECT_NE(r.output.find("pmr: warning: frames 25:26 lie outside the animation 'Slide' (frames 0:24 at 24 fps): they "
                          "repeat its last pose"),
            std::string::npos)
      << r.output;
  r = run("render --frames all" + scene + "--out " + dir + "/b");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count(r.output, "outside"), 0u) << r.output;
  EXPECT_TRUE(test::exists(dir + "/b/frame_0024.json"));
  r = run("render --frames 0:2" + scene + "--out " + dir + "/c");
  EXPECT_EQ(count(r.output, "outside"), 0u) << r.output;
  // the default scene has no animation: a turntable past one turn keeps turning, no warning
  r = run("render --frames 7:9" + kSmall + "--out " + dir + "/d");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count(r.output, "outside"), 0u) << r.output;
}

}  // namespace pmr
