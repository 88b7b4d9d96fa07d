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
  uint64_t pose_work = uint64_t(1) << 28;         // "pose-work": work units of posing one frame
  uint64_t framing_work = uint64_t(1) << 34;      // "framing-work": work units of all the framing's poses
  uint64_t tile_queue = uint64_t(1) << 30;        // "tile-queue": tile-queue entries of one frame
  uint64_t frame_work = uint64_t(600000000000);  // "frame-work": work units of one frame (about ns: 10 min)
  uint64_t memory = 0;                            // "memory": bytes; 0 = automatic (memory_budget.h)
};

// Parses --limit's value into `limits`: KEY=VALUE pairs separated by commas, VALUE a positive integer
// with an optional K, M, G or T suffix (powers of 1024). Throws pmr::Error naming the bad pair.
void parse_limits(const std::string& text, InputLimits& limits);
// The --help lines that list the keys and their defaults.
std::string limit_help();

// Outcome of read_input_file.
struct InputFile {
  enum class Status { Ok, NotFound, Outside, NotRegular, TooLarge, Unreadable };
  Status status = Status::Ok;
  std::string reason;                // why not, for a message ("is not a regular file (a FIFO)"); "" when Ok
  std::vector<unsigned char> bytes;  // the file's bytes, when Ok
};

// The canonical path of a folder (realpath), or "" when it cannot be resolved.
std::string real_folder(const std::string& folder);

// The scene's folder, opened once: every file a scene names is opened beneath this descriptor, so no
// path resolved earlier is trusted later (docs/SECURITY.md, "Confinement"). Move-only.
class InputFolder {
 public:
  InputFolder() = default;
  explicit InputFolder(const std::string& folder);  // !ok() when it cannot be opened
  InputFolder(InputFolder&& o) noexcept;
  InputFolder& operator=(InputFolder&& o) noexcept;
  InputFolder(const InputFolder&) = delete;
  InputFolder& operator=(const InputFolder&) = delete;
  ~InputFolder();
  bool ok() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  const std::string& path() const { return path_; }  // as given, for messages

 private:
  int fd_ = -1;
  std::string path_;
};

// A file opened for reading by open_input: its type and size were checked on the open descriptor, and
// read() reads exactly what was opened. Move-only; closes the descriptor when it goes.
class OpenInput {
 public:
  InputFile::Status status = InputFile::Status::Ok;
  std::string reason;  // why not ("is not a regular file (a FIFO)"); "" when Ok
  uint64_t size = 0;   // bytes, when Ok

  OpenInput() = default;
  OpenInput(OpenInput&& o) noexcept;
  OpenInput& operator=(OpenInput&& o) noexcept;
  OpenInput(const OpenInput&) = delete;
  OpenInput& operator=(const OpenInput&) = delete;
  ~OpenInput();
  // Reads the whole file into `out`; false (status Unreadable, a reason) when it cannot.
  bool read(std::vector<unsigned char>& out);

 private:
  friend OpenInput open_input(const std::string&, const InputFolder*, uint64_t);
  int fd_ = -1;
};

// Opens `path` for reading, non-blocking (a FIFO never waits for a writer), and requires a regular
// file of at most `max_bytes` bytes. With `beneath`, `path` is relative to that folder and the open
// itself cannot leave it: openat2 with RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS where the kernel has
// it (symbolic links that stay inside are followed), else a walk one component at a time with
// O_NOFOLLOW that refuses every symbolic link and resolves ".." by name (status Outside when either
// would leave the folder). Without `beneath` any path is opened, symbolic links followed.
OpenInput open_input(const std::string& path, const InputFolder* beneath, uint64_t max_bytes);

// Tests only: the component walk instead of openat2, as on a kernel without it.
void force_confinement_walk(bool on);

// open_input without confinement, then the whole file read.
InputFile read_input_file(const std::string& path, uint64_t max_bytes);

// A file the user named (the scene, --environment, --display-config): read_input_file; throws pmr::Error("<path>: <reason>") unless it is Ok.
std::vector<unsigned char> read_user_file(const std::string& path, uint64_t max_bytes);

}  // namespace pmr
