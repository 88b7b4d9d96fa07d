// Atomic file creation (temporary name + rename) and the output-folder check.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <climits>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "output/interrupt.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/printable.h"

namespace pmr {
namespace {

namespace fs = std::filesystem;

std::atomic<unsigned> g_counter{0};

// Creates `path` exclusively (0666 minus the umask, like any new file). Returns errno, 0 on success.
int create_exclusive(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) return errno;
  ::close(fd);
  return 0;
}

// At most kTempNameExtra bytes longer than the name: ".", ".tmp-", the host (at most kHostBytes), "-",
// the pid and "-" the counter (at most 10 digits each).
constexpr size_t kHostBytes = 32;
constexpr size_t kTempNameExtra = 1 + 5 + kHostBytes + 1 + 10 + 1 + 10;

// This machine's name as temporary names carry it: letters, digits, '.' and '-' (others become '_'),
// cut to kHostBytes; "unknown" when the system has none.
const std::string& temp_host() {
  static const std::string host = [] {
    char buf[256] = {};
    std::string h;
    if (::gethostname(buf, sizeof buf - 1) == 0)
      for (const char* c = buf; *c && h.size() < kHostBytes; ++c)
        h += std::isalnum((unsigned char)*c) || *c == '.' || *c == '-' ? *c : '_';
    return h.empty() ? std::string("unknown") : h;
  }();
  return host;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 10 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

std::string temporary_name(const std::string& final_path) {
  const fs::path p(final_path);
  const std::string name = "." + p.filename().string() + ".tmp-" + temp_host() + "-" + std::to_string(::getpid()) +
                           "-" + std::to_string(g_counter.fetch_add(1));
  return (p.parent_path() / name).string();
}

bool parse_temporary_name(const std::string& file_name, TemporaryOwner& owner) {
  const size_t at = file_name.rfind(".tmp-");
  if (file_name.size() < 2 || file_name[0] != '.' || at == std::string::npos || at < 2) return false;
  const std::string tail = file_name.substr(at + 5);  // [host-]pid-n; a host may hold '-'
  const size_t last = tail.rfind('-');
  if (last == std::string::npos || !all_digits(tail.substr(last + 1))) return false;
  const std::string head = tail.substr(0, last);
  const size_t dash = head.rfind('-');
  const std::string pid = dash == std::string::npos ? head : head.substr(dash + 1);
  if (!all_digits(pid)) return false;
  owner.host = dash == std::string::npos ? std::string() : head.substr(0, dash);
  owner.pid = std::stol(pid);
  owner.this_host = owner.host == temp_host();
  owner.running = owner.this_host && owner.pid > 0 && (::kill(pid_t(owner.pid), 0) == 0 || errno == EPERM);
  return true;
}

size_t remove_dead_temporaries(const std::string& dir) {
  size_t removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    TemporaryOwner owner;
    const std::string name = it->path().filename().string();
    // only this host's, and only a process that is gone: the folder may be shared by nodes over NFS
    if (parse_temporary_name(name, owner) && owner.this_host && !owner.running && it->is_regular_file(ec) &&
        ::unlink(it->path().c_str()) == 0)
      ++removed;
  }
  return removed;
}

namespace {

// What a file pmr writes may replace: nothing, or a regular file. A device, a FIFO, a socket, a folder
// or a symbolic link at the path is somebody else's and is refused (a rename would replace it: as
// root, /dev/full became a regular file).
void check_replaceable(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return;
  const char* kind = S_ISLNK(st.st_mode)    ? "a symbolic link"
                     : S_ISDIR(st.st_mode)  ? "a folder"
                     : S_ISFIFO(st.st_mode) ? "a FIFO"
                     : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                                                                  : "a special file";
  throw Error("cannot write " + printable_text(path) + ": it exists and is " + kind +
              ", not a regular file (pmr replaces only regular files)");
}

}  // namespace

AtomicFile::AtomicFile(std::string final_path) : final_path_(std::move(final_path)) {
  const fs::path p(final_path_);
  if (final_path_.empty() || !p.has_filename()) throw Error("cannot write '" + final_path_ + "': not a file name");
  check_replaceable(final_path_);
  int err = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    temp_path_ = temporary_name(final_path_);
    slot_ = register_temp_file(temp_path_);  // before it exists: a signal in between cannot leak it
    err = create_exclusive(temp_path_);
    if (err != EEXIST) break;
    unregister_temp_file(slot_);  // someone else's file of that name: not ours to remove
    slot_ = -1;
  }
  if (err != 0) {
    unregister_temp_file(slot_);
    slot_ = -1;
    const std::string reason = std::strerror(err);
    temp_path_.clear();
    throw Error("cannot write " + final_path_ + ": cannot create a file in its folder: " + reason);
  }
}

