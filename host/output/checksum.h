// Checksums of the bytes pmr reads (scene files, the display calibration) and, later, of what it
// writes: one fast non-cryptographic hash, XXH3-64 (libxxhash), printed as 16 lower-case hex digits
// in xxhsum's canonical order (most significant byte first, what `xxhsum -H3` shows). It detects
// changed inputs; it is no protection against someone forging a file on purpose.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace pmr {

// The algorithm's name as the sidecar records it.
constexpr const char* kChecksumAlgorithm = "XXH3-64";

// XXH3-64 (seed 0) of `size` bytes at `data`.
uint64_t checksum64(const void* data, size_t size);

// 16 lower-case hex digits, most significant first.
std::string checksum_hex(uint64_t h);

// checksum_hex(checksum64(data, size)).
std::string checksum_hex(const void* data, size_t size);

// The checksum (as checksum_hex) of a whole file, read in pieces; throws pmr::Error naming it when it
// cannot be read.
std::string checksum_file(const std::string& path);

// The same of what is left to read from an open descriptor (`name` for messages); `bytes` gets how many
// bytes were hashed.
std::string checksum_descriptor(int fd, const std::string& name, uint64_t* bytes = nullptr);

}  // namespace pmr
