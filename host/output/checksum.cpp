#include "output/checksum.h"

#include <xxhash.h>

#include <cerrno>
#include <cstring>
#include <fstream>
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

std::string checksum_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read " + path + ": " + std::strerror(errno));
  const std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state(XXH3_createState(), XXH3_freeState);
  if (!state || XXH3_64bits_reset(state.get()) != XXH_OK) throw Error("cannot checksum " + path + ": out of memory");
  std::vector<char> piece(size_t(1) << 20);
  while (in) {
    in.read(piece.data(), std::streamsize(piece.size()));
    if (in.gcount() > 0) XXH3_64bits_update(state.get(), piece.data(), size_t(in.gcount()));
  }
  if (!in.eof()) throw Error("cannot read " + path + ": read error");
  return checksum_hex(XXH3_64bits_digest(state.get()));
}

}  // namespace pmr
