// Checks a sequence's output folder frame by frame: the sidecar is there and parses, names this frame
// and its time, was rendered from the same scene (its recorded checksums) and with the same
// configuration as the folder's other frames; every output it lists (or, with --write / --preview, every
// requested kind) is a regular file in the folder and complete. Missing or broken frames are printed on
// stdout as a --frames list to resubmit (details on stderr); the exit code is 1 when any frame is
// missing or broken.
#include "cli/verify_command.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "cli/options.h"
#include "pmr/error.h"
#include "pmr/json_text.h"
#include "pmr/memory_budget.h"
#include "output/checksum.h"
#include "output/sidecar.h"
#include "output/sidecar_names.h"
#include "pmr/output.h"
#include "sequence/folder_guard.h"
#include "sequence/frame_files.h"
#include "sequence/frame_list.h"

namespace pmr {

namespace {

namespace fs = std::filesystem;

std::string verify_help() {
  return "usage: pmr verify DIR [--frames LIST] [--write LIST] [--name PATTERN] [--preview] [--deep]\n"
         "                  [--limit memory=N] [--preset NAME] [--views N] [--view-size WxH] [--display WxH]\n"
         "Checks that every listed frame in DIR is complete: its sidecar names the frame and its time, was\n"
         "rendered from the scene as it is now (the checksums it records of the scene file and the files it\n"
         "reads; where the scene cannot be read, the version most frames show) and with the same\n"
         "configuration as the folder's other frames, and every output\n"
         "it lists exists as a regular file in DIR and is the file the sidecar records: its size and checksum,\n"
         "and for an EXR its chunk table, without decoding pixels. --deep decodes every pixel as well (as\n"
         "for frames whose sidecar records no checksums, written by an older pmr). --write LIST (and --preview\n"
         "for the PNGs) checks just those kinds of output instead. Without --frames, the frames whose sidecars\n"
         "DIR holds are checked (a frame missing altogether is then not found). Prints the missing or broken\n"
         "frames on stdout as a --frames list to resubmit (with --resume; frames of another configuration\n"
         "with --overwrite); exit code 1 if there are any. A folder of several configurations is reported\n"
         "group by group (frames and main settings); the frames are judged against the largest, and\n"
         "--preset, --views, --view-size and --display say which group is the job's as it is now.\n";
}

// A listed output must be a plain file name in the frame's folder.
bool plain_file_name(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return false;
  for (unsigned char c : name)
    if (c == '/' || c == '\\' || c < 0x20 || c == 0x7f) return false;
  return true;
}

// What the folder's frames were rendered from: the scene identity most sidecars record (ties: the
// earliest frame's), the first frame showing it (the configuration reference) and the program versions.
// Frames of one configuration (sidecar_config_difference finds none between them), named by the first.
struct ConfigGroup {
  std::string text;  // its first frame's sidecar
  std::vector<long> frames;
};
constexpr size_t kMaxConfigGroups = 16;  // beyond, further configurations join the last group's report

struct FolderScene {
  std::string scene;
  long reference_frame = -1;
  std::string reference_text;  // its sidecar
  std::vector<std::string> versions;
  std::vector<ConfigGroup> groups;  // in the order of their first frames
  size_t reference_group = 0;       // the largest: the frames are judged against it
};

std::string sidecar_path(const std::string& dir, const RenderOptions& o, long f) {
  return (fs::path(dir) / (frame_stem(o.job.products.name, f) + ".json")).string();
}

// Adds a readable sidecar to the group of its configuration, or starts one.
void add_to_group(std::vector<ConfigGroup>& groups, long f, const std::string& text) {
  const std::string scene = sidecar_provenance(text).scene;
  for (ConfigGroup& g : groups)
    if (sidecar_config_difference(text, g.text, sidecar_provenance(g.text).scene != scene).empty())
      return g.frames.push_back(f);
  if (groups.size() < kMaxConfigGroups) groups.push_back({text, {f}});
}

// The folder's largest configuration (ties: the earlier), and the first of its frames rendered from the
// scene most frames were rendered from: the reference the frames are judged against.
void choose_reference(FolderScene& folder, const std::string& dir, const RenderOptions& o) {
  for (size_t g = 1; g < folder.groups.size(); ++g)
    if (folder.groups[g].frames.size() > folder.groups[folder.reference_group].frames.size())
      folder.reference_group = g;
  if (folder.groups.empty()) return;
  const ConfigGroup& best = folder.groups[folder.reference_group];
  folder.reference_frame = best.frames.front();
  for (long f : best.frames) {
    const std::string text = read_sidecar_text(sidecar_path(dir, o, f));
    if (sidecar_provenance(text).scene == folder.scene) {
      folder.reference_frame = f;
      break;
    }
  }
}

FolderScene folder_scene(const std::string& dir, const RenderOptions& o, const std::vector<long>& frames) {
  std::map<std::string, std::pair<long, long>> seen;  // identity -> (count, first frame)
  FolderScene folder;
  for (long f : frames) {
    const std::string path = sidecar_path(dir, o, f);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) continue;
    const std::string text = read_sidecar_text(path);
    if (!parse_json_text(text).is_object()) continue;
    add_to_group(folder.groups, f, text);
    const SidecarProvenance p = sidecar_provenance(text);
    ++seen.try_emplace(p.scene, 0, f).first->second.first;
    const std::string v = p.version.empty() ? "unrecorded" : p.version;
    if (std::find(folder.versions.begin(), folder.versions.end(), v) == folder.versions.end())
      folder.versions.push_back(v);
  }
  long best = 0, first = -1;
  for (const auto& [scene, count_first] : seen)
    if (count_first.first > best || (count_first.first == best && count_first.second < first)) {
      best = count_first.first;
      folder.scene = scene;
      first = count_first.second;
    }
  choose_reference(folder, dir, o);
  if (folder.reference_frame >= 0)
    folder.reference_text = read_sidecar_text(sidecar_path(dir, o, folder.reference_frame));
  return folder;
}

// The scene files as they are now, each distinct file hashed once however many spellings and frames
// name it (distinct: the (st_dev, st_ino) of the opened file, so "x.bin", "./x.bin" and hard links are
// one file), so verify's reading is bounded by the bytes on disk, not by the sidecars' entries: the
// scene the sidecars name and the files they list beside it. Only regular files are read, listed files
// only inside the scene's folder.
struct SceneNow {
  std::map<std::string, std::string> by_path;              // as named -> XXH3-64, "" when unreadable
  std::map<std::pair<dev_t, ino_t>, std::string> by_file;  // each opened file's
  uint64_t files_hashed = 0, bytes_hashed = 0;             // what `sum` read, for the summary
  bool scene_unreadable = false;  // a sidecar's scene cannot be read: the folder's majority decides

