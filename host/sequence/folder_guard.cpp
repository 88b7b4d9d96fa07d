#include "sequence/folder_guard.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include "sequence/frame_names.h"
#include "output/interrupt.h"
#include "pmr/error.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "sequence/frame_files.h"
#include "sequence/frame_list.h"

namespace pmr {

namespace {

namespace fs = std::filesystem;

const std::string kLockPrefix = ".pmr-lock-";
constexpr size_t kHexDigits = 16;
// ".pmr-lock-" + 16 hex digits (the pattern) + "-" + 16 hex digits (the configuration)
const size_t kLockNameSize = kLockPrefix.size() + kHexDigits + 1 + kHexDigits;

// FNV-1a, 64 bits: the same on every machine and build (std::hash is not specified to be).
std::string hash_hex(const std::string& text) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  char buf[kHexDigits + 1];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)h);
  return buf;
}

bool is_lock_name(const std::string& name) {
  if (name.size() != kLockNameSize || name.compare(0, kLockPrefix.size(), kLockPrefix) != 0) return false;
  for (size_t i = kLockPrefix.size(); i < name.size(); ++i) {
    const bool dash = i == kLockPrefix.size() + kHexDigits;
    if (dash ? name[i] != '-' : !std::isxdigit((unsigned char)name[i])) return false;
  }
  return true;
}

bool same_file(int fd, const std::string& path) {
  struct stat a, b;
  return ::fstat(fd, &a) == 0 && ::stat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

// Opens for reading and writing (fcntl-emulated flock over NFS needs write access for an exclusive
// lock), else read-only (someone else's file). A lock is a regular file that pmr created: a symlink is
// not followed (ELOOP), a FIFO does not block the open, and anything but a regular file is refused
// (EINVAL), so a planted name cannot make pmr read a device or wait on a pipe.
int open_lock(const std::string& path) {
  const int flags = O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK;
  int fd = ::open(path.c_str(), O_RDWR | flags);
  if (fd < 0 && errno == EACCES) fd = ::open(path.c_str(), O_RDONLY | flags);
  struct stat st;
  if (fd >= 0 && (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))) {
    ::close(fd);
    errno = EINVAL;
    return -1;
  }
  return fd;
}

bool write_all(int fd, const std::string& text) {
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

// Creates the lock file with its content complete before its name appears (written under a temporary
// name, then hard-linked: link never replaces a file that another process created meanwhile). Returns
// errno (0 also when someone else created it first).
int create_lock_file(const std::string& path, const std::string& text) {
  const std::string temp = temporary_name(path);
  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0 && errno == EEXIST) {  // left by a dead process of this host that had our process id
    ::unlink(temp.c_str());
    fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  }
  if (fd < 0) return errno;
  const bool ok = write_all(fd, text);
  const int write_err = ok ? 0 : (errno ? errno : EIO);
  ::close(fd);
  int err = write_err;
  if (ok && ::link(temp.c_str(), path.c_str()) != 0 && errno != EEXIST) {
    // a file system without hard links: create it in place (its content may show partly for a moment)
    const int out = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (out >= 0) {
      if (!write_all(out, text)) err = errno ? errno : EIO;
      ::close(out);
    } else if (errno != EEXIST) {
      err = errno;
    }
  }
  ::unlink(temp.c_str());
  return err;
}

// A lock's text: its configuration (a sidecar, a few KB per view count's matrices). One longer than
// kLockTextLimit is not pmr's: read no further, and report it as unrecorded (empty).
constexpr off_t kLockTextLimit = off_t(4) << 20;

std::string read_lock_text(int fd) {
  std::string text;
  char buf[65536];
  off_t at = 0;
  for (;;) {
    const ssize_t n = ::pread(fd, buf, sizeof buf, at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buf, size_t(n));
    at += n;
    if (at > kLockTextLimit) return std::string();
  }
  return text;
}

// The configuration difference of a sidecar from this run's, compared without its view matrices (most
// of a sidecar with many views; 48 views: 1.3 -> 0.23 ms per comparison). A cut that does not parse (a
// sidecar not laid out as pmr writes them) is compared whole.
class ConfigDifference {
 public:
  explicit ConfigDifference(const std::string& expected)
      : expected_(expected), expected_config_(without_view_matrices(expected)) {}

  std::string operator()(const std::string& text) const {
    const std::string diff = sidecar_config_difference(without_view_matrices(text), expected_config_);
    return diff == "unreadable" ? sidecar_config_difference(text, expected_) : diff;
  }

 private:
  const std::string& expected_;
  const std::string expected_config_;
};

