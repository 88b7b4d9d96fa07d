// Exit codes and what exists after a refusal (issue 21): 0 success, 1 bad input or runtime error or out
// of memory, 2 usage, 128 + N for signal N; nothing is created before the inputs have been checked,
// and a --name too long for the file system fails before the first frame.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <set>
#include <cstring>
#include <new>
#include <stdexcept>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "cli/exit_status.h"
#include "gltf_builder.h"
#include "pmr/error.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::CliRun;
using test::exists;
using test::expect_one_error_line;
using test::expect_usage_error;
using test::run;
using test::temp_dir;

const char* const kSmall = " --view-size 32x16 --display 64x36 --views 4";

TEST(ExitCodes, UsageErrorsExitTwo) {
  const std::string out = temp_dir("usage") + "/out";
  expect_usage_error(run("frobnicate"), "unknown command");
  expect_usage_error(run("render --frobnicate --out " + out), "--frobnicate");
  expect_usage_error(run("render --views --out " + out), "--views");  // "--out" is not a count
  expect_usage_error(run("render --views 0 --out " + out), "--views");
  expect_usage_error(run("render --out"), "--out needs a value");
  expect_usage_error(run("render --yfov 0 --out " + out), "--yfov");
  expect_usage_error(run("render --yfov 180 --out " + out), "--yfov");
  expect_usage_error(run("render --compression lzma --out " + out), "lzma");
  expect_usage_error(run("render --compression dwaa --out " + out), "encoded image");  // encoded by default
  expect_usage_error(run("render --compression dwab --write quilt,encoded --out " + out), "crosstalk");
  expect_usage_error(run("render --frames 5:1 --out " + out), "5:1");
  expect_usage_error(run("render --preset lg-99 --out " + out), "lg-99");
  expect_usage_error(run("render --limit bogus=1 --out " + out), "bogus");
  expect_usage_error(run("render --preset lg-go --preset lg-16 --out " + out), "one of --preset");
  expect_usage_error(run("render --cone 180 --out " + out), "--cone");
  expect_usage_error(run("render --environment env.hdr --shading lambert --out " + out), "--shading pbr");
  expect_usage_error(run("render --quilt 4x1 --out " + out + kSmall), "--quilt needs --write quilt");
  expect_usage_error(run("info --frobnicate"), "--frobnicate");
  expect_usage_error(run("info --limit file-bytes=0 x.gltf"), "file-bytes");
  expect_usage_error(run("verify"), "needs the output folder");
  expect_usage_error(run("verify " + out + " --frames x"), "x");
  expect_usage_error(run("render --blend-views --bilinear --out " + out + kSmall), "--blend-views");
  expect_usage_error(run("render --shard 3/2 --out " + out + kSmall), "--shard");
  // outside an array job: the command, not the input, is wrong (tests never run inside one)
  expect_usage_error(run("render --shard auto --out " + out + kSmall), "no array job");
  expect_usage_error(run("bench --keep always"), "--keep");
  expect_usage_error(run("quality --scale 1"), "--scale");
  EXPECT_EQ(run("").status, 2) << "no command: the usage text, status 2";
  EXPECT_FALSE(exists(out));
}

TEST(ExitCodes, BadInputExitsOne) {
  const std::string dir = temp_dir("badinput");
  const std::string out = dir + "/out";
  expect_one_error_line(run("render /nonexistent/scene.gltf --out " + out), "scene.gltf");
  expect_one_error_line(run("render --display-config /nonexistent/visual.json --out " + out), "visual.json");
  expect_one_error_line(run("info /nonexistent/scene.gltf"), "file not found");
  // --camera beyond the scene's cameras depends on the scene: bad input, not usage
  expect_one_error_line(run("render --camera '#3' --out " + out + kSmall), "--camera '#3'");
  EXPECT_FALSE(exists(out));
  EXPECT_EQ(run("render --out " + out + kSmall + " -q").status, 0);
}

// The mapping itself, for the status no input should reach: a pmr::InternalError, or an exception that
// is not a pmr::Error, is a bug, reported as an internal error with status 3 (and its message sanitized
// like every other).
TEST(ExitCodes, EachKindOfFailureHasItsStatus) {
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_reporting_errors([] { return 0; }), 0);
  EXPECT_EQ(run_reporting_errors([] { return 7; }), 7) << "a command's own status passes through";
  EXPECT_EQ(run_reporting_errors([]() -> int { throw Error("bad input"); }), 1);
  EXPECT_EQ(run_reporting_errors([]() -> int { throw UsageError("bad option"); }), 2);
  EXPECT_EQ(run_reporting_errors([]() -> int { throw std::bad_alloc(); }), 1) << "out of memory is not a bug";
  EXPECT_EQ(run_reporting_errors([]() -> int { throw std::logic_error("vector::at \x1b]0;owned\x07"); }), 3);
  EXPECT_EQ(run_reporting_errors([]() -> int { throw 42; }), 3);
  EXPECT_EQ(run_reporting_errors([]() -> int { throw InternalError("an invariant \x1b[2J broke"); }), 3);
  // as_usage turns a parser's pmr::Error into a usage error, never a bug
  EXPECT_EQ(run_reporting_errors([]() -> int { return as_usage([]() -> int { throw InternalError("in a parser"); }); }),
            3);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("pmr: internal error: vector::at"), std::string::npos) << err;
  EXPECT_NE(err.find("\npmr: internal error: an invariant"), std::string::npos) << "the prefix once: " << err;
  EXPECT_NE(err.find("\npmr: internal error: in a parser\n"), std::string::npos) << err;
  EXPECT_EQ(err.find("internal error: internal error"), std::string::npos) << err;
  EXPECT_EQ(err.find('\x1b'), std::string::npos) << "escape sequences reach the terminal: " << err;
}