  std::string sum(const std::string& path) {
    if (const auto it = by_path.find(path); it != by_path.end()) return it->second;
    std::string s;
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st {};
    if (fd >= 0 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
      const auto file = by_file.find({st.st_dev, st.st_ino});
      if (file != by_file.end()) {
        s = file->second;
      } else {
        uint64_t bytes = 0;
        try {
          s = checksum_descriptor(fd, path, &bytes);
        } catch (const Error&) {}
        ++files_hashed, bytes_hashed += bytes;
        by_file[{st.st_dev, st.st_ino}] = s;
      }
    }
    if (fd >= 0) ::close(fd);
    return by_path[path] = s;
  }
};

bool inside_folder(const std::string& name) {
  const fs::path p(name);
  if (name.empty() || p.is_absolute()) return false;
  for (const fs::path& part : p)
    if (part == "..") return false;
  return true;
}

// The first file of the scene a frame's sidecar records that differs now (changed, gone or not a plain
// name), "" when every one is as recorded or the sidecar records no checksums.
std::string changed_scene_file(const nlohmann::json& j, SceneNow& now) {
  const auto c = j.find("checksums");
  if (c == j.end() || !c->is_object() || c->value("algorithm", "") != "XXH3-64" || !j.contains("scene") ||
      !j["scene"].is_string())
    return "";
  const std::string scene = recorded_name(&j["scene"], j.contains("scene_hex") ? &j["scene_hex"] : nullptr);
  const std::string sum = now.sum(scene);
  if (sum.empty()) return now.scene_unreadable = true, "";
  if (c->value("scene", "") != sum) return fs::path(scene).filename().string();
  for (const auto& [name, sum] : recorded_scene_files(*c))
    if (!inside_folder(name) || !sum->is_string() ||
        now.sum((fs::path(scene).parent_path() / name).string()) != sum->get<std::string>())
      return name;
  return "";
}

// What is wrong with one frame ("" if nothing), given what the folder's frames were rendered from.
// explicit_kinds: --write / --preview were given, check those kinds; else every output the sidecar lists.
std::string check_frame(const std::string& dir, const RenderOptions& o, bool explicit_kinds, bool deep, long f,
                        const FolderScene& folder, SceneNow& now) {
  const std::string stem = frame_stem(o.job.products.name, f);
  const std::string sidecar = sidecar_path(dir, o, f);
  std::error_code ec;
  if (!fs::is_regular_file(sidecar, ec)) return stem + ".json is missing";
  const std::string text = read_sidecar_text(sidecar);
  const nlohmann::json j = parse_json_text(text);
  if (j.is_discarded()) return stem + ".json is truncated or unreadable";
  if (!j.is_object() || !j.contains("frame") || j["frame"] != f)
    return stem + ".json does not describe frame " + std::to_string(f);
  if (!j.contains("fps") || !j.contains("time") || !j["fps"].is_number() || !j["time"].is_number() ||
      !(j["fps"].get<double>() > 0.0) || std::fabs(j["time"].get<double>() - double(f) / j["fps"].get<double>()) > 1e-9)
    return stem + ".json has a time that is not frame / fps";
  const SidecarProvenance prov = sidecar_provenance(text);
  const std::string reference_name = frame_stem(o.job.products.name, folder.reference_frame) + ".json";
  // the scene as it is now decides; the folder's majority only where the scene cannot be read
  if (const std::string changed = changed_scene_file(j, now); !changed.empty())
    return stem + ".json was rendered from another version of the scene (" + printable_text(changed) + " differs now)";
  if (now.scene_unreadable && !prov.scene.empty() && prov.scene != folder.scene)
    return stem + ".json was rendered from another scene than " + reference_name +
           " and the folder's other frames (scene checksums differ)";
  // (frames of two versions of the scene differ in what follows from its content: bounds, pivot, lights)
  const std::string diff = sidecar_config_difference(folder.reference_text, text, prov.scene != folder.scene);
  if (!diff.empty())
    return stem + ".json was rendered with another configuration (" +
           config_difference_text(text, folder.reference_text, diff, stem + ".json", reference_name) + ")";
  if (prov.scene.empty() && !folder.scene.empty())
    return stem + ".json records no scene checksum, unlike " + reference_name;
  std::vector<std::pair<std::string, nlohmann::json>> listed;  // (kind, file name as listed)
  const nlohmann::json* outputs = j.contains("outputs") && j["outputs"].is_object() ? &j["outputs"] : nullptr;
  if (explicit_kinds) {
    std::vector<std::string> kinds;
    if (o.job.products.encoded) kinds.push_back("encoded");
    if (o.job.products.views) kinds.push_back("views");
    if (o.job.products.quilt) kinds.push_back("quilt");
    if (o.job.products.preview) {
      kinds.push_back("preview_center");
      if (o.job.products.encoded) kinds.push_back("preview_encoded");
      if (o.job.products.quilt) kinds.push_back("preview_quilt");
    }
    for (const std::string& kind : kinds) {
      if (!outputs || !outputs->contains(kind)) return stem + ".json lists no " + kind + " output";
      listed.push_back({kind, (*outputs)[kind]});
    }
  } else {
    if (!outputs || outputs->empty()) return stem + ".json lists no outputs";
    for (auto it = outputs->begin(); it != outputs->end(); ++it) listed.push_back({it.key(), it.value()});
  }
  // names that are not UTF-8 are recorded byte-exact beside them
  const nlohmann::json* hex = j.contains("outputs_hex") && j["outputs_hex"].is_object() ? &j["outputs_hex"] : nullptr;
  for (auto& [kind, value] : listed)
    if (hex && hex->contains(kind) && value.is_string()) value = recorded_name(&value, &(*hex)[kind]);
  std::vector<std::string> images;  // each file once, however many kinds list it: the work is bounded by the files
  std::set<std::string> seen;
  for (const auto& [kind, value] : listed) {
    if (!value.is_string()) return stem + ".json lists a " + printable_text(kind) + " output that is not a file name";
    const std::string name = value.get<std::string>();
    if (!plain_file_name(name))
      return stem + ".json lists " + printable_text(kind) + " output '" + printable_text(name) +
             "', which is not a plain file name in the folder";
    if (!seen.insert(name).second) continue;  // looked at already
    const fs::path path = fs::path(dir) / name;
    const fs::file_status st = fs::symlink_status(path, ec);
    if (st.type() == fs::file_type::not_found) return printable_text(name) + " is missing";
    if (st.type() != fs::file_type::regular)
      return printable_text(name) + " is not a regular file (" +
             (st.type() == fs::file_type::symlink     ? "a symbolic link"
              : st.type() == fs::file_type::directory ? "a folder"
                                                      : "a special file") +
             ")";
    images.push_back(path.string());
  }
  // frame_problem names the files by their (plain, but maybe not ASCII) names
  return printable_text(frame_problem(sidecar, images, deep), std::string::npos);
}

// Without --frames: the frames whose sidecars the folder holds (under --name's pattern), said so, since
// a frame missing altogether cannot be named then.
std::vector<long> frames_in_folder(const std::string& dir, const RenderOptions& o) {
  std::vector<long> frames;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const long f = sidecar_frame(o.job.products.name, e.path().filename().string());
    if (f >= 0) frames.push_back(f);
  }
  if (frames.empty())
    throw Error(dir + " holds no frame sidecars named as --name " + printable_text(o.job.products.name) +
                " makes them; give --frames LIST, the frames the job was asked for");
  std::sort(frames.begin(), frames.end());
  std::fprintf(stderr,
               "pmr verify: no --frames: checking the %zu frame(s) the folder holds (%s); a frame missing altogether "
               "is only found with --frames\n",
               frames.size(), format_frame_list(frames).c_str());
  return frames;
}

