#include "output/checksum.h"

#include <xxhash.h>

namespace pmr {

uint64_t checksum64(const void* data, size_t size) { return XXH3_64bits(data, size); }

std::string checksum_hex(uint64_t h) {
  static const char digits[] = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, h >>= 4) s[size_t(i)] = digits[h & 15];
  return s;
}

std::string checksum_hex(const void* data, size_t size) { return checksum_hex(checksum64(data, size)); }

}  // namespace pmr