// 1. This run's lock: shared with every process of the same configuration. Returns its descriptor, or
// -1 with lock_path cleared when the file system cannot lock (the run goes on unguarded).
int take_own_lock(const std::string& dir, const std::string& own_name, const std::string& expected,
                  std::string& lock_path) {
  int held = -1;
  for (int attempt = 0; attempt < 20 && held < 0; ++attempt) {
    struct stat st;
    if (::stat(lock_path.c_str(), &st) != 0) {
      if (const int err = create_lock_file(lock_path, expected))
        throw Error("cannot lock output folder " + dir + ": cannot create " + own_name + ": " + std::strerror(err));
    }
    const int fd = open_lock(lock_path);
    if (fd < 0) {
      if (errno == ENOENT) continue;  // removed as stale by another process meanwhile
      throw Error("cannot lock output folder " + dir + ": cannot open " + own_name + ": " +
                  (errno == ELOOP    ? std::string("it is a symbolic link, not a lock pmr made")
                   : errno == EINVAL ? std::string("it is not a regular file")
                                     : std::string(std::strerror(errno))));
    }
    int rc;
    while ((rc = ::flock(fd, LOCK_SH)) != 0 && errno == EINTR) {}
    if (rc != 0) {  // e.g. ENOLCK: an NFS mount without lock support
      std::fprintf(stderr,
                   "pmr: warning: cannot lock output folder %s (%s): another configuration rendering into it "
                   "at the same time would not be noticed\n",
                   dir.c_str(), std::strerror(errno));
      ::close(fd);
      ::unlink(lock_path.c_str());
      lock_path.clear();
      return -1;
    }
    if (same_file(fd, lock_path)) held = fd;
    else ::close(fd);  // the name was removed (stale) after we opened it: take the new one
  }
  if (held < 0) throw Error("cannot lock output folder " + dir + ": " + own_name + " keeps being replaced");
  return held;
}

struct FolderContents {
  std::vector<std::string> locks;                      // of the same --name pattern, besides this run's
  std::vector<std::pair<long, std::string>> sidecars;  // the pattern names, outside the job; by frame
};

// One pass over the folder for both.
FolderContents scan_folder(const std::string& dir, const std::string& pattern, std::vector<long> job,
                           const std::string& own_name) {
  const std::string same_pattern = own_name.substr(0, kLockPrefix.size() + kHexDigits + 1);
  FolderContents found;
  std::sort(job.begin(), job.end());
  DIR* d = ::opendir(dir.c_str());
  if (!d) throw Error("cannot read output folder " + dir + ": " + std::strerror(errno));
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name[0] == '.') {
      if (name != own_name && name.compare(0, same_pattern.size(), same_pattern) == 0 && is_lock_name(name))
        found.locks.push_back(name);
      continue;
    }
    const long f = sidecar_frame(pattern, name);
    if (f >= 0 && !std::binary_search(job.begin(), job.end(), f)) found.sidecars.emplace_back(f, name);
  }
  ::closedir(d);
  std::sort(found.sidecars.begin(), found.sidecars.end());
  return found;
}

// 2. Other configurations' locks: held = a process renders into this folder right now.
void refuse_running_configurations(const std::string& dir, const std::vector<std::string>& locks,
                                   const ConfigDifference& difference) {
  for (const std::string& name : locks) {
    const std::string path = (fs::path(dir) / name).string();
    const int fd = open_lock(path);
    if (fd < 0) continue;  // gone
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
      if (same_file(fd, path)) ::unlink(path.c_str());  // nobody holds it: stale
      ::close(fd);
      continue;
    }
    const bool held = errno == EWOULDBLOCK;
    const std::string text = held ? read_lock_text(fd) : std::string();
    ::close(fd);
    if (!held) continue;  // cannot tell (e.g. a read-only file over NFS)
    const std::string diff = difference(text);
    if (diff.empty()) continue;  // the same configuration under another fingerprint (e.g. other --write)
    throw Error(dir + " is being rendered right now by a pmr process with another configuration (" +
                (diff == "unreadable" ? std::string("unrecorded") : diff + " differs") + "; it holds " + name +
                "); wait for it, use another --out, or delete " + name + " if no such process is running");
  }
}