// j[a][b], or null when the sidecar (a stranger's file) lacks it.
nlohmann::json member(const nlohmann::json& j, const char* a, const char* b) {
  return j.is_object() && j.contains(a) && j[a].is_object() && j[a].contains(b) ? j[a][b] : nlohmann::json();
}

// A configuration's main settings, from its sidecar: "preset lg-portrait, 1536x2048 display, 48 views of
// 420x560".
std::string group_settings(const std::string& text) {
  const nlohmann::json j = parse_json_text(text);
  auto at = [&](const char* a, const char* b) { return member(j, a, b); };
  auto number = [](const nlohmann::json& v) { return v.is_number() ? std::to_string(v.get<long long>()) : "?"; };
  const nlohmann::json source = at("display", "source");
  return (source.is_string() ? printable_text(source.get<std::string>()) : std::string("display")) + ", " +
         number(at("display", "width")) + "x" + number(at("display", "height")) + " display, " +
         number(at("rig", "views")) + " views of " + number(at("rig", "view_width")) + "x" +
         number(at("rig", "view_height"));
}

// The main settings given to verify (--preset, --views, --view-size, --display): which group is the
// job's as it is now. Unset: not given.
struct GivenSettings {
  std::string source;  // "preset NAME"
  long views = -1, view_w = -1, view_h = -1, width = -1, height = -1;
  bool any() const { return !source.empty() || views > 0 || view_w > 0 || width > 0; }
};

