// File names and terminal output as a user types them: --name with %d, %0Nd, Blender's #### or no
// frame field at all (a single frame), refused spellings in one line with an example, -o, --quiet.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "cli/options.h"
#include "sequence/frame_names.h"
#include "pmr/error.h"
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

nlohmann::json sidecar(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

// The error message of a pattern parse_name_pattern refuses ("" when it accepts it).
std::string refusal(const std::string& pattern) {
  try {
    check_name_pattern(pattern);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Names, FrameFieldsAndTheirStems) {
  EXPECT_EQ(frame_stem("frame_%04d", 7), "frame_0007");
  EXPECT_EQ(frame_stem("frame_%04d", 123456), "frame_123456");  // wider than the field: every digit
  EXPECT_EQ(frame_stem("shot_%d_v2", 12), "shot_12_v2");
  EXPECT_EQ(frame_stem("shot_####", 7), "shot_0007");  // Blender: N '#' are N zero-padded digits
  EXPECT_EQ(frame_stem("s#", 7), "s7");
  EXPECT_EQ(frame_stem("a%%b%03d", 7), "a%b007");
  EXPECT_EQ(frame_stem("duck", 0), "duck");  // no field: the stem as given, for any frame
  EXPECT_EQ(frame_stem("duck", 42), "duck");
  EXPECT_EQ(frame_stem("50%%_off", 3), "50%_off");
  EXPECT_FALSE(parse_name_pattern("duck").has_field);
  EXPECT_TRUE(parse_name_pattern("d_%d").has_field);
  EXPECT_EQ(canonical_name_pattern("shot_####"), "shot_%04d");
  EXPECT_EQ(canonical_name_pattern("a%%b#"), "a%%b%01d");
  EXPECT_EQ(canonical_name_pattern("duck"), "duck");
  for (const char* ok : {"frame_%04d", "%d", "f%0d", "shot_####", "duck", "a%%b_%02d", "x#"})
    EXPECT_EQ(refusal(ok), "") << ok;
}

TEST(Names, RefusedSpellingsShowAnAcceptedExample) {
  // space-padded, other conversions, two fields, folders, empty and hidden stems
  for (const char* bad : {"shot_%4d", "shot_%x", "shot_%s", "shot_%", "%-4d", "a_%d_%d", "a_##_%d", "a/%d", "", ".h_%d",
                          "%%%5d", "f%0123d",
                          // what verify would refuse to read back: terminal controls, a backslash
                          "a\nb_%d", "a\tb_%d", "a\\b_%d", "\x1b[31m_%d", "a\x7f_%d"}) {
    const std::string why = refusal(bad);
    EXPECT_NE(why.find("invalid --name"), std::string::npos) << bad << ": " << why;
    EXPECT_NE(why.find("e.g. --name shot_%04d"), std::string::npos) << bad << ": " << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    EXPECT_EQ(why.find('\x1b'), std::string::npos) << "the name reaches the terminal sanitized: " << why;
  }
  EXPECT_NE(refusal("a\\b_%d").find("cannot contain '\\'"), std::string::npos) << refusal("a\\b_%d");
  EXPECT_NE(refusal("a\tb_%d").find("control characters"), std::string::npos) << refusal("a\tb_%d");
  EXPECT_NE(refusal("shot_%4d").find("use %04d"), std::string::npos) << refusal("shot_%4d");
  EXPECT_NE(refusal("a_%d_%d").find("more than one"), std::string::npos) << refusal("a_%d_%d");
  EXPECT_NO_THROW(check_name_covers_frames("duck", 1));
  EXPECT_NO_THROW(check_name_covers_frames("duck_%d", 2));
  EXPECT_THROW(check_name_covers_frames("duck", 2), Error);
}

// The frame number as sequence readers take it: the last run of digits in the file name without its
// extension (Blender's BLI_path_sequence_decode, fileseq, pyseq); -1 when there is none.
long last_digit_group(const std::string& file) {
  const std::string stem = file.substr(0, file.rfind('.'));
  const size_t end = stem.find_last_of("0123456789");
  if (end == std::string::npos) return -1;
  const size_t begin = stem.find_last_not_of("0123456789", end) + 1;
  return std::stol(stem.substr(begin, end + 1 - begin));
}

// A quilt's Looking Glass tag: at %q, else at the end of a still's stem, else before a sequence's frame
// number, which stays the last digit group of the file name.
TEST(Names, QuiltTagPlacement) {
  const std::string tag = "_qs8x6a0.75";
  EXPECT_EQ(quilt_file_stem("frame_%04d", 5, false, tag), "frame_0005_qs8x6a0.75");  // Looking Glass's own
  EXPECT_EQ(quilt_file_stem("frame_%04d", 5, true, tag), "frame_qs8x6a0.75_0005");
  EXPECT_EQ(quilt_file_stem("fox.####", 5, true, tag), "fox_qs8x6a0.75.0005");
  EXPECT_EQ(quilt_file_stem("shot%04d", 5, true, tag), "shot_qs8x6a0.75_0005");
  EXPECT_EQ(quilt_file_stem("a_-.%d_v", 5, true, tag), "a_qs8x6a0.75_-.5_v");
  EXPECT_EQ(quilt_file_stem("%03d", 5, true, tag), "_qs8x6a0.75_005");
  EXPECT_EQ(quilt_file_stem("duck", 5, true, tag), "duck_qs8x6a0.75");  // one frame's name
  for (bool sequence : {false, true}) {
    EXPECT_EQ(quilt_file_stem("fox%q.####", 5, sequence, tag), "fox_qs8x6a0.75.0005");
    EXPECT_EQ(quilt_file_stem("fox.%d%q", 5, sequence, tag), "fox.5_qs8x6a0.75");  // where asked
    EXPECT_EQ(quilt_file_stem("%qduck", 5, sequence, tag), "_qs8x6a0.75duck");
  }
  EXPECT_EQ(frame_stem("fox%q.####", 5), "fox.0005") << "the other files have nothing at %q";
  EXPECT_EQ(frame_stem("fox.%d_%q_x", 5), "fox.5__x");
  EXPECT_EQ(canonical_name_pattern("fox%q.####"), "fox%q.%04d");
  EXPECT_EQ(canonical_name_pattern("f_%d%q%%"), "f_%d%q%%");
  EXPECT_NE(refusal("a%q%q_%d").find("more than one %q"), std::string::npos) << refusal("a%q%q_%d");
  EXPECT_NE(refusal("%q").find("empty"), std::string::npos) << "the other files' stems would be empty";
  // every default sequence name reads back as its frame, whatever the aspect's digits
  for (const char* pattern : {"frame_%04d", "fox.####", "shot%d", "take2_%03d", "fox%q.####"})
    for (const std::string& t : {tag, std::string("_qs5x9a1.7849"), std::string("_qs10x10a1")})
      for (long f : {0L, 1L, 9L, 10L, 75L, 1234L}) {
        const std::string file = quilt_file_stem(pattern, f, true, t) + ".exr";
        EXPECT_EQ(last_digit_group(file), f) << file;
      }
  EXPECT_EQ(last_digit_group("fox.0005_qs8x6a0.75.exr"), 75) << "the old sequence name is misread";
}

// The command lines a user types: a still named without a frame number, Blender's ####, refusals
// with nothing written, -o.
TEST(Names, FromTheCommandLine) {
  const std::string a = temp_dir("names_still");
  CliRun r = run("render --name duck" + kSmall + "-o " + a);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(listing(a), (std::set<std::string>{"duck.exr", "duck.json"}));
  EXPECT_EQ(sidecar(a + "/duck.json")["frame"], 0);

  const std::string b = temp_dir("names_blender");
  r = run("render --name shot_#### --frames 3,12 --turntable 360:16" + kSmall + "--out " + b);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(listing(b), (std::set<std::string>{"shot_0003.exr", "shot_0003.json", "shot_0012.exr", "shot_0012.json"}));

  const std::string c = temp_dir("names_refused");
  expect_usage_error(run("render --name duck --frames 0:1" + kSmall + "--out " + c), "names one frame");
  expect_usage_error(run("render --name shot_%4d" + kSmall + "--out " + c), "use %04d");
  expect_usage_error(run("render --name shot_%x" + kSmall + "--out " + c), "e.g. --name shot_%04d");
  EXPECT_FALSE(test::exists(c)) << "nothing written for a refused name";
  expect_usage_error(run("verify " + a + " --frames 0:1 --name duck"), "names one frame");

  // quilts: a still keeps the Looking Glass name, a sequence puts the frame number last, %q places the tag
  const std::string q = temp_dir("names_quilt");
  ASSERT_EQ(run("render --write quilt" + kSmall + "--out " + q + "/still").status, 0);
  EXPECT_EQ(listing(q + "/still"), (std::set<std::string>{"frame_0000_qs2x2a1.7849.exr", "frame_0000.json"}));
  r = run("render --write quilt,encoded --turntable 360:3 --frames 0:2" + kSmall + "--out " + q + "/seq");
  ASSERT_EQ(r.status, 0) << r.output;
  std::set<std::string> want;
  for (const char* f : {"0000", "0001", "0002"})
    want.insert({std::string("frame_qs2x2a1.7849_") + f + ".exr", std::string("frame_") + f + ".exr",
                 std::string("frame_") + f + ".json"});
  EXPECT_EQ(listing(q + "/seq"), want);
  r = run("render --write quilt --name 'fox%q.##' --turntable 360:3 --frames 1" + kSmall + "--out " + q + "/fox");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(listing(q + "/fox"), (std::set<std::string>{"fox_qs2x2a1.7849.01.exr", "fox.01.json"}));
  EXPECT_EQ(sidecar(q + "/fox/fox.01.json")["outputs"]["quilt"], "fox_qs2x2a1.7849.01.exr");
  r = run("render --write quilt --name 'fox%q.##' --turntable 360:3 --frames 1 --resume" + kSmall + "--out " + q +
          "/fox");
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  EXPECT_NE(run("render --help").output.find("-o DIR"), std::string::npos);
}

// A name without a frame field holds one frame at a time: --resume of another frame renders it
// instead of keeping the other frame's files.
TEST(Names, ResumeOfAnotherFrameUnderOneNameRendersIt) {
  const std::string out = temp_dir("names_resume");
  ASSERT_EQ(run("render --name duck --turntable 360:8 --frames 1" + kSmall + "--out " + out).status, 0);
  CliRun r = run("render --name duck --turntable 360:8 --frames 1 --resume" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("nothing to do"), std::string::npos) << r.output;
  r = run("render --name duck --turntable 360:8 --frames 2 --resume" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("1 frame(s) in"), std::string::npos) << r.output;
  EXPECT_EQ(sidecar(out + "/duck.json")["frame"], 2);
}

// --quiet: nothing on a clean run; a warning still prints, alone.
TEST(Names, QuietPrintsOnlyErrorsAndWarnings) {
  const std::string out = temp_dir("names_quiet");
  CliRun r = run("render -q" + kSmall + "--out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output, "");
  r = run("render --quiet --environment uniform --environment-rotation 30" + kSmall + "--out " +
          temp_dir("names_quiet_warning"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.rfind("pmr: warning: --environment-rotation", 0), 0u) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  r = run("render" + kSmall + "--out " + temp_dir("names_not_quiet"));  // without it: the header line and the summary
  EXPECT_NE(r.output.find("triangles"), std::string::npos) << r.output;
}

// --print-outputs: the files of every frame as pmr names them (here shot_%0d, which a tool expanding
// patterns itself got wrong), one JSON line a frame, and nothing rendered or created; the files then
// rendered are those.
TEST(Names, PrintOutputsListsTheFilesOfEveryFrameAndRendersNothing) {
  const std::string out = temp_dir("names_print");
  const std::string args = "render --name shot_%0d --frames 9:10 --turntable 360:12 --write encoded,quilt" + kSmall + "--out " + out;
  const CliRun r = run(args + " --print-outputs");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(test::exists(out)) << "nothing is created";
  std::istringstream lines(r.output);
  std::vector<nlohmann::json> frames;
  for (std::string line; std::getline(lines, line);)
    if (!line.empty() && line[0] == '{') frames.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(frames.size(), 2u) << r.output;
  EXPECT_EQ(frames[0]["frame"], 9);
  EXPECT_EQ(frames[0]["sidecar"], "shot_9.json");
  EXPECT_EQ(frames[1]["sidecar"], "shot_10.json");
  EXPECT_EQ(frames[1]["outputs"]["encoded"], "shot_10.exr");
  ASSERT_EQ(run(args + " -q").status, 0);
  for (const nlohmann::json& f : frames) {
    EXPECT_TRUE(test::exists(out + "/" + f["sidecar"].get<std::string>())) << f.dump();
    for (const auto& [kind, file] : f["outputs"].items())
      EXPECT_TRUE(test::exists(out + "/" + file.get<std::string>())) << kind;
  }
}

}  // namespace pmr
