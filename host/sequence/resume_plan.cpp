#include "sequence/resume_plan.h"

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "pmr/json_text.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "pmr/version.h"

namespace pmr {

namespace {

std::string base_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

// "a, b, c, ..." of the first three names
std::string first_few(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size() && i < 3; ++i) s += (i ? ", " : "") + names[i];
  return names.size() > 3 ? s + ", ..." : s;
}

// The sidecar says it holds frame f (frame_problem has checked that it parses as an object).
bool records_frame(const std::string& sidecar, long f) {
  const nlohmann::json j = parse_json_text(sidecar);
  return j.is_object() && j.contains("frame") && j["frame"].is_number_integer() && j["frame"].get<long>() == f;
}

}  // namespace

ResumePlan plan_resume(const std::vector<long>& frames, bool resume, bool overwrite,
                       const std::function<FramePaths(long)>& paths,
                       const std::function<std::string(long, const FramePaths&)>& expected) {
  ResumePlan plan;
  // the frames rendered again, by reason: sidecars absent, frames present but incomplete, files of
  // another frame (a --name without a frame field), another configuration (--overwrite)
  std::vector<std::string> missing, incomplete, other_frame, other_config;
  std::vector<std::string> other_scene;   // sidecars of frames rendered from another scene
  long unrecorded = 0;                    // ... of them recording no scene checksum
  std::vector<std::string> old_versions;  // versions of kept frames other than this program's
  long old_version_frames = 0;
  std::string scene_now;  // this run's scene identity (sidecar_provenance)
  for (long f : frames) {
    const FramePaths p = paths(f);
    // complete = every file present and readable (a node may have died during a rename on a network
    // file system); anything less is rendered again
    const std::string problem = resume ? frame_problem(p.sidecar, p.images()) : std::string();
    if (resume && !problem.empty())
      (std::filesystem::exists(p.sidecar) ? incomplete : missing).push_back(base_name(p.sidecar));
    if (resume && problem.empty()) {
      const std::string existing = read_sidecar_text(p.sidecar);
      if (!records_frame(existing, f)) {  // a --name without a frame field: another frame's files
        other_frame.push_back(base_name(p.sidecar));
        plan.todo.push_back(f);
        continue;
      }
      const std::string want = expected(f, p);
      if (scene_now.empty()) scene_now = sidecar_provenance(want).scene;
      const SidecarProvenance had = sidecar_provenance(existing);
      const bool same_scene = !had.scene.empty() && had.scene == scene_now;
      const std::string diff = sidecar_config_difference(existing, want, /*ignore_scene_derived=*/!same_scene);
      if (diff.empty() && same_scene) {
        ++plan.kept;
        if (had.version != program_version()) {
          ++old_version_frames;
          const std::string v = had.version.empty() ? "unrecorded" : printable_text(had.version);
          if (std::find(old_versions.begin(), old_versions.end(), v) == old_versions.end()) old_versions.push_back(v);
        }
        continue;
      }
      if (!diff.empty() && !overwrite)
        throw Error("--resume: " + p.sidecar + " was rendered with a different configuration (" +
                    config_difference_text(existing, want, diff, "the folder", "this run") +
                    "); use --overwrite to re-render such frames, or another --out folder");
      if (diff.empty()) {
        other_scene.push_back(base_name(p.sidecar));
        unrecorded += had.scene.empty();
      } else {
        other_config.push_back(base_name(p.sidecar));
      }
    }
    plan.todo.push_back(f);
  }
  auto note = [&](const std::vector<std::string>& frames, const std::string& why) {
    if (!frames.empty())
      plan.notes.push_back("--resume: " + std::to_string(frames.size()) + " frame(s) " + why + " (" +
                           first_few(frames) + "): rendering them");
  };
  note(missing, "are missing");
  note(incomplete, "are incomplete (a file missing, cut short or not the one their sidecar lists)");
  note(other_frame, "hold another frame's files");
  note(other_config, "were rendered with another configuration (--overwrite)");
  if (!other_scene.empty())
    plan.notes.push_back("--resume: " + std::to_string(other_scene.size()) +
                         " frame(s) were rendered from a different scene" +
                         (unrecorded ? "; " + std::to_string(unrecorded) + " of them record no scene checksum" : "") +
                         " (" + first_few(other_scene) + "): rendering them again");
  if (old_version_frames)
    plan.notes.push_back("--resume: " + std::to_string(old_version_frames) +
                         " kept frame(s) were rendered by another pmr version (" + first_few(old_versions) +
                         "; this is " + program_version() + "): kept, a version change alone renders nothing again");
  return plan;
}

}  // namespace pmr
