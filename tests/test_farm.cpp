// Render-farm pieces that need no scheduler: the shard arithmetic for every scheduler's array
// environment (each frame to exactly one task), and `pmr verify` on broken folders.
#include <gtest/gtest.h>

#include <regex>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>

#include <filesystem>
#include <fstream>
#include <cstdio>
#include <map>
#include <sstream>

#include <xxhash.h>

#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "pmr/output.h"
#include "sequence/frame_list.h"
#include "sequence/shard.h"
#include "test_util.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

using Env = std::map<std::string, std::string>;

ProcessEnvironment from(const Env& env) {
  return [env](const char* name) -> const char* {
    auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  };
}

// Every task of an array (ids as the scheduler numbers them) with its environment: the union of their
// shares is every frame exactly once, in interleaved order.
void expect_partition(const std::vector<Env>& tasks, const std::vector<long>& frames, long count = 0, long first = 0) {
  std::map<long, int> seen;
  for (const Env& env : tasks) {
    const Shard s = parse_shard("auto", count, first, from(env));
    EXPECT_EQ(s.count, long(tasks.size()));
    for (long f : shard_frames(frames, s)) ++seen[f];
  }
  ASSERT_EQ(seen.size(), frames.size());
  for (const auto& [f, n] : seen) EXPECT_EQ(n, 1) << "frame " << f;
}

std::vector<long> range(long a, long b) {
  std::vector<long> v;
  for (long f = a; f <= b; ++f) v.push_back(f);
  return v;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// XXH3-64 of a file as xxhsum -H3 prints it (the library directly, not pmr's checksum code).
std::string xxh3(const std::string& path) {
  const std::string bytes = read_file(path);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)XXH3_64bits(bytes.data(), bytes.size()));
  return hex;
}

// The byte offset of a single-part EXR's chunk table: after magic, version and the header's attributes
// (name, type name, 32-bit size, value), which end with an empty name.
size_t exr_chunk_table_offset(const std::string& b) {
  size_t at = 8;
  auto cstr = [&] {
    const size_t end = b.find('\0', at);
    const std::string s = b.substr(at, end - at);
    at = end + 1;
    return s;
  };
  while (!cstr().empty()) {
    cstr();
    uint32_t size = 0;
    for (int k = 0; k < 4; ++k) size |= uint32_t(uint8_t(b[at + size_t(k)])) << (8 * k);
    at += 4 + size;
  }
  return at;
}

void put64(std::string& b, size_t at, uint64_t v) {
  for (int k = 0; k < 8; ++k) b[at + size_t(k)] = char(v >> (8 * k));
}

}  // namespace

TEST(Shard, ExplicitSharesAreInterleaved) {
  const std::vector<long> frames = parse_frame_list("10:19");
  EXPECT_EQ(shard_frames(frames, parse_shard("1/3", 0, 0, from({}))), (std::vector<long>{11, 14, 17}));
  EXPECT_TRUE(shard_frames({1, 2}, parse_shard("4/5", 0, 0, from({}))).empty());  // more shards than frames
  for (const char* bad : {"3/3", "-1/2", "1", "a/b", "1/0", "2/"})
    EXPECT_THROW(parse_shard(bad, 0, 0, from({})), Error) << bad;
}

