#include "sequence/frame_files.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "pmr/output.h"

namespace pmr {

namespace fs = std::filesystem;

std::vector<std::string> FramePaths::images() const {
  std::vector<std::string> all;
  for (const std::string* p : {&encoded, &views, &quilt, &encoded_png, &center_png, &quilt_png})
    if (!p->empty()) all.push_back(*p);
  return all;
}

FramePaths frame_paths(const RenderOptions& o, long frame, const QuiltLayout& quilt, double aspect) {
  const std::string stem = frame_stem(o.name, frame);
  const std::string base = (fs::path(o.out_dir) / stem).string();
  FramePaths p;
  p.sidecar = base + ".json";
  if (o.write_encoded) p.encoded = base + ".exr";
  if (o.write_views) p.views = base + ".views.exr";
  if (o.write_quilt || o.preview) {
    const std::string quilt_base = (fs::path(o.out_dir) / quilt_stem(stem, quilt, aspect)).string();
    if (o.write_quilt) p.quilt = quilt_base + ".exr";
    if (o.preview && o.write_quilt) p.quilt_png = quilt_base + ".png";
  }
  if (o.preview) {
    if (o.write_encoded) p.encoded_png = base + ".png";
    p.center_png = base + ".center.png";
  }
  return p;
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string frame_problem(const std::string& sidecar, const std::vector<std::string>& images) {
  std::error_code ec;
  auto name = [](const std::string& p) { return fs::path(p).filename().string(); };
  for (const std::string* p : {&sidecar})
    if (!fs::is_regular_file(*p, ec)) return name(*p) + " is missing";
  for (const std::string& p : images)
    if (!fs::is_regular_file(p, ec)) return name(p) + " is missing";
  try {
    if (!nlohmann::json::parse(read_text_file(sidecar)).is_object()) return name(sidecar) + " is not a sidecar";
  } catch (const std::exception&) {
    return name(sidecar) + " is truncated or unreadable";
  }
  for (const std::string& p : images) {
    const bool png = p.size() > 4 && p.compare(p.size() - 4, 4, ".png") == 0;
    bool ok = true;
    if (png) {
      try {
        int w = 0, h = 0;
        std::vector<uint8_t> px;
        read_png_rgba8(p, w, h, px);
      } catch (const std::exception&) {
        ok = false;
      }
    } else {
      ok = exr_is_complete(p);
    }
    if (!ok) return name(p) + " is truncated or unreadable";
  }
  return "";
}

void check_frame_file_names(const RenderOptions& o, const std::vector<long>& frames, const QuiltLayout& quilt,
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
    throw UsageError("invalid --name '" + o.name + "': it makes the file name " + name + " of " +
                     std::to_string(name.size()) + " bytes, and pmr can write at most " + std::to_string(limit) +
                     " (the file system's 255, less what the temporary name it writes first adds)");
}

}  // namespace pmr