bool matches_given(const GivenSettings& s, const std::string& text) {
  const nlohmann::json j = parse_json_text(text);
  auto at = [&](const char* a, const char* b) { return member(j, a, b); };
  auto same = [](const nlohmann::json& v, long want) { return want < 0 || (v.is_number() && v.get<long>() == want); };
  return (s.source.empty() || at("display", "source") == s.source) && same(at("rig", "views"), s.views) &&
         same(at("rig", "view_width"), s.view_w) && same(at("rig", "view_height"), s.view_h) &&
         same(at("display", "width"), s.width) && same(at("display", "height"), s.height);
}

// A folder of several configurations: each with its frames and main settings, which one the frames
// are judged against, which were rendered from the scene as it is now, and which has the settings given.
void report_groups(const FolderScene& folder, SceneNow& now, const GivenSettings& given) {
  if (folder.groups.size() < 2) return;
  std::fprintf(stderr, "pmr verify: the folder holds frames of %zu configurations%s:\n", folder.groups.size(),
               folder.groups.size() == kMaxConfigGroups ? " or more" : "");
  for (size_t g = 0; g < folder.groups.size(); ++g) {
    const ConfigGroup& group = folder.groups[g];
    const bool current = changed_scene_file(parse_json_text(group.text), now).empty();
    const bool asked = given.any() && matches_given(given, group.text);
    std::fprintf(stderr, "pmr verify:   frames %s: %s%s%s%s\n", format_frame_list(group.frames).c_str(),
                 group_settings(group.text).c_str(), current ? "; rendered from the scene as it is now" : "",
                 asked ? "; matches the settings given" : "",
                 g == folder.reference_group ? "; the largest: the other frames are judged against it" : "");
  }
}

