// The memory budget (docs/SECURITY.md, --limit memory=N): the large host and device allocations are
// checked against it before they are made, so that a scene or a configuration too large for the
// machine is one clear "out of memory" error (exit 1) instead of an allocation that overcommit lets
// through and the kernel's OOM killer, a cgroup limit or a failed PoCL assertion ends later.
#pragma once
#include <cstdint>
#include <string>

namespace pmr {

// What the automatic budget is computed from; 0 = no limit of that kind.
struct MemoryFacts {
  uint64_t mem_available = 0;  // /proc/meminfo MemAvailable
  uint64_t cgroup_left = 0;    // memory.max - memory.current of the process's cgroup (v2) or its parents
  uint64_t address_left = 0;   // RLIMIT_AS - VmSize (address space this process may still map)
};
MemoryFacts read_memory_facts();
// The smallest of the facts less a margin (an eighth, and 64 MiB for what is never counted: code,
// stacks, small allocations); `source` names the fact that decided it ("MemAvailable", ...).
uint64_t automatic_memory_budget(const MemoryFacts& facts, std::string* source = nullptr);

// The process's budget: --limit memory's value, or 0 for the automatic one (computed once, when first
// needed). The commands call it before loading a scene.
void set_memory_budget(uint64_t bytes);
uint64_t memory_budget();

// Bytes of OpenCL buffers alive now (ClBuffer counts them).
void add_device_bytes(int64_t delta);
uint64_t device_bytes_in_use();

// Throws pmr::Error("out of memory: <what> needs N MiB, but the memory budget leaves M MiB (...)")
// when `bytes` more than the device buffers alive now do not fit in the budget.
void check_memory(uint64_t bytes, const std::string& what);

}  // namespace pmr