TEST(Shard, EverySchedulersArrayCoversEveryFrameOnce) {
  const std::vector<long> frames = range(0, 16);  // 17 frames over 4 tasks: uneven shares
  std::vector<Env> slurm, slurm_step, k8s, aws, sge, lsf, lsf5, pbs, torque;
  for (int t = 0; t < 4; ++t) {
    // Slurm --array=3-6 (first index other than 0 or 1), and --array=0-12:4 with a step
    slurm.push_back({{"SLURM_ARRAY_TASK_ID", std::to_string(3 + t)},
                     {"SLURM_ARRAY_TASK_MIN", "3"},
                     {"SLURM_ARRAY_TASK_MAX", "6"},
                     {"SLURM_ARRAY_TASK_COUNT", "4"}});
    slurm_step.push_back({{"SLURM_ARRAY_TASK_ID", std::to_string(4 * t)},
                          {"SLURM_ARRAY_TASK_MIN", "0"},
                          {"SLURM_ARRAY_TASK_MAX", "12"},
                          {"SLURM_ARRAY_TASK_STEP", "4"}});
    k8s.push_back({{"JOB_COMPLETION_INDEX", std::to_string(t)}});
    aws.push_back({{"AWS_BATCH_JOB_ARRAY_INDEX", std::to_string(t)}, {"AWS_BATCH_JOB_ARRAY_SIZE", "4"}});
    sge.push_back({{"SGE_TASK_ID", std::to_string(2 + 3 * t)},
                   {"SGE_TASK_FIRST", "2"},
                   {"SGE_TASK_LAST", "11"},
                   {"SGE_TASK_STEPSIZE", "3"}});
    lsf.push_back({{"LSB_JOBINDEX", std::to_string(1 + t)}, {"LSB_JOBINDEX_END", "4"}});
    lsf5.push_back({{"LSB_JOBINDEX", std::to_string(5 + t)}, {"LSB_JOBINDEX_END", "8"}});
    pbs.push_back({{"PBS_ARRAY_INDEX", std::to_string(1 + t)}});
    torque.push_back({{"PBS_ARRAYID", std::to_string(t)}});
  }
  expect_partition(slurm, frames);
  expect_partition(slurm_step, frames);
  expect_partition(k8s, frames, 4);
  expect_partition(aws, frames);
  expect_partition(sge, frames);
  expect_partition(lsf, frames);
  expect_partition(lsf5, frames, 0, 5);  // bsub -J "r[5-8]": --shard-first 5
  expect_partition(pbs, frames, 4, 1);
  expect_partition(torque, frames, 4, 0);
  // more tasks than frames: every frame still once, some tasks idle
  expect_partition(aws, range(0, 1));
}