// The temporary files writers leave when they are killed (temporary_name's ".NAME.tmp-HOST-PID-N"): no
// frame needs them. One note per kind of owner, each naming the first file: this host's dead processes
// (the next run here removes them), this host's running ones, and other hosts' (verify cannot tell
// whether those still run).
void note_leftover_temporaries(const std::string& dir) {
  std::map<std::string, std::vector<std::string>> kinds;  // note -> names, sorted
  std::set<std::string> hosts;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    TemporaryOwner owner;
    if (!parse_temporary_name(name, owner)) continue;
    if (!owner.this_host) hosts.insert(owner.host.empty() ? "an unrecorded host" : owner.host);
    kinds[!owner.this_host ? "c" : owner.running ? "b" : "a"].push_back(name);
  }
  const std::string folder = printable_text(dir);
  for (auto& [kind, names] : kinds) {
    std::sort(names.begin(), names.end());
    const std::string first = printable_text(names[0]) + (names.size() > 1 ? ", ..." : "");
    std::string host_list;
    for (const std::string& h : hosts) host_list += (host_list.empty() ? "" : ", ") + printable_text(h);
    const std::string why =
        kind == "a" ? "of writers on this host that no longer run (" + first +
                          "): no frame needs them, and the next pmr run in this folder on this host removes them"
        : kind == "b" ? "of pmr processes running on this host now (" + first + ")"
                      : "of writers on other hosts (" + host_list + ": " + first +
                            "): no frame needs them; remove them once no pmr process there writes into " + folder;
    std::fprintf(stderr, "pmr verify: note: %zu temporary file(s) %s\n", names.size(), why.c_str());
  }
}

}  // namespace

