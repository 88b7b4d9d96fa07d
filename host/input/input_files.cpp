#include "pmr/input_files.h"

#include <fcntl.h>
#include <sys/stat.h>
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
    {"framing-work", &InputLimits::framing_work, "vertices x poses the framing of an animation may pose"},
    {"tile-queue", &InputLimits::tile_queue, "tile-queue entries of one frame"},
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

InputFile check_input_file(const std::string& path, const std::string& confine_to, uint64_t max_bytes) {
  char* real = realpath(path.c_str(), nullptr);
  if (!real) {
    if (errno == ENOENT || errno == ENOTDIR) return refused(InputFile::Status::NotFound, "not found");
    return refused(InputFile::Status::Unreadable, std::string("cannot be resolved (") + std::strerror(errno) + ")");
  }
  InputFile f;
  f.real_path = real;
  std::free(real);
  if (!confine_to.empty()) {
    const std::string folder = confine_to.back() == '/' ? confine_to : confine_to + "/";
    if (f.real_path.compare(0, folder.size(), folder) != 0) {
      f.status = InputFile::Status::Outside;
      f.reason = "lies outside the scene folder (" + f.real_path + ")";
      return f;
    }
  }
  struct stat st {};
  if (stat(f.real_path.c_str(), &st) != 0) {
    f.status = InputFile::Status::Unreadable;
    f.reason = std::string("cannot be read (") + std::strerror(errno) + ")";
    return f;
  }
  acceptable(st, max_bytes, f);
  return f;
}

InputFile read_input_file(const std::string& path, const std::string& confine_to, uint64_t max_bytes) {
  InputFile f = check_input_file(path, confine_to, max_bytes);
  if (f.status != InputFile::Status::Ok) return f;
  auto unreadable = [&](const std::string& why) {
    f.status = InputFile::Status::Unreadable;
    f.reason = "cannot be read (" + why + ")";
    f.bytes.clear();
    return f;
  };
  // O_NONBLOCK: should the path have become a FIFO since the check, opening it must not wait for a writer.
  const int fd = open(f.real_path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return unreadable(std::strerror(errno));
  struct stat st {};
  if (fstat(fd, &st) != 0 || !acceptable(st, max_bytes, f)) {
    close(fd);
    if (f.status == InputFile::Status::Ok) return unreadable(std::strerror(errno));
    return f;
  }
  try {
    f.bytes.resize(size_t(st.st_size));
  } catch (const std::bad_alloc&) {
    close(fd);
    return unreadable("out of memory for " + std::to_string(st.st_size) + " bytes");
  }
  size_t done = 0;
  while (done < f.bytes.size()) {
    const ssize_t n = read(fd, f.bytes.data() + done, f.bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? std::strerror(errno) : "the file shrank while being read";
      close(fd);
      return unreadable(why);
    }
    done += size_t(n);
  }
  close(fd);
  return f;
}

std::vector<unsigned char> read_user_file(const std::string& path, uint64_t max_bytes) {
  InputFile f = read_input_file(path, "", max_bytes);
  if (f.status == InputFile::Status::NotFound) throw Error(path + ": file not found");
  if (f.status != InputFile::Status::Ok) throw Error(path + ": " + f.reason);
  return std::move(f.bytes);
}

}  // namespace pmr