TEST(Shard, BadEnvironmentsFailWithOneLine) {
  auto msg = [](const Env& env, long count = 0) {
    try {
      parse_shard("auto", count, 0, from(env));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_NE(msg({}).find("no array job in the environment"), std::string::npos);
  EXPECT_NE(msg({{"JOB_COMPLETION_INDEX", "2"}}).find("--shard-count"), std::string::npos);  // k8s has no count
  EXPECT_NE(msg({{"PBS_ARRAY_INDEX", "2"}}).find("--shard-count"), std::string::npos);
  EXPECT_NE(msg({{"JOB_COMPLETION_INDEX", "5"}}, 4).find("outside"), std::string::npos);
  EXPECT_NE(msg({{"AWS_BATCH_JOB_ARRAY_INDEX", "1"}, {"AWS_BATCH_JOB_ARRAY_SIZE", "4"}}, 3).find("disagrees"),
            std::string::npos);
  EXPECT_NE(msg({{"SLURM_ARRAY_TASK_ID", "5"},
                 {"SLURM_ARRAY_TASK_MIN", "0"},
                 {"SLURM_ARRAY_TASK_STEP", "4"},
                 {"SLURM_ARRAY_TASK_MAX", "12"}})
                .find("not on the array's range"),
            std::string::npos);
  EXPECT_NE(msg({{"SLURM_ARRAY_TASK_ID", "x"}}).find("not a whole number"), std::string::npos);
  // SGE outside an array job, LSF index 0: not an array
  EXPECT_NE(msg({{"SGE_TASK_ID", "undefined"}, {"LSB_JOBINDEX", "0"}}).find("no array job"), std::string::npos);
}

// pmr verify on a sequence folder: complete, then with a frame missing, an EXR cut short, a sidecar
// from another configuration; the printed list is what to resubmit, and --resume redoes exactly those.
TEST(Verify, SidecarRecordsEveryOutputsSizeAndChecksum) {
  const std::string out = test::temp_dir("verify_sums");
  ASSERT_EQ(test::run("render --frames 0:1 -q --views 4 --view-size 64x32 --display 240x135 --write encoded,quilt "
                      "--preview --out " +
                      out)
                .status,
            0);
  const nlohmann::json j = nlohmann::json::parse(read_file(out + "/frame_0001.json"));
  ASSERT_TRUE(j.contains("output_checksums")) << j.dump(2);
  EXPECT_EQ(j["output_checksums"]["algorithm"], "XXH3-64");
  const nlohmann::json& files = j["output_checksums"]["files"];
  ASSERT_EQ(files.size(), j["outputs"].size());  // every output, nothing else
  for (auto it = j["outputs"].begin(); it != j["outputs"].end(); ++it) {
    const std::string name = it.value().get<std::string>();
    ASSERT_TRUE(files.contains(name)) << name;
    EXPECT_EQ(files[name]["bytes"].get<uint64_t>(), uint64_t(fs::file_size(out + "/" + name))) << name;
    EXPECT_EQ(files[name]["checksum"].get<std::string>(), xxh3(out + "/" + name)) << name;
  }
}

// Without --frames, verify checks the frames whose sidecars the folder holds, and says that a frame
// missing altogether is not found that way; a folder without any is one error line.
TEST(Verify, WithoutFramesChecksTheFramesTheFolderHolds) {
  const std::string out = test::temp_dir("verify_no_frames");
  const std::string args = " --views 4 --view-size 64x32 --display 240x135 --turntable 360:6 --out " + out;
  ASSERT_EQ(test::run("render --frames 0:3 -q" + args).status, 0);
  fs::remove(out + "/frame_0003.json");  // frame 3 is then not a frame of the folder (its image stays)
  fs::resize_file(out + "/frame_0001.exr", fs::file_size(out + "/frame_0001.exr") / 2);
  const test::CliRun v = test::run("verify " + out);
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("no --frames: checking the 3 frame(s) the folder holds (0:2)"), std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("frame 1: frame_0001.exr is truncated"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("2 of 3 frame(s) complete"), std::string::npos) << v.output;
  const std::string empty = test::temp_dir("verify_no_frames_empty");
  fs::create_directories(empty);
  test::expect_one_error_line(test::run("verify " + empty), "holds no frame sidecars");
}

// Temporary files carry their writer's host and pid. A writer killed with SIGKILL leaves its file;
// verify names each kind of owner (this host's dead writers, this host's running ones, other hosts'
// and names from before the host was recorded), and the next run in the folder removes only this
// host's dead writers' files: on a folder shared by nodes (NFS) another host's writer may be running.
TEST(Verify, TemporaryFilesAreNamedByOwnerAndOnlyThisHostsDeadOnesRemoved) {
  const std::string out = test::temp_dir("verify_temporaries");
  const std::string args = " --views 4 --view-size 64x32 --display 240x135 --turntable 360:6 --frames 0:1 --out " + out;
  ASSERT_EQ(test::run("render -q" + args).status, 0);
  char buf[256] = {};
  ASSERT_EQ(gethostname(buf, sizeof buf - 1), 0);
  std::string host;  // as pmr records it: letters, digits, '.' and '-', others '_', at most 32 bytes
  for (const char* c = buf; *c && host.size() < 32; ++c)
    host += std::isalnum((unsigned char)*c) || *c == '.' || *c == '-' ? *c : '_';
  const pid_t dead = fork();  // a pid that no longer runs
  if (dead == 0) _exit(0);
  ASSERT_GT(dead, 0);
  waitpid(dead, nullptr, 0);
  const std::string mine_dead = ".frame_0002.exr.tmp-" + host + "-" + std::to_string(dead) + "-7",
                    mine_running = ".frame_0003.exr.tmp-" + host + "-" + std::to_string(getpid()) + "-1",
                    other = ".frame_0004.exr.tmp-node-17.farm-4242-7", old = ".frame_0005.exr.tmp-4242-7";
  for (const std::string& name : {mine_dead, mine_running, other, old}) std::ofstream(out + "/" + name) << "partial";
  const std::string v = test::run("verify " + out).output;
  EXPECT_NE(v.find("note: 1 temporary file(s) of writers on this host that no longer run (" + mine_dead +
                   "): no frame needs them, and the next pmr run in this folder on this host removes them"),
            std::string::npos)
      << v;
  EXPECT_NE(v.find("note: 1 temporary file(s) of pmr processes running on this host now (" + mine_running + ")"),
            std::string::npos)
      << v;
  EXPECT_NE(v.find("note: 2 temporary file(s) of writers on other hosts (an unrecorded host, node-17.farm: " + other +
                   ", ...): no frame needs them; remove them once no pmr process there writes into " + out),
            std::string::npos)
      << v;
  const test::CliRun again = test::run("render --resume" + args);
  EXPECT_EQ(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("removed 1 temporary file(s) that writers on this host left when they were killed"),
            std::string::npos)
      << again.output;
  EXPECT_FALSE(fs::exists(out + "/" + mine_dead));
  for (const std::string& name : {mine_running, other, old}) EXPECT_TRUE(fs::exists(out + "/" + name)) << name;
}

// The scene as it is now decides, not the folder's majority: after the scene changes, every frame is
// stale; after one shard re-renders with --resume, its frames are complete and the others are listed;
// resubmitting that list with --resume completes the folder (the loop ends).
TEST(Verify, TheSceneAsItIsNowDecidesWhichFramesAreStale) {
  const std::string dir = test::temp_dir("verify_scene_now");
  fs::create_directories(dir);
  const std::string scene = dir + "/scene.glb", out = dir + "/out";
  fs::copy_file(std::string(PMR_SOURCE_DIR) + "/data/default_scene.glb", scene);
  const std::string args = " --views 4 --view-size 64x32 --display 240x135 --turntable 360:6 -q --out " + out;
  ASSERT_EQ(test::run("render '" + scene + "' --frames 0:5" + args).status, 0);
  test::save_square_glb(scene);  // another version of the scene file
  test::CliRun v = test::run("verify " + out + " --frames 0:5");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 0: frame_0000.json was rendered from another version of the scene (scene.glb "
                          "differs now)"),
            std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("0 of 6 frame(s) complete"), std::string::npos) << v.output;
  ASSERT_EQ(test::run("render '" + scene + "' --frames 0:5 --shard 0/3 --resume" + args).status, 0);  // 0, 3
  v = test::run("verify " + out + " --frames 0:5");
  EXPECT_NE(v.output.find("2 of 6 frame(s) complete"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("\n1:2,4:5\n"), std::string::npos) << v.output;
  ASSERT_EQ(test::run("render '" + scene + "' --frames 1:2,4:5 --resume" + args).status, 0);
  EXPECT_EQ(test::run("verify " + out + " --frames 0:5").status, 0);
}

// A sidecar is parsed only within the memory budget (parsed JSON takes about a hundred times its text):
// a 10 MB one under --limit memory=256M stops verify in one line before parsing it; --resume counts
// that frame as unreadable and renders it again.
TEST(Verify, SidecarsAreParsedWithinTheMemoryBudget) {
  const std::string out = test::temp_dir("verify_sidecar_budget");
  const std::string args = " --views 4 --view-size 64x32 --display 240x135 --out " + out;
  ASSERT_EQ(test::run("render --frames 0:1 -q" + args).status, 0);
  std::string numbers = "[";
  for (int i = 0; i < 5000000; ++i) numbers += "0,";
  numbers += "0]";
  std::ofstream(out + "/frame_0001.json") << numbers;
  test::expect_one_error_line(test::run("verify " + out + " --frames 0:1 --limit memory=256M"),
                              "out of memory: parsing the sidecar frame_0001.json (10000003 bytes)");
  const test::CliRun r = test::run("render --frames 0:1 --resume --limit memory=256M" + args);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("1 frame(s) in"), std::string::npos) << r.output;
  EXPECT_EQ(test::run("verify " + out + " --frames 0:1").status, 0);
}

TEST(Verify, QuickCheckFindsChangedAndDamagedFilesWithoutDecoding) {
  const std::string out = test::temp_dir("verify_quick");
  const std::string args = " --views 4 --view-size 64x32 --display 240x135 --turntable 360:6 --out " + out;
  ASSERT_EQ(test::run("render --frames 0:5 -q" + args).status, 0);
  // frame 5: frame 1's whole image copied over it, a smaller file: another file, not a truncated one
  ASSERT_LT(fs::file_size(out + "/frame_0001.exr"), fs::file_size(out + "/frame_0005.exr"));
  write_file(out + "/frame_0005.exr", read_file(out + "/frame_0001.exr"));
  // frame 1: one byte of the first chunk's pixel data changed, size and chunk table intact
  std::string b = read_file(out + "/frame_0001.exr");
  {
    const size_t t = exr_chunk_table_offset(b);
    size_t first = 0;
    for (int k = 0; k < 8; ++k) first |= size_t(uint8_t(b[t + size_t(k)])) << (8 * k);
    b[first + 8 + 20] = char(b[first + 8 + 20] ^ 0x10);  // after its y and size
  }
  write_file(out + "/frame_0001.exr", b);
  // frame 2: a chunk-table entry past the end of the file, and the sidecar's record updated to match,
  // so that only the structure check can see it
  b = read_file(out + "/frame_0002.exr");
  put64(b, exr_chunk_table_offset(b) + 8, uint64_t(b.size()) + 1000);
  write_file(out + "/frame_0002.exr", b);
  nlohmann::json j = nlohmann::json::parse(read_file(out + "/frame_0002.json"));
  j["output_checksums"]["files"]["frame_0002.exr"]["checksum"] = xxh3(out + "/frame_0002.exr");
  write_file(out + "/frame_0002.json", j.dump(2));
  // frame 3: two chunk-table entries pointing at the same chunk (overlap), record updated
  b = read_file(out + "/frame_0003.exr");
  {
    const size_t t = exr_chunk_table_offset(b);
    uint64_t first = 0;
    for (int k = 0; k < 8; ++k) first |= uint64_t(uint8_t(b[t + size_t(k)])) << (8 * k);
    put64(b, t + 8, first);
  }
  write_file(out + "/frame_0003.exr", b);
  j = nlohmann::json::parse(read_file(out + "/frame_0003.json"));
  j["output_checksums"]["files"]["frame_0003.exr"]["checksum"] = xxh3(out + "/frame_0003.exr");
  write_file(out + "/frame_0003.json", j.dump(2));
  // frame 4: cut short
  fs::resize_file(out + "/frame_0004.exr", fs::file_size(out + "/frame_0004.exr") - 1);
  test::CliRun v = test::run("verify " + out + " --frames 0:5");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 1: frame_0001.exr is not the file its sidecar records (its checksum differs)"),
            std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("frame 2: frame_0002.exr is truncated or damaged"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("frame 3: frame_0003.exr"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("frame 4: frame_0004.exr is truncated"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("frame 5: frame_0005.exr is not the file its sidecar records"), std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("\n1:5\n"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("1 of 6 frame(s) complete"), std::string::npos) << v.output;
  // --resume renders exactly those frames again
  test::CliRun r = test::run("render --frames 0:5 --resume" + args);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("5 frame(s) in"), std::string::npos) << r.output;
  EXPECT_EQ(test::run("verify " + out + " --frames 0:5").status, 0);
}

TEST(Verify, DeepDecodesEveryPixelAndOldSidecarsAreDecoded) {
  const std::string out = test::temp_dir("verify_deep");
  const std::string args = " --views 4 --view-size 64x32 --display 240x135 --turntable 360:3 --out " + out;
  ASSERT_EQ(test::run("render --frames 0:2 -q" + args).status, 0);
  // frame 1: compressed data garbled, the record updated: whole to the quick check, not to a decode
  std::string b = read_file(out + "/frame_0001.exr");
  const size_t t = exr_chunk_table_offset(b);
  for (size_t i = t + 2000; i < t + 2400 && i < b.size(); ++i) b[i] = char(0x5a);
  write_file(out + "/frame_0001.exr", b);
  nlohmann::json j = nlohmann::json::parse(read_file(out + "/frame_0001.json"));
  j["output_checksums"]["files"]["frame_0001.exr"]["checksum"] = xxh3(out + "/frame_0001.exr");
  write_file(out + "/frame_0001.json", j.dump(2));
  EXPECT_EQ(test::run("verify " + out + " --frames 0:2").status, 0);
  test::CliRun v = test::run("verify " + out + " --frames 0:2 --deep");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 1: frame_0001.exr is truncated or unreadable"), std::string::npos) << v.output;
  // a sidecar without checksums (an older pmr): its images are decoded
  j.erase("output_checksums");
  write_file(out + "/frame_0001.json", j.dump(2));
  v = test::run("verify " + out + " --frames 0:2");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 1: frame_0001.exr is truncated or unreadable"), std::string::npos) << v.output;
  j = nlohmann::json::parse(read_file(out + "/frame_0002.json"));
  j.erase("output_checksums");
  write_file(out + "/frame_0002.json", j.dump(2));
  v = test::run("verify " + out + " --frames 0:2");
  EXPECT_NE(v.output.find("2 of 3 frame(s) complete"), std::string::npos) << v.output;
}

// A frame missing from a quilt sequence, re-rendered alone (--frames 5 --resume, what verify's list
// says to resubmit) or in a list, keeps the sequence's names: the folder's sidecars decide, not the
// command line's single frame number. The sequence readers (frame_qs..._NNNN) then see every frame.
TEST(Verify, AFrameRenderedAgainKeepsTheSequencesNames) {
  const std::string out = test::temp_dir("verify_names");
  const std::string args =
      " -q --turntable 360:12 --views 4 --view-size 32x32 --display 120x68 --write quilt --out " + out;
  ASSERT_EQ(test::run("render --frames 0:11" + args).status, 0);
  auto sequence_quilts = [&] {
    size_t n = 0, stills = 0;
    for (const auto& e : fs::directory_iterator(out)) {
      const std::string name = e.path().filename().string();
      n += std::regex_match(name, std::regex(R"(frame_qs2x2a[0-9.]+_[0-9]{4}\.exr)"));
      stills += std::regex_match(name, std::regex(R"(frame_[0-9]{4}_qs.*\.exr)"));
    }
    EXPECT_EQ(stills, 0u) << "a still's name among a sequence's";
    return n;
  };
  ASSERT_EQ(sequence_quilts(), 12u);
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().filename().string().find("0005") != std::string::npos) fs::remove(e.path());
  const test::CliRun v = test::run("verify " + out + " --frames 0:11 --write quilt");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("\n5\n"), std::string::npos) << v.output;
  const test::CliRun one = test::run("render --frames 5 --resume" + args.substr(3));  // without -q: the note
  ASSERT_EQ(one.status, 0) << one.output;
  EXPECT_NE(one.output.find("quilts are named as a sequence's"), std::string::npos) << one.output;
  EXPECT_EQ(sequence_quilts(), 12u);
  // --print-outputs names the same files
  const test::CliRun listed = test::run("render --frames 5 --print-outputs" + args);
  EXPECT_NE(listed.output.find("frame_qs2x2a"), std::string::npos) << listed.output;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name.find("0003") != std::string::npos || name.find("0007") != std::string::npos) fs::remove(e.path());
  }
  ASSERT_EQ(test::run("render --frames 3,7 --resume" + args).status, 0);
  EXPECT_EQ(sequence_quilts(), 12u);
  EXPECT_EQ(test::run("verify " + out + " --frames 0:11 --write quilt").status, 0);
}

