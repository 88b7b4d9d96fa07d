#include "pmr/input_files.h"

#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "pmr/error.h"

namespace pmr {

namespace {

struct LimitKey {
  const char* name;
  uint64_t InputLimits::*field;
  const char* what;
};

const LimitKey kLimitKeys[] = {
    {"file-bytes", &InputLimits::file_bytes,
     "bytes read from one file (the scene, each buffer and image it\n"
     "                         names, --display-config)"},
    {"texture-pixels", &InputLimits::texture_pixels, "pixels (width x height) of one decoded texture image"},
    {"vertex-data", &InputLimits::vertex_data,
     "bytes of decoded vertex data, every instance and morph target\n"
     "                         counted"},
    {"animation-data", &InputLimits::animation_data, "bytes of decoded animation keys, every sampler counted"},
    {"json-bytes", &InputLimits::json_bytes, "bytes of the scene's JSON (a .gltf file, a .glb's JSON chunk)"},
    {"pose-work", &InputLimits::pose_work,
     "work of posing one frame (about one unit per vertex and morph\n"
     "                         target; docs/SECURITY.md, \"Posing\")"},
    {"framing-work", &InputLimits::framing_work, "work of all the poses that frame an animation (same units)"},
    {"tile-queue", &InputLimits::tile_queue, "tile-queue entries of one frame"},
    {"frame-work", &InputLimits::frame_work,
     "work of rendering one frame: light evaluations and BLEND\n"
     "                         fragments, about a nanosecond a unit (docs/SECURITY.md,\n"
     "                         \"Frame work\")"},
    {"memory", &InputLimits::memory, "bytes of memory for the large host and device allocations"},
};

// "4294967296", "4G", "256M": a positive integer, optionally times 1024^n.
bool parse_amount(const std::string& text, uint64_t& out) {
  if (text.empty() || text[0] < '0' || text[0] > '9') return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (errno != 0) return false;
  int shift = 0;
  const std::string suffix(end);
  if (suffix == "K" || suffix == "k") shift = 10;
  else if (suffix == "M") shift = 20;
  else if (suffix == "G") shift = 30;
  else if (suffix == "T") shift = 40;
  else if (!suffix.empty()) return false;
  if (v == 0 || (shift && v > (UINT64_MAX >> shift))) return false;
  out = uint64_t(v) << shift;
  return true;
}

const char* file_type(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

InputFile refused(InputFile::Status status, const std::string& reason) {
  InputFile f;
  f.status = status;
  f.reason = reason;
  return f;
}

OpenInput as_open(const InputFile& f) {
  OpenInput o;
  o.status = f.status;
  o.reason = f.reason;
  return o;
}

// The type and size checks, shared by the path (before opening) and the open descriptor (after).
bool acceptable(const struct stat& st, uint64_t max_bytes, InputFile& f) {
  if (!S_ISREG(st.st_mode)) {
    f.status = InputFile::Status::NotRegular;
    f.reason = std::string("is not a regular file (") + file_type(st.st_mode) + ")";
    return false;
  }
  if (uint64_t(st.st_size) > max_bytes) {
    f.status = InputFile::Status::TooLarge;
    f.reason = "has " + std::to_string(st.st_size) + " bytes, more than the file-bytes limit of " +
               std::to_string(max_bytes) + " (raise it with --limit file-bytes=N)";
    return false;
  }
  return true;
}

}  // namespace

void parse_limits(const std::string& text, InputLimits& limits) {
  std::stringstream ss(text);
  std::string pair;
  bool any = false;
  while (std::getline(ss, pair, ',')) {
    any = true;
    const size_t eq = pair.find('=');
    const std::string key = pair.substr(0, eq);
    const LimitKey* k = nullptr;
    for (const LimitKey& candidate : kLimitKeys)
      if (key == candidate.name) k = &candidate;
    if (!k || eq == std::string::npos) {
      std::string keys;
      for (const LimitKey& candidate : kLimitKeys) keys += std::string(keys.empty() ? "" : ", ") + candidate.name;
      throw Error("invalid --limit '" + pair + "': expected KEY=VALUE with KEY one of " + keys);
    }
    uint64_t v = 0;
    if (!parse_amount(pair.substr(eq + 1), v))
      throw Error("invalid --limit '" + pair +
                  "': expected a positive integer, optionally with K, M, G or T (x1024^n)");
    limits.*(k->field) = v;
  }
  if (!any) throw Error("invalid --limit '': expected KEY=VALUE[,KEY=VALUE...]");
}

std::string limit_help() {
  const InputLimits defaults;
  std::string out;
  for (const LimitKey& k : kLimitKeys) {
    const uint64_t v = defaults.*(k.field);
    out +=
        "                         " + std::string(k.name) + ": " + k.what +
        (v ? " (default " + std::to_string(v) + ")\n"
           : std::string("\n                         (default: the smallest of MemAvailable, the cgroup's memory.max "
                         "and\n                         RLIMIT_AS, less a margin)\n"));
  }
  return out;
}

std::string real_folder(const std::string& folder) {
  char* real = realpath(folder.c_str(), nullptr);
  if (!real) return "";
  std::string out(real);
  std::free(real);
  return out;
}

InputFolder::InputFolder(const std::string& folder)
    : fd_(open(folder.c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC)), path_(folder) {}
InputFolder::InputFolder(InputFolder&& o) noexcept : fd_(o.fd_), path_(std::move(o.path_)) { o.fd_ = -1; }
InputFolder& InputFolder::operator=(InputFolder&& o) noexcept {
  std::swap(fd_, o.fd_);
  std::swap(path_, o.path_);
  return *this;
}
InputFolder::~InputFolder() {
  if (fd_ >= 0) close(fd_);
}

OpenInput::OpenInput(OpenInput&& o) noexcept : status(o.status), reason(std::move(o.reason)), size(o.size), fd_(o.fd_) {
  o.fd_ = -1;
}
OpenInput& OpenInput::operator=(OpenInput&& o) noexcept {
  std::swap(status, o.status);
  std::swap(reason, o.reason);
  std::swap(size, o.size);
  std::swap(fd_, o.fd_);
  return *this;
}
OpenInput::~OpenInput() {
  if (fd_ >= 0) close(fd_);
}

bool OpenInput::read(std::vector<unsigned char>& out) {
  auto unreadable = [&](const std::string& why) {
    status = InputFile::Status::Unreadable;
    reason = "cannot be read (" + why + ")";
    out.clear();
    return false;
  };
  if (fd_ < 0 || status != InputFile::Status::Ok) return unreadable("not open");
  try {
    out.resize(size_t(size));
  } catch (const std::bad_alloc&) {
    return unreadable("out of memory for " + std::to_string(size) + " bytes");
  }
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::read(fd_, out.data() + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return unreadable(n < 0 ? std::strerror(errno) : "the file shrank while being read");
    done += size_t(n);
  }
  return true;
}

namespace {

bool walk_forced = false;
constexpr int kReadFlags = O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY;

// Why an open failed, as a status and a reason. EXDEV is openat2's "would leave the folder".
OpenInput open_failed(int err) {
  if (err == ENOENT || err == ENOTDIR) return as_open(refused(InputFile::Status::NotFound, "not found"));
  if (err == EXDEV) return as_open(refused(InputFile::Status::Outside, "lies outside the scene folder"));
  return as_open(refused(InputFile::Status::Unreadable, std::string("cannot be opened (") + std::strerror(err) + ")"));
}

// The component walk: ".." resolved by name (never above the folder), every component opened with
// O_NOFOLLOW relative to the one before, so a symbolic link anywhere on the way is refused rather than
// followed. Returns the descriptor, or -1 with `result` saying why.
int walk_beneath(int folder, const std::string& relative, OpenInput& result) {
  if (!relative.empty() && relative[0] == '/') return result = open_failed(EXDEV), -1;  // as openat2 does
  std::vector<std::string> parts;
  std::stringstream ss(relative);
  for (std::string part; std::getline(ss, part, '/');) {
    if (part.empty() || part == ".") continue;
    if (part != "..") parts.push_back(part);
    else if (parts.empty()) return result = open_failed(EXDEV), -1;
    else parts.pop_back();
  }
  if (parts.empty()) return result = open_failed(EISDIR), -1;
  int dir = folder;
  for (size_t i = 0; i < parts.size(); ++i) {
    const bool last = i + 1 == parts.size();
    const int fd =
        openat(dir, parts[i].c_str(), last ? kReadFlags | O_NOFOLLOW : O_PATH | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    const int err = errno;
    struct stat st {};
    const bool link = fd < 0 && fstatat(dir, parts[i].c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode);
    if (dir != folder) close(dir);
    if (link)
      return result = as_open(refused(InputFile::Status::Outside,
                                      "reaches a symbolic link ('" + parts[i] +
                                          "'), which the scene folder's confinement does not follow on this kernel")),
             -1;
    if (fd < 0) return result = open_failed(err), -1;
    dir = fd;
  }
  return dir;
}

// openat2 beneath the folder; the walk where the kernel (or a seccomp filter) lacks it.
int open_beneath(int folder, const std::string& relative, OpenInput& result) {
  if (!walk_forced) {
    open_how how{};
    how.flags = uint64_t(kReadFlags);
    how.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const long fd = syscall(SYS_openat2, folder, relative.c_str(), &how, sizeof how);
      if (fd >= 0) return int(fd);
      if (errno == EAGAIN || errno == EINTR) continue;  // a rename raced the lookup: look again
      if (errno == ENOSYS || errno == EPERM || errno == EINVAL) break;
      return result = open_failed(errno), -1;
    }
    if (errno == EAGAIN || errno == EINTR) return result = open_failed(EAGAIN), -1;
  }
  return walk_beneath(folder, relative, result);
}

}  // namespace

void force_confinement_walk(bool on) { walk_forced = on; }

OpenInput open_input(const std::string& path, const InputFolder* beneath, uint64_t max_bytes) {
  OpenInput result;
  int fd = -1;
  if (beneath) {
    fd = open_beneath(beneath->fd(), path, result);
    if (fd < 0) return result;
  } else {
    // a user's path: its type is checked before the open too, so no device is ever opened
    struct stat st {};
    InputFile f;
    if (stat(path.c_str(), &st) != 0) return open_failed(errno);
    if (!acceptable(st, max_bytes, f)) return as_open(f);
    fd = open(path.c_str(), kReadFlags);
    if (fd < 0) return open_failed(errno);
  }
  result.fd_ = fd;
  struct stat st {};
  if (fstat(fd, &st) != 0) return open_failed(errno);
  InputFile f;
  if (!acceptable(st, max_bytes, f)) return as_open(f);
  result.size = uint64_t(st.st_size);
  return result;
}

InputFile read_input_file(const std::string& path, uint64_t max_bytes) {
  OpenInput in = open_input(path, nullptr, max_bytes);
  InputFile f;
  if (in.status == InputFile::Status::Ok) in.read(f.bytes);
  f.status = in.status;
  f.reason = in.reason;
  return f;
}

std::vector<unsigned char> read_user_file(const std::string& path, uint64_t max_bytes) {
  InputFile f = read_input_file(path, max_bytes);
  if (f.status == InputFile::Status::NotFound) throw Error(path + ": file not found");
  if (f.status != InputFile::Status::Ok) throw Error(path + ": " + f.reason);
  return std::move(f.bytes);
}

}  // namespace pmr