// 3. Finished frames outside this job (every shard's frames count as this job's).
void check_finished_frames(const std::string& dir, const std::vector<std::pair<long, std::string>>& sidecars,
                           const ConfigDifference& difference, bool overwrite, bool quiet) {
  if (sidecars.size() >= 10000 && !quiet)  // about 0.3 ms each (48 views): say why the start takes a while
    std::fprintf(stderr, "pmr: comparing the configuration of %zu frame(s) outside --frames in %s\n", sidecars.size(),
                 dir.c_str());
  long others = 0;
  std::string first_name, first_diff;
  for (const auto& [frame, name] : sidecars) {
    const std::string diff = difference(read_sidecar_text((fs::path(dir) / name).string()));
    // unreadable: a broken frame, not a configuration (pmr verify reports it)
    if (diff.empty() || diff == "unreadable") continue;
    if (others++ == 0) first_name = name, first_diff = diff;
    if (!overwrite) break;  // one is enough to refuse
  }
  if (others > 0 && !overwrite)
    throw Error(dir + " holds " + first_name + " rendered with another configuration (" + first_diff +
                " differs) that this run would not replace; use another --out, render those frames too, or "
                "--overwrite");
  if (others > 0)
    std::fprintf(stderr,
                 "pmr: warning: --overwrite: %s keeps %ld frame(s) of another configuration that this run "
                 "does not replace (%s: %s differs)\n",
                 dir.c_str(), others, first_name.c_str(), first_diff.c_str());
}

}  // namespace

std::string without_view_matrices(const std::string& sidecar) {
  // The layout sidecar_json writes: top-level members indented by two spaces, everything nested deeper
  // (JSON strings hold no raw newline), so the first "\n  ]" after the member closes its array.
  const std::string open = ",\n  \"views\": [", close = "\n  ]";
  const size_t begin = sidecar.find(open);
  if (begin == std::string::npos) return sidecar;
  const size_t end = sidecar.find(close, begin + open.size());
  if (end == std::string::npos) return sidecar;
  return sidecar.substr(0, begin) + sidecar.substr(end + close.size());
}

std::string folder_lock_name(const std::string& pattern, const std::string& expected) {
  // canonical: frame_#### and frame_%04d name the same files
  return kLockPrefix + hash_hex(canonical_name_pattern(pattern)) + "-" + hash_hex(expected);
}

long sidecar_frame(const std::string& pattern, const std::string& file_name) {
  const std::string ext = ".json";
  if (file_name.size() <= ext.size() || file_name.compare(file_name.size() - ext.size(), ext.size(), ext) != 0)
    return -1;
  const std::string stem = file_name.substr(0, file_name.size() - ext.size());
  const NamePattern name = parse_name_pattern(pattern);
  if (!name.has_field) return -1;  // the stem of one frame, whichever its number: always this job's
  const std::string &prefix = name.prefix, &suffix = name.suffix;
  if (stem.size() <= prefix.size() + suffix.size() || stem.compare(0, prefix.size(), prefix) != 0 ||
      stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) != 0)
    return -1;
  const std::string number = stem.substr(prefix.size(), stem.size() - prefix.size() - suffix.size());
  if (number.empty() || number.size() > 8) return -1;
  for (char c : number)
    if (!std::isdigit((unsigned char)c)) return -1;
  const long frame = std::stol(number);
  // the pattern must make exactly this name (padding included)
  if (frame > kMaxFrame || frame_stem(pattern, frame) != stem) return -1;
  return frame;
}

FolderGuard::FolderGuard(const std::string& dir, const std::string& pattern, const std::vector<long>& job_frames,
                         const std::string& expected, bool overwrite, bool quiet) {
  const std::string own_name = folder_lock_name(pattern, expected);
  const ConfigDifference difference(expected);
  lock_path_ = (fs::path(dir) / own_name).string();
  fd_ = take_own_lock(dir, own_name, expected, lock_path_);
  release_at_exit(this);
  if (fd_ >= 0) register_lock_file(fd_, lock_path_);
  try {
    const FolderContents found = scan_folder(dir, pattern, job_frames, own_name);
    refuse_running_configurations(dir, found.locks, difference);
    check_finished_frames(dir, found.sidecars, difference, overwrite, quiet);
  } catch (...) {
    release();  // a throwing constructor runs no destructor
    throw;
  }
}

FolderGuard::~FolderGuard() { release(); }

// A library that gives up calls exit() (PoCL's LLVM on a failed write: "LLVM ERROR: IO failure on output
// stream"), which runs no destructor: the guard of the run, if any, is released by an exit handler then.
void FolderGuard::release_at_exit(FolderGuard* guard) {
  static std::atomic<FolderGuard*> live{nullptr};
  static const int registered = std::atexit([] {
    if (FolderGuard* g = live.exchange(nullptr)) g->release();
  });
  (void)registered;
  live.store(guard);
  guard->live_ = &live;
}

void FolderGuard::release() {
  if (live_) {
    FolderGuard* self = this;
    live_->compare_exchange_strong(self, nullptr);
    live_ = nullptr;
  }
  if (fd_ < 0) return;
  unregister_lock_file();
  // the last process of this configuration removes the file (exclusive = nobody else holds it)
  remove_lock_if_last(fd_, lock_path_.c_str());
  ::close(fd_);
  fd_ = -1;
}

}  // namespace pmr
