// Reading files that may come from strangers (docs/SECURITY.md): every read is of a regular file under
// a byte budget, opened so that a FIFO or a device never blocks or streams forever, and the files a
// scene names are confined to the scene's folder.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace pmr {

// The budgets and the confinement switch, one set per run (render, bench, info). Each budget is a key
// of --limit KEY=VALUE[,KEY=VALUE...].
struct InputLimits {
  uint64_t file_bytes = uint64_t(4) << 30;      // "file-bytes": bytes read from any one file
  uint64_t texture_pixels = uint64_t(1) << 28;  // "texture-pixels": pixels of one decoded texture image
  bool allow_outside_scene_folder = false;      // --allow-outside-scene-folder
  // The budgets of docs/SECURITY.md beyond the files: each is checked before the allocation or the
  // work it bounds, against counts that every reference (instance, morph target, sampler) adds to.
  uint64_t vertex_data = uint64_t(64) << 30;      // "vertex-data": bytes of decoded vertex data
  uint64_t animation_data = uint64_t(256) << 20;  // "animation-data": bytes of decoded animation keys
  uint64_t json_bytes = uint64_t(32) << 20;       // "json-bytes": bytes of a scene's JSON text
  uint64_t framing_work = uint64_t(1) << 34;      // "framing-work": vertex-poses the framing may pose
  uint64_t tile_queue = uint64_t(1) << 30;        // "tile-queue": tile-queue entries of one frame
  uint64_t memory = 0;                            // "memory": bytes; 0 = automatic (memory_budget.h)
};

// Parses --limit's value into `limits`: KEY=VALUE pairs separated by commas, VALUE a positive integer
// with an optional K, M, G or T suffix (powers of 1024). Throws pmr::Error naming the bad pair.
void parse_limits(const std::string& text, InputLimits& limits);
// The --help lines that list the keys and their defaults.
std::string limit_help();

// Outcome of check_input_file / read_input_file.
struct InputFile {
  enum class Status { Ok, NotFound, Outside, NotRegular, TooLarge, Unreadable };
  Status status = Status::Ok;
  std::string reason;                // why not, for a message ("is not a regular file (a FIFO)"); "" when Ok
  std::string real_path;             // the file after resolving symlinks and ".." (when found)
  std::vector<unsigned char> bytes;  // read_input_file only
};

// The canonical path of a folder (realpath), or "" when it cannot be resolved.
std::string real_folder(const std::string& folder);

// Resolves `path` (realpath: symlinks and ".." followed), requires it to lie inside `confine_to` (a
// real_folder result; "" = anywhere), to be a regular file and to have at most `max_bytes` bytes. Does
// not open it.
InputFile check_input_file(const std::string& path, const std::string& confine_to, uint64_t max_bytes);
// check_input_file, then reads the whole file (opened non-blocking, its type and size checked again on
// the open descriptor).
InputFile read_input_file(const std::string& path, const std::string& confine_to, uint64_t max_bytes);

// A file the user named (the scene, --environment, --display-config): read_input_file without
// confinement; throws pmr::Error("<path>: <reason>") unless it is Ok.
std::vector<unsigned char> read_user_file(const std::string& path, uint64_t max_bytes);

}  // namespace pmr
