// Atomic file creation (temporary name + rename) and the output-folder check.
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
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

// "<dir>/.<name>.tmp-<pid>-<n>": hidden, in the same folder (so rename stays on one file system).
// At most kTempNameExtra bytes longer than the name (pid_t and the counter have at most 10 digits).
constexpr size_t kTempNameExtra = 1 + 5 + 10 + 1 + 10;
std::string temp_name(const fs::path& final_path) {
  const std::string name = "." + final_path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(g_counter.fetch_add(1));
  return (final_path.parent_path() / name).string();
}

}  // namespace

AtomicFile::AtomicFile(std::string final_path) : final_path_(std::move(final_path)) {
  const fs::path p(final_path_);
  if (final_path_.empty() || !p.has_filename()) throw Error("cannot write '" + final_path_ + "': not a file name");
  int err = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    temp_path_ = temp_name(p);
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
    if (!out) throw Error("cannot write " + path + ": " + std::strerror(errno));
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
  const std::string probe =
      (p / (".pmr-write-probe-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter.fetch_add(1)))).string();
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

size_t max_output_file_name() { return NAME_MAX - kTempNameExtra; }

}  // namespace pmr