// An internal error through the real binary (forced by its test hook, as no input should cause one):
// status 3, one line saying it is an internal error, and no output folder.
TEST(ExitCodes, InternalErrorExitsThreeAndWritesNothing) {
  const std::string dir = temp_dir("internal"), out = dir + "/out";
  const CliRun r = test::run_env("PMR_TEST_FORCE_INTERNAL_ERROR=render-options", "render --out " + out + kSmall);
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_EQ(r.output.rfind("pmr: internal error: ", 0), 0u) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "exactly one line: " << r.output;
  EXPECT_FALSE(exists(out));
  EXPECT_FALSE(exists(dir)) << "not even the folder above --out";
  // the hook names its stage: another name does not fire, and the same command then renders
  const CliRun other = test::run_env("PMR_TEST_FORCE_INTERNAL_ERROR=no-such-stage", "render -q --out " + out + kSmall);
  EXPECT_EQ(other.status, 0) << other.output;
  EXPECT_TRUE(exists(out));
}

// A render stopped by SIGTERM, SIGHUP (a closed terminal or SSH session), SIGALRM, SIGXCPU (a CPU-time
// limit) or SIGUSR1 / SIGUSR2 (a scheduler's warning before its kill) exits 128 + the signal, as SIGINT exits 130 (test_sequence), leaving whole frames only: every image on disk has its
// sidecar, and no temporary file is left.
TEST(ExitCodes, SignalNExits128PlusN) {
  for (int sig : {SIGTERM, SIGHUP, SIGALRM, SIGXCPU, SIGUSR1, SIGUSR2}) {
    SCOPED_TRACE(strsignal(sig));
    const std::string out = temp_dir("signal_" + std::to_string(sig));
    const pid_t pid = test::start(
        "render -q --turntable 360:50 --frames 0:49 --views 16 --view-size 256x128 "
        "--display 640x360 --out " +
        out);
    ASSERT_GE(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline && !exists(out + "/frame_0000.json"))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    kill(pid, sig);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    if (WEXITSTATUS(status) != 0) {  // a very fast machine may have finished all 50 frames first
      EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    }
    for (const std::string& name : test::listing(out)) {
      EXPECT_EQ(name[0] == '.', false) << "left behind: " << name;
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".exr") == 0) {
        EXPECT_TRUE(exists(out + "/" + name.substr(0, name.size() - 4) + ".json")) << name << " has no sidecar";
      }
    }
  }
}

// `quads` full-view quads stacked in depth, each half transparent (alphaMode BLEND): at paper-8k, a
// frame of a few hundred takes minutes (every quad is a layer of every sample of every view).
std::string write_stacked_blend_quads(const std::string& dir, int quads) {
  using namespace test::gltf_builder_detail;
  GltfFile g;
  std::vector<float> pos;
  std::vector<uint32_t> idx;
  for (int q = 0; q < quads; ++q) {
    const float z = -0.5f + float(q) / float(quads);
    using Corner = std::array<float, 2>;
    for (const Corner& c : {Corner{-1, -1}, Corner{1, -1}, Corner{1, 1}, Corner{-1, 1}})
      pos.insert(pos.end(), {c[0], c[1], z});
    for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) idx.push_back(uint32_t(4 * q) + k);
  }
  const int p = g.data(pos, kFloat, "VEC3"), i = g.data(idx, kUInt, "SCALAR");
  g.add("materials", {{"alphaMode", "BLEND"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 0.2, 0.5}}}}});
  g.mesh(nlohmann::json::array({{{"attributes", {{"POSITION", p}}}, {"indices", i}, {"material", 0}}}));
  g.add("nodes", {{"mesh", 0}});
  g.scene({0});
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/stacked.glb";
  write_bytes(path, g.glb());
  return path;
}

// The first SIGTERM ends a run within 2 s whatever it is doing: here a paper-8k frame of minutes,
// whose kernels never look at the flag. It exits 143 as a second signal would: no temporary file, no
// image, and no lock left in the folder.
TEST(ExitCodes, TheFirstSignalEndsALongFrameWithinTwoSeconds) {
  const std::string dir = temp_dir("long_frame"), out = dir + "/out";
  const std::string scene = write_stacked_blend_quads(dir, 200);
  // (shadows off: the studio's shadowed boxes would make the frame-work estimate refuse this frame)
  const pid_t pid = test::start("render " + scene + " -q --shadows off --out " + out);
  ASSERT_GE(pid, 0);
  // the run has its lock (the frame is set up next), then 5 s for the kernels to start
  auto locked = [&] {
    if (!exists(out)) return false;
    for (const std::string& name : test::listing(out))
      if (name.rfind(".pmr-lock-", 0) == 0) return true;
    return false;
  };
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < give_up && !locked())
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(locked()) << "the render never took its lock";
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const auto sent = std::chrono::steady_clock::now();
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  EXPECT_LT(seconds, 2.0 + 1.0) << "1.5 s by design, and a margin for a loaded machine";
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  if (exists(out)) {
    EXPECT_EQ(test::listing(out), std::set<std::string>()) << "nothing left: no image, temporary or lock";
  }
  std::filesystem::remove_all(dir);
}

