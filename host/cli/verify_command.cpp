// Checks a sequence's output folder frame by frame: the sidecar is there and parses, names this frame
// and its time, and shows the same configuration as the folder's other frames; every requested image
// it lists exists and is complete. Missing or broken frames are printed on stdout as a --frames list
// to resubmit (details on stderr); the exit code is 1 when any frame is missing or broken.
#include "cli/verify_command.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli/options.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "sequence/frame_files.h"
#include "sequence/frame_list.h"

namespace pmr {

namespace {

namespace fs = std::filesystem;

std::string verify_help() {
  return "usage: pmr verify DIR --frames LIST [--write LIST] [--name PATTERN] [--preview]\n"
         "Checks that every listed frame in DIR is complete: its sidecar names the frame and its time and\n"
         "shows the same configuration as the other frames, and every requested output (--write, default\n"
         "encoded; --preview for the PNGs) exists and opens completely. Prints the missing or broken frames\n"
         "on stdout as a --frames list to resubmit (with --resume); exit code 1 if there are any.\n";
}

// What is wrong with one frame ("" if nothing), given the folder's reference sidecar text.
std::string check_frame(const std::string& dir, const RenderOptions& o, long f, std::string& reference) {
  const std::string stem = frame_stem(o.name, f);
  const std::string sidecar = (fs::path(dir) / (stem + ".json")).string();
  std::error_code ec;
  if (!fs::is_regular_file(sidecar, ec)) return stem + ".json is missing";
  const std::string text = read_text_file(sidecar);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception&) {
    return stem + ".json is truncated or unreadable";
  }
  if (!j.is_object() || !j.contains("frame") || j["frame"] != f)
    return stem + ".json does not describe frame " + std::to_string(f);
  if (!j.contains("fps") || !j.contains("time") || !j["fps"].is_number() || !j["time"].is_number() ||
      std::fabs(j["time"].get<double>() - double(f) / j["fps"].get<double>()) > 1e-9)
    return stem + ".json has a time that is not frame / fps";
  if (reference.empty()) reference = text;
  const std::string diff = sidecar_config_difference(reference, text);
  if (!diff.empty()) return stem + ".json was rendered with another configuration (" + diff + " differs)";
  std::vector<std::string> kinds;
  if (o.write_encoded) kinds.push_back("encoded");
  if (o.write_views) kinds.push_back("views");
  if (o.write_quilt) kinds.push_back("quilt");
  if (o.preview) {
    kinds.push_back("preview_center");
    if (o.write_encoded) kinds.push_back("preview_encoded");
    if (o.write_quilt) kinds.push_back("preview_quilt");
  }
  std::vector<std::string> images;
  for (const std::string& kind : kinds) {
    if (!j.contains("outputs") || !j["outputs"].contains(kind) || !j["outputs"][kind].is_string())
      return stem + ".json lists no " + kind + " output";
    images.push_back((fs::path(dir) / j["outputs"][kind].get<std::string>()).string());
  }
  return frame_problem(sidecar, images);
}

}  // namespace

int run_verify(const std::vector<std::string>& args) {
  std::string dir;
  std::vector<std::string> rest;  // --frames, --write, --name, --preview go through render's parser
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::fputs(verify_help().c_str(), stdout);
      return 0;
    }
    if (a == "--frames" || a == "--write" || a == "--name") {
      if (i + 1 >= args.size()) throw Error("option " + a + " needs a value (see pmr verify --help)");
      rest.push_back(a);
      rest.push_back(args[++i]);
    } else if (a == "--preview") {
      rest.push_back(a);
    } else if (!a.empty() && a[0] == '-') {
      throw Error("unknown option " + a + " (see pmr verify --help)");
    } else if (dir.empty()) {
      dir = a;
    } else {
      throw Error("more than one folder given");
    }
  }
  if (dir.empty()) throw Error("pmr verify needs the output folder (see pmr verify --help)");
  bool frames_given = false;
  for (const std::string& r : rest) frames_given |= r == "--frames";
  if (!frames_given) throw Error("pmr verify needs --frames LIST (the frames the job was asked for)");
  const RenderOptions o = parse_render_options(rest);
  if (o.frames == "all") throw Error("pmr verify needs the frames as a list (--frames all depends on the scene)");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error("cannot verify " + dir + ": not a folder");
  const std::vector<long> frames = parse_frame_list(o.frames);
  std::vector<long> bad;
  std::string reference;
  for (long f : frames) {
    const std::string problem = check_frame(dir, o, f, reference);
    if (problem.empty()) continue;
    bad.push_back(f);
    std::fprintf(stderr, "pmr verify: frame %ld: %s\n", f, problem.c_str());
  }
  std::fprintf(stderr, "pmr verify: %zu of %zu frame(s) complete%s\n", frames.size() - bad.size(), frames.size(),
               bad.empty() ? "" : "; resubmit the list below with --resume");
  if (bad.empty()) return 0;
  std::printf("%s\n", format_frame_list(bad).c_str());
  return 1;
}

}  // namespace pmr