AtomicFile::~AtomicFile() {
  unregister_temp_file(slot_);
  if (!committed_ && !temp_path_.empty()) ::unlink(temp_path_.c_str());
}

void AtomicFile::commit() {
  if (committed_) return;
  if (std::rename(temp_path_.c_str(), final_path_.c_str()) != 0)
    throw Error("cannot write " + final_path_ + ": cannot rename the finished temporary file " + temp_path_ +
                " into place: " + std::strerror(errno));
  committed_ = true;
  unregister_temp_file(slot_);
  slot_ = -1;
}

void write_text_atomic(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary | std::ios::trunc);
    if (out) out.write(text.data(), std::streamsize(text.size()));
    if (out) out.close();
    if (!out) throw Error("cannot write " + path + ": " + write_failure(errno));
  }
  file.commit();
}

bool prepare_output_dir(const std::string& dir) {
  const std::string what = "cannot write to output folder " + dir + ": ";
  if (dir.empty()) throw Error("cannot write to output folder '': empty path");
  std::error_code ec;
  const fs::path p(dir);
  const fs::file_status st = fs::status(p, ec);
  const bool created = !fs::exists(st);
  if (!created) {
    if (!fs::is_directory(st)) throw Error(what + "exists and is not a folder");
  } else {
    fs::create_directories(p, ec);
    if (ec) throw Error(what + ec.message());
    if (!fs::is_directory(p, ec)) throw Error(what + "could not create it");
  }
  // Probe: create and remove a file (access(W_OK) would not tell the truth for root or read-only mounts).
  const std::string probe = temporary_name((p / "pmr-write-probe").string());
  const int err = create_exclusive(probe);
  if (err != 0) throw Error(what + std::strerror(err));
  if (::unlink(probe.c_str()) != 0)
    throw Error(what + "cannot remove the probe file " + probe + ": " + std::strerror(errno));
  return created;
}

void check_output_dir(const std::string& dir) {
  const std::string what = "cannot write to output folder " + dir + ": ";
  if (dir.empty()) throw Error("cannot write to output folder '': empty path");
  std::error_code ec;
  fs::path p(dir);
  const fs::file_status st = fs::status(p, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) throw Error(what + "exists and is not a folder");
    return;
  }
  // the nearest existing ancestor must be a folder for create_directories to succeed
  for (p = fs::absolute(p, ec).parent_path(); !p.empty(); p = p.parent_path()) {
    const fs::file_status up = fs::status(p, ec);
    if (fs::exists(up)) {
      if (!fs::is_directory(up)) throw Error(what + p.string() + " is not a folder");
      return;
    }
    if (p == p.root_path()) return;
  }
}

std::string write_failure(const std::string& reason) {
  const std::string too_large = std::strerror(EFBIG), named = "file size limit reached";
  if (reason.find(too_large) == std::string::npos || reason.find(named) != std::string::npos) return reason;
  return named + " (" + reason + ")";
}

std::string write_failure(int err) { return write_failure(std::string(std::strerror(err))); }

size_t max_output_file_name() { return NAME_MAX - kTempNameExtra; }

}  // namespace pmr