// Frames of two configurations in one folder (a shard run without --preset overwrote some): verify
// names both groups with their frames and main settings, judges the frames against the larger, names
// its settings in the advice, and says which group has the settings given to it.
TEST(Verify, AMixedFolderIsReportedGroupByGroup) {
  const std::string out = test::temp_dir("verify_mixed");
  const std::string common = " -q --turntable 360:6 --views 4 --write quilt --out " + out;
  ASSERT_EQ(test::run("render --frames 0:5 --preset lg-portrait --view-size 30x40" + common).status, 0);
  ASSERT_EQ(test::run("render --frames 2,4 --preset paper-8k --view-size 64x32 --overwrite" + common).status, 0);
  const test::CliRun v = test::run("verify " + out + " --frames 0:5");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frames of 2 configurations"), std::string::npos) << v.output;
  const size_t portrait = v.output.find("preset lg-portrait, 1536x2048 display, 4 views of 30x40");
  const size_t paper = v.output.find("preset paper-8k, 7680x4320 display, 4 views of 64x32");
  ASSERT_NE(portrait, std::string::npos) << v.output;
  ASSERT_NE(paper, std::string::npos) << v.output;
  const std::string portrait_line = v.output.substr(portrait, v.output.find('\n', portrait) - portrait);
  EXPECT_NE(portrait_line.find("the largest"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("with the folder's configuration (preset lg-portrait"), std::string::npos) << v.output;
  EXPECT_NE(v.output.find("\n2,4\n"), std::string::npos) << "the paper-8k frames to redo: " << v.output;
  const test::CliRun asked = test::run("verify " + out + " --frames 0:5 --preset paper-8k");
  const size_t at = asked.output.find("preset paper-8k, 7680x4320");
  ASSERT_NE(at, std::string::npos) << asked.output;
  const std::string paper_line = asked.output.substr(at, asked.output.find('\n', at) - at);
  EXPECT_NE(paper_line.find("matches the settings given"), std::string::npos) << asked.output;
  EXPECT_EQ(asked.output.find("matches the settings given"), asked.output.rfind("matches the settings given"))
      << "one group only: " << asked.output;
}

TEST(Verify, ReportsMissingAndBrokenFramesAsAFramesList) {
  const std::string out = test::temp_dir("verify");
  const std::string args = " --turntable 360:8 --views 4 --view-size 64x32 --display 240x135 --out " + out;
  ASSERT_EQ(test::run("render --frames 0:7 -q" + args).status, 0);
  test::CliRun v = test::run("verify " + out + " --frames 0:7");
  EXPECT_EQ(v.status, 0) << v.output;
  EXPECT_NE(v.output.find("8 of 8 frame(s) complete"), std::string::npos) << v.output;
  fs::remove(out + "/frame_0002.exr");
  {  // truncate frame 4's image
    const std::string p = out + "/frame_0004.exr";
    const auto size = fs::file_size(p);
    fs::resize_file(p, size / 2);
  }
  // a damaged but parseable sidecar (frame 1): reported, not a crash
  std::ofstream(out + "/frame_0001.json") << R"({"frame": 1, "fps": 24, "time": 0.041666666666666664})";
  v = test::run("verify " + out + " --frames 0:7");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("frame 1: frame_0001.json was rendered with another configuration"), std::string::npos)
      << v.output;
  ASSERT_EQ(test::run("render --frames 1 -q" + args).status, 0);
  // frame 6 rendered again at another fps: another configuration (--overwrite: the other frames stay
  // in the first one)
  ASSERT_EQ(test::run("render --frames 6 -q --fps 30 --overwrite" + args).status, 0);
  v = test::run("verify " + out + " --frames 0:7");
  EXPECT_EQ(v.status, 1) << v.output;
  EXPECT_NE(v.output.find("2:6:2\n"), std::string::npos) << v.output;  // frames 2, 4, 6
  EXPECT_NE(v.output.find("frame 4: frame_0004.exr is truncated"), std::string::npos) << v.output;
  // the values, and advice that works (--resume refuses another configuration)
  EXPECT_NE(v.output.find("frame 6: frame_0006.json was rendered with another configuration (fps differs: fps 30"),
            std::string::npos)
      << v.output;
  EXPECT_NE(v.output.find("with the folder's configuration (preset paper-8k, 240x135 display, 4 views of 64x32) and "
                          "--overwrite"),
            std::string::npos)
      << v.output;
  // --resume redoes the missing and truncated frames (the other configuration needs --overwrite)
  test::CliRun r = test::run("render --frames 0:7 --resume --overwrite" + args);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("3 frame(s) in"), std::string::npos) << r.output;
  EXPECT_EQ(test::run("verify " + out + " --frames 0:7").status, 0);
  test::expect_usage_error(test::run("verify " + out + " --frames all"), "--frames");
  test::expect_one_error_line(test::run("verify /nonexistent --frames 0"), "not a folder");
}

}  // namespace pmr
