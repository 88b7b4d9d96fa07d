#include "pmr/memory_budget.h"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <mutex>
#include <sstream>

#include "pmr/error.h"

namespace pmr {
namespace {

// "MemAvailable:   22945728 kB" -> bytes; 0 when absent.
uint64_t meminfo_field(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, key.size(), key) == 0 && line.size() > key.size() && line[key.size()] == ':') {
      std::istringstream value(line.substr(key.size() + 1));
      uint64_t kb = 0;
      if (value >> kb) return kb * 1024;
    }
  return 0;
}

// A cgroup file holding one number ("max" = no limit: 0).
uint64_t cgroup_number(const std::string& path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text == "max") return 0;
  try {
    return std::stoull(text);
  } catch (...) {
    return 0;
  }
}

// The smallest memory.max - memory.current along the process's cgroup v2 path up to the root: a
// parent's limit binds its children too. 0 when no cgroup limits memory (or cgroup v2 is absent).
uint64_t cgroup_left() {
  std::ifstream in("/proc/self/cgroup");
  std::string line, path;
  while (std::getline(in, line))
    if (line.rfind("0::", 0) == 0) path = line.substr(3);
  if (path.empty()) return 0;
  uint64_t left = 0;
  for (;;) {
    const std::string dir = "/sys/fs/cgroup" + (path == "/" ? std::string() : path);
    const uint64_t max = cgroup_number(dir + "/memory.max");
    if (max > 0) {
      const uint64_t current = cgroup_number(dir + "/memory.current");
      const uint64_t here = max > current ? max - current : 1;
      left = left ? std::min(left, here) : here;
    }
    if (path == "/" || path.empty()) break;
    const size_t slash = path.find_last_of('/');
    path = slash == 0 || slash == std::string::npos ? "/" : path.substr(0, slash);
  }
  return left;
}

std::atomic<uint64_t> g_budget{0};  // 0: not yet set or computed
std::atomic<int64_t> g_device{0};
std::string g_source;  // what decided the budget
std::mutex g_mutex;

uint64_t mib(uint64_t bytes) { return (bytes + (uint64_t(1) << 20) - 1) >> 20; }

}  // namespace

MemoryFacts read_memory_facts() {
  MemoryFacts f;
  f.mem_available = meminfo_field("/proc/meminfo", "MemAvailable");
  f.cgroup_left = cgroup_left();
  struct rlimit as {};
  if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    const uint64_t used = meminfo_field("/proc/self/status", "VmSize");
    f.address_left = uint64_t(as.rlim_cur) > used ? uint64_t(as.rlim_cur) - used : 1;
  }
  return f;
}

uint64_t automatic_memory_budget(const MemoryFacts& facts, std::string* source) {
  uint64_t m = UINT64_MAX;
  std::string from = "no memory limit found";
  const std::pair<uint64_t, const char*> candidates[] = {{facts.mem_available, "MemAvailable"},
                                                         {facts.cgroup_left, "the cgroup's memory.max"},
                                                         {facts.address_left, "RLIMIT_AS"}};
  for (const auto& [value, name] : candidates)
    if (value > 0 && value < m) m = value, from = std::string(name) + ", less a margin";
  if (source) *source = from;
  if (m == UINT64_MAX) return m;
  const uint64_t margin = m / 8 + (uint64_t(64) << 20);
  return m > margin ? m - margin : 1;
}

void set_memory_budget(uint64_t bytes) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_budget = bytes;
  g_source = bytes ? "set by --limit memory" : "";
}

uint64_t memory_budget() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_budget == 0) g_budget = automatic_memory_budget(read_memory_facts(), &g_source);
  return g_budget;
}

void add_device_bytes(int64_t delta) { g_device += delta; }
uint64_t device_bytes_in_use() { return uint64_t(std::max<int64_t>(0, g_device.load())); }

void check_memory(uint64_t bytes, const std::string& what) {
  const uint64_t budget = memory_budget();
  const uint64_t used = device_bytes_in_use();
  const uint64_t left = budget > used ? budget - used : 0;
  if (bytes <= left) return;
  std::string source;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    source = g_source;
  }
  throw Error("out of memory: " + what + " needs " + std::to_string(mib(bytes)) + " MiB, but the memory budget of " +
              std::to_string(mib(budget)) + " MiB (" + source + ")" +
              (used ? " leaves " + std::to_string(left >> 20) + " MiB" : std::string()) +
              " (raise it with --limit memory=N)");
}

}  // namespace pmr
