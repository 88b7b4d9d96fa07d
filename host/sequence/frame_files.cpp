#include "sequence/frame_files.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <sstream>

#include <nlohmann/json.hpp>

#include "output/checksum.h"
#include "pmr/error.h"
#include "output/sidecar_names.h"
#include "pmr/json_text.h"
#include "pmr/printable.h"
#include "pmr/memory_budget.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "sequence/folder_guard.h"
#include "sequence/frame_names.h"

namespace pmr {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::vector<std::string> FramePaths::images() const {
  std::vector<std::string> all;
  for (const std::string* p : {&encoded, &views, &quilt, &encoded_png, &center_png, &quilt_png})
    if (!p->empty()) all.push_back(*p);
  return all;
}

FramePaths frame_paths(const FrameProducts& o, long frame, const QuiltLayout& quilt, double aspect) {
  const std::string stem = frame_stem(o.name, frame);
  const std::string base = (fs::path(o.out_dir) / stem).string();
  FramePaths p;
  p.sidecar = base + ".json";
  if (o.encoded) p.encoded = base + ".exr";
  if (o.views) p.views = base + ".views.exr";
  if (o.quilt || o.preview) {
    const std::string quilt_name = quilt_file_stem(o.name, frame, o.sequence, quilt_stem("", quilt, aspect));
    const std::string quilt_base = (fs::path(o.out_dir) / quilt_name).string();
    if (o.quilt) p.quilt = quilt_base + ".exr";
    if (o.preview && o.quilt) p.quilt_png = quilt_base + ".png";
  }
  if (o.preview) {
    if (o.encoded) p.encoded_png = base + ".png";
    p.center_png = base + ".center.png";
  }
  return p;
}

FolderNames folder_quilt_names(const FrameProducts& o, const QuiltLayout& quilt, double aspect) {
  if (!o.quilt) return FolderNames::None;
  std::error_code ec;
  fs::directory_iterator it(o.out_dir, ec), end;
  FrameProducts as_sequence = o, as_still = o;
  as_sequence.sequence = true, as_still.sequence = false;
  bool sequence = false, still = false;
  size_t read = 0;
  for (; !ec && it != end && read < kMaxFolderSidecars; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const long f = sidecar_frame(o.name, name);
    if (f < 0 || !it->is_regular_file(ec)) continue;
    ++read;
    const json j = parse_json_text(read_sidecar_text(it->path().string()));
    if (!j.is_object() || !j.contains("outputs") || !j["outputs"].is_object()) continue;
    const json& q = j["outputs"].contains("quilt") ? j["outputs"]["quilt"] : json();
    if (!q.is_string()) continue;
    const std::string recorded = q.get<std::string>();
    const std::string seq_name = fs::path(frame_paths(as_sequence, f, quilt, aspect).quilt).filename().string();
    const std::string still_name = fs::path(frame_paths(as_still, f, quilt, aspect).quilt).filename().string();
    if (seq_name == still_name) continue;  // the pattern places the quilt's tag itself (%q): no evidence
    sequence |= recorded == seq_name;
    still |= recorded == still_name;
  }
  return sequence && still ? FolderNames::Mixed
         : sequence        ? FolderNames::Sequence
         : still           ? FolderNames::Still
                           : FolderNames::None;
}

namespace {

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

std::string read_sidecar_text(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec || size > kMaxSidecarBytes) return "";
  // parsed, JSON takes about a hundred times its text (a stranger's sidecar may be all numbers)
  check_memory(uint64_t(size) * 100,
               "parsing the sidecar " + fs::path(path).filename().string() + " (" + std::to_string(size) + " bytes)");
  return read_text_file(path);
}

namespace {

// What the sidecar records of the files written before it (name -> bytes, checksum); empty when it
// records none (written before pmr recorded them) or with another algorithm.
std::map<std::string, OutputChecksum> recorded_outputs(const nlohmann::json& sidecar) {
  std::map<std::string, OutputChecksum> out;
  const auto c = sidecar.find("output_checksums");
  if (c == sidecar.end() || !c->is_object() || c->value("algorithm", json()) != kChecksumAlgorithm) return out;
  const auto files = c->find("files");
  if (files == c->end() || !files->is_object()) return out;
  for (auto it = files->begin(); it != files->end(); ++it) {
    const json& v = it.value();
    if (!v.is_object() || !v.contains("bytes") || !v["bytes"].is_number_unsigned() || !v.contains("checksum") ||
        !v["checksum"].is_string())
      continue;
    const json key = it.key();  // a name that is not UTF-8 is recorded byte-exact in name_hex
    const std::string name = recorded_name(&key, v.contains("name_hex") ? &v["name_hex"] : nullptr);
    out[name] = {name, v["bytes"].get<uint64_t>(), v["checksum"].get<std::string>()};
  }
  return out;
}

bool is_png(const std::string& p) { return p.size() > 4 && p.compare(p.size() - 4, 4, ".png") == 0; }

// The full check: every pixel decoded.
bool decodes(const std::string& p) {
  if (!is_png(p)) return exr_is_complete(p);
  try {
    int w = 0, h = 0;
    std::vector<uint8_t> px;
    read_png_rgba8(p, w, h, px);
    return true;
  } catch (const std::bad_alloc&) {
    throw;  // out of memory is not a damaged file
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

std::string frame_problem(const std::string& sidecar, const std::vector<std::string>& images, bool deep) {
  std::error_code ec;
  auto name = [](const std::string& p) { return fs::path(p).filename().string(); };
  if (!fs::is_regular_file(sidecar, ec)) return name(sidecar) + " is missing";
  for (const std::string& p : images)
    if (!fs::is_regular_file(p, ec)) return name(p) + " is missing";
  json j;
  try {
    j = parse_json_text(read_sidecar_text(sidecar));
  } catch (const Error&) {  // beyond the memory budget: a frame to render again, not the job's end
    return name(sidecar) + " is truncated or unreadable";
  }
  if (j.is_discarded()) return name(sidecar) + " is truncated or unreadable";
  if (!j.is_object()) return name(sidecar) + " is not a sidecar";
  const std::map<std::string, OutputChecksum> recorded = recorded_outputs(j);
  for (const std::string& p : images) {
    const auto r = recorded.find(name(p));
    if (r != recorded.end()) {  // the quick check: size, structure, checksum
      const auto size = fs::file_size(p, ec);
      if (ec) return name(p) + " cannot be read";
      const std::string problem = is_png(p) ? std::string() : exr_chunk_problem(p);
      // a whole file of another size is another file (e.g. another frame's copied over it)
      if (uint64_t(size) < r->second.bytes && !problem.empty())
        return name(p) + " is truncated (" + std::to_string(size) + " of " + std::to_string(r->second.bytes) +
               " bytes)";
      if (uint64_t(size) != r->second.bytes)
        return name(p) + " is not the file its sidecar records (" + std::to_string(size) + " bytes, recorded " +
               std::to_string(r->second.bytes) + ")";
      if (!problem.empty()) return problem;
      std::string sum;
      try {
        sum = checksum_file(p);
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception&) {
        return name(p) + " cannot be read";
      }
      if (sum != r->second.checksum) return name(p) + " is not the file its sidecar records (its checksum differs)";
      if (!deep) continue;
    }
    // older sidecars record no checksums: decode every pixel (and always with `deep`)
    if (!decodes(p)) return name(p) + " is truncated or unreadable";
  }
  return "";
}

void check_frame_file_names(const FrameProducts& o, const std::vector<long>& frames, const QuiltLayout& quilt,
                            double aspect) {
  if (frames.empty()) return;
  // the frame number is the only part that varies: the largest frame makes the longest names
  const FramePaths p = frame_paths(o, *std::max_element(frames.begin(), frames.end()), quilt, aspect);
  std::vector<std::string> files = p.images();
  files.push_back(p.sidecar);
  std::string name;  // the longest
  for (const std::string& file : files)
    if (const std::string n = fs::path(file).filename().string(); n.size() > name.size()) name = n;
  const size_t limit = max_output_file_name();
  if (name.size() > limit)
    throw UsageError("invalid --name '" + printable_text(o.name) + "': it makes the file name " + name + " of " +
                     std::to_string(name.size()) + " bytes, and pmr can write at most " + std::to_string(limit) +
                     " (the file system's 255, less what the temporary name it writes first adds)");
}

}  // namespace pmr