int run_verify(const std::vector<std::string>& args) {
  std::string dir;
  bool deep = false;
  std::vector<std::string> rest;  // --frames, --write, --name, --preview go through render's parser
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::fputs(verify_help().c_str(), stdout);
      return 0;
    }
    if (a == "--frames" || a == "--write" || a == "--name" || a == "--limit" || a == "--preset" || a == "--views" ||
        a == "--view-size" || a == "--display") {
      if (i + 1 >= args.size()) throw UsageError("option " + a + " needs a value (see pmr verify --help)");
      rest.push_back(a);
      rest.push_back(args[++i]);
    } else if (a == "--preview") {
      rest.push_back(a);
    } else if (a == "--deep") {
      deep = true;
    } else if (!a.empty() && a[0] == '-') {
      throw UsageError("unknown option " + a + " (see pmr verify --help)");
    } else if (dir.empty()) {
      dir = a;
    } else {
      throw UsageError("more than one folder given");
    }
  }
  if (dir.empty()) throw UsageError("pmr verify needs the output folder (see pmr verify --help)");
  bool frames_given = false;
  for (const std::string& r : rest) frames_given |= r == "--frames";
  const RenderOptions o = parse_render_options(rest);
  GivenSettings given;
  for (const std::string& r : rest) {
    if (r == "--preset") given.source = o.job.display_source.name;
    if (r == "--views") given.views = o.job.rig.views;
    if (r == "--view-size") given.view_w = o.job.rig.view_w, given.view_h = o.job.rig.view_h;
    if (r == "--display") given.width = o.job.display.width, given.height = o.job.display.height;
  }
  set_memory_budget(o.job.input_limits.memory);  // sidecars are parsed within it (0: automatic)
  if (frames_given && o.job.frames == "all")
    throw UsageError("pmr verify needs the frames as a list (--frames all depends on the scene)");
  std::vector<long> frames;  // a usage error in the list comes before any look at the folder
  if (frames_given) frames = as_usage([&] { return parse_frame_list(o.job.frames); });
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error("cannot verify " + dir + ": not a folder");
  if (!frames_given) frames = frames_in_folder(dir, o);
  as_usage([&] { check_name_covers_frames(o.job.products.name, frames.size()); });
  bool explicit_kinds = false;
  for (const std::string& r : rest) explicit_kinds |= r == "--write" || r == "--preview";
  const FolderScene folder = folder_scene(dir, o, frames);
  std::vector<long> bad;
  SceneNow now;
  bool configuration = false;  // a frame of another configuration: --resume refuses it, --overwrite redoes it
  for (long f : frames) {
    const std::string problem = check_frame(dir, o, explicit_kinds, deep, f, folder, now);
    if (problem.empty()) continue;
    bad.push_back(f);
    configuration |= problem.find("rendered with another configuration") != std::string::npos;
    std::fprintf(stderr, "pmr verify: frame %ld: %s\n", f, problem.c_str());
  }
  report_groups(folder, now, given);
  note_leftover_temporaries(dir);
  if (now.files_hashed > 0)
    std::fprintf(stderr, "pmr verify: read %llu scene file(s), %llu bytes, to compare with the sidecars' checksums\n",
                 (unsigned long long)now.files_hashed, (unsigned long long)now.bytes_hashed);
  if (now.scene_unreadable)
    std::fprintf(stderr,
                 "pmr verify: note: the scene the sidecars name cannot be read from here: frames are compared with "
                 "the scene most of them were rendered from\n");
  if (folder.versions.size() > 1) {  // not a problem: versions do not change pixels (docs/SEQUENCES.md)
    std::string list;
    for (const std::string& v : folder.versions) list += (list.empty() ? "" : ", ") + printable_text(v);
    std::fprintf(stderr, "pmr verify: note: the frames were rendered by %zu pmr versions (%s)\n",
                 folder.versions.size(), list.c_str());
  }
  std::fprintf(stderr, "pmr verify: %zu of %zu frame(s) complete%s\n", frames.size() - bad.size(), frames.size(),
               bad.empty()     ? ""
               : configuration ? ("; resubmit the list below with the folder's configuration (" +
                                  group_settings(folder.reference_text) +
                                  ") and --overwrite (some frames were rendered with another configuration, which "
                                  "--resume refuses)")
                                     .c_str()
                               : "; resubmit the list below with --resume");
  if (bad.empty()) return 0;
  std::printf("%s\n", format_frame_list(bad).c_str());
  return 1;
}

}  // namespace pmr