// A closed pipe (`pmr render ... 2>&1 | head -1`) does not kill the render: it finishes every frame and
// exits 0, its later messages lost.
TEST(ExitCodes, AClosedPipeDoesNotStopTheRender) {
  const std::string out = temp_dir("sigpipe");
  const std::string cmd = "bash -c 'set -o pipefail; " + std::string(PMR_BINARY) +
                          " render --frames 0:5 --turntable 360:6 --out " + out + kSmall +
                          " 2>&1 | head -1 > /dev/null'";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  for (int f = 0; f < 6; ++f) EXPECT_TRUE(exists(out + "/frame_000" + std::to_string(f) + ".exr")) << f;
  for (const std::string& name : test::listing(out)) EXPECT_NE(name[0], '.') << "left behind: " << name;
}

// A file-size limit smaller than a frame (ulimit -f): one error line naming the file, exit 1, no partial
// file and no lock left (the write fails instead of SIGXFSZ killing the process).
TEST(ExitCodes, AFileSizeLimitIsAnErrorNotACrash) {
  const std::string out = temp_dir("fsize");
  const std::string big = " --views 32 --view-size 1024x256 --display 320x180 --write views";
  const CliRun warm = run("render --frames 0 --out " + out + "/warm" + big);  // the kernel cache, written first
  ASSERT_EQ(warm.status, 0) << warm.output;
  const CliRun r = test::run_wrapped("prlimit --fsize=3000000", "render -q --frames 0 --out " + out + "/x" + big);
  if (r.output.find("LLVM ERROR") != std::string::npos)
    GTEST_SKIP() << "the OpenCL compiler itself wrote a file beyond the limit: " << r.output;
  expect_one_error_line(r, "file size limit reached (File too large");
  // (the run made the folder; refused before any frame was complete, it removes it again)
  if (exists(out + "/x"))
    for (const std::string& name : test::listing(out + "/x")) ADD_FAILURE() << "left behind: " << name;
}

TEST(ExitCodes, NothingIsCreatedBeforeTheInputsAreChecked) {
  const std::string dir = temp_dir("nothing_created");
  const std::string out = dir + "/a/b/out";
  std::system(("mkdir -p '" + dir + "'").c_str());
  std::ofstream(dir + "/broken.gltf") << "{ \"asset\": {\"version\": \"2.0\"}, \"buffers\": [ {";
  expect_one_error_line(run("render '" + dir + "/broken.gltf' --out " + out + kSmall), "broken.gltf");
  EXPECT_FALSE(exists(dir + "/a")) << "the output folder was created for a scene that does not load";
  std::ofstream(dir + "/bad.hdr") << "not an image";
  expect_one_error_line(run("render --shading pbr --environment '" + dir + "/bad.hdr' --out " + out + kSmall),
                        "bad.hdr");
  EXPECT_FALSE(exists(dir + "/a"));
  // a folder below a regular file is refused at once, before the scene is read
  std::ofstream(dir + "/file") << "x";
  expect_one_error_line(run("render '" + dir + "/broken.gltf' --out '" + dir + "/file/sub'" + kSmall),
                        "is not a folder");
}

// File names hold 255 bytes; pmr writes each file under a temporary name first (60 bytes longer at
// most), so the longest --name is checked against that before anything is rendered or created.
TEST(ExitCodes, NameTooLongForTheFileSystemFailsBeforeRendering) {
  const std::string out = temp_dir("long_name") + "/out";
  const std::string name(244, 'n');
  const CliRun r = run("render --name " + name + " --out " + out + kSmall);
  expect_usage_error(r, "invalid --name");
  EXPECT_NE(r.output.find(name + ".json of 249 bytes"), std::string::npos) << r.output;
  EXPECT_FALSE(exists(out));
  // the longest suffix decides: with --write views the views file is 5 bytes longer than the sidecar
  // + ".json" = 195 bytes, the most pmr can write: 255 less its temporary name's 60 more (".", ".tmp-",
  // 32 bytes of host name, "-", 10 digits of pid, "-", 10 of counter)
  const std::string fits(190, 'n');
  const CliRun ok = run("render -q --name " + fits + " --out " + out + kSmall);
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(exists(out + "/" + fits + ".json"));
  const CliRun views = run("render --write views --name " + fits + " --out " + out + "2" + kSmall);
  expect_usage_error(views, fits + ".views.exr of 200 bytes");
  EXPECT_FALSE(exists(out + "2"));
}

}  // namespace
}  // namespace pmr
