#include "output/checksum.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <vector>

#include "pmr/error.h"

namespace pmr {

uint64_t checksum64(const void* data, size_t size) { return XXH3_64bits(data, size); }

std::string checksum_hex(uint64_t h) {
  static const char digits[] = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, h >>= 4) s[size_t(i)] = digits[h & 15];
  return s;
}

std::string checksum_hex(const void* data, size_t size) { return checksum_hex(checksum64(data, size)); }

namespace {

using XxhState = std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)>;

XxhState new_state(const std::string& name) {
  XxhState state(XXH3_createState(), XXH3_freeState);
  if (!state || XXH3_64bits_reset(state.get()) != XXH_OK) throw Error("cannot checksum " + name + ": out of memory");
  return state;
}

}  // namespace

std::string checksum_descriptor(int fd, const std::string& name, uint64_t* bytes) {
  const XxhState state = new_state(name);
  std::vector<char> piece(size_t(1) << 20);
  uint64_t total = 0;
  for (;;) {
    const ssize_t n = ::read(fd, piece.data(), piece.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error("cannot read " + name + ": " + std::strerror(errno));
    if (n == 0) break;
    XXH3_64bits_update(state.get(), piece.data(), size_t(n));
    total += uint64_t(n);
  }
  if (bytes) *bytes = total;
  return checksum_hex(XXH3_64bits_digest(state.get()));
}

std::string checksum_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error("cannot read " + path + ": " + std::strerror(errno));
  try {
    std::string sum = checksum_descriptor(fd, path);
    ::close(fd);
    return sum;
  } catch (...) {
    ::close(fd);
    throw;
  }
}

}  // namespace pmr
