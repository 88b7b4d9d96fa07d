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
                          "%%%5d", "f%0123d"}) {
    const std::string why = refusal(bad);
    EXPECT_NE(why.find("invalid --name"), std::string::npos) << bad << ": " << why;
    EXPECT_NE(why.find("e.g. --name shot_%04d"), std::string::npos) << bad << ": " << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  }
  EXPECT_NE(refusal("shot_%4d").find("use %04d"), std::string::npos) << refusal("shot_%4d");
  EXPECT_NE(refusal("a_%d_%d").find("more than one"), std::string::npos) << refusal("a_%d_%d");
  EXPECT_NO_THROW(check_name_covers_frames("duck", 1));
  EXPECT_NO_THROW(check_name_covers_frames("duck_%d", 2));
  EXPECT_THROW(check_name_covers_frames("duck", 2), Error);
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

}  // namespace pmr
