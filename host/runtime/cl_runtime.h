// A thin RAII layer over the OpenCL C API: device selection, buffers, program build from the
// embedded kernel sources, kernel launches with profiling events. Every failure is a pmr::Error that
// names the call, the OpenCL error and (for builds) carries the build log.
#pragma once
#include <CL/cl.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace pmr {

const char* cl_error_name(cl_int code);
// Throws pmr::Error("<what>: <CL_ERROR_NAME>") unless code == CL_SUCCESS.
void cl_check(cl_int code, const std::string& what);

// One line per platform and device, for `pmr info`.
std::vector<std::string> describe_opencl_devices();

template <typename T>
size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

class ClBuffer {
 public:
  ClBuffer() = default;
  ClBuffer(cl_context ctx, cl_mem_flags flags, size_t bytes, const std::string& name);
  ~ClBuffer();
  ClBuffer(ClBuffer&& o) noexcept;
  ClBuffer& operator=(ClBuffer&& o) noexcept;
  ClBuffer(const ClBuffer&) = delete;
  ClBuffer& operator=(const ClBuffer&) = delete;
  cl_mem get() const { return mem_; }
  size_t size() const { return bytes_; }

 private:
  cl_mem mem_ = nullptr;
  size_t bytes_ = 0;
};

// An OpenCL program; released with its owner.
class ClProgram {
 public:
  ClProgram() = default;
  explicit ClProgram(cl_program program) : program_(program) {}
  ~ClProgram();
  ClProgram(ClProgram&& o) noexcept : program_(o.program_) { o.program_ = nullptr; }
  ClProgram& operator=(ClProgram&& o) noexcept;
  ClProgram(const ClProgram&) = delete;
  ClProgram& operator=(const ClProgram&) = delete;
  cl_program get() const { return program_; }

 private:
  cl_program program_ = nullptr;
};

class ClKernel {
 public:
  ClKernel() = default;
  ClKernel(const ClProgram& program, const std::string& name);
  ~ClKernel();
  ClKernel(ClKernel&& o) noexcept;
  ClKernel& operator=(ClKernel&& o) noexcept;
  ClKernel(const ClKernel&) = delete;
  ClKernel& operator=(const ClKernel&) = delete;
  cl_kernel get() const { return kernel_; }
  const std::string& name() const { return name_; }
  template <typename T>
  void arg(cl_uint index, const T& value) {
    set(index, sizeof(T), &value);
  }
  void arg(cl_uint index, const ClBuffer& b) {
    cl_mem m = b.get();
    set(index, sizeof(cl_mem), &m);
  }
  // Sets arguments 0, 1, 2, ... in order.
  template <typename... Args>
  void args(const Args&... values) {
    args_from(0, values...);
  }
  // Sets arguments first, first + 1, ... in order.
  template <typename... Args>
  void args_from(cl_uint first, const Args&... values) {
    cl_uint index = first;
    (arg(index++, values), ...);
  }

 private:
  void set(cl_uint index, size_t size, const void* value);
  cl_kernel kernel_ = nullptr;
  std::string name_;
};

class ClRuntime {
 public:
  // Picks the first CPU device (or the device named in the PMR_DEVICE environment variable, a
  // substring of its name); throws if there is none.
  ClRuntime();
  ~ClRuntime();
  ClRuntime(const ClRuntime&) = delete;
  ClRuntime& operator=(const ClRuntime&) = delete;

  cl_context context() const { return context_; }
  cl_command_queue queue() const { return queue_; }
  cl_device_id device() const { return device_; }
  std::string device_name() const;
  size_t max_alloc_bytes() const;
  size_t global_mem_bytes() const;
  size_t max_work_group_size() const;

  // Builds a program from embedded sources: `files` are names from the embedded table, concatenated in
  // order, with `#include "x"` lines replaced by the embedded file x (once). Options are logged with
  // the build log on failure.
  // `extra`: more sources to look names up in first (the tests' kernel probes, which the shipped binary
  // does not carry).
  ClProgram build_program(const std::vector<std::string>& files, const std::string& options,
                          const std::map<std::string, std::string>* extra = nullptr) const;

  ClBuffer buffer(size_t bytes, const std::string& name, cl_mem_flags flags = CL_MEM_READ_WRITE) const;
  void write(const ClBuffer& b, const void* data, size_t bytes, size_t offset = 0) const;
  // Writes all of `v` at the buffer's start.
  template <typename T>
  void write(const ClBuffer& b, const std::vector<T>& v) const {
    write(b, v.data(), bytes_of(v));
  }
  // A read-only buffer holding `v`, of at least `min_bytes` (OpenCL has no empty buffers).
  template <typename T>
  ClBuffer upload(const std::vector<T>& v, const std::string& name, size_t min_bytes = 1) const {
    ClBuffer b = buffer(std::max(bytes_of(v), min_bytes), name, CL_MEM_READ_ONLY);
    write(b, v);
    return b;
  }
  // Rewrites `b` with `v`, reallocating it (read-only) only when the size changes: per-frame tables
  // keep their buffer.
  template <typename T>
  void rewrite(ClBuffer& b, const std::vector<T>& v, const std::string& name) const {
    if (b.size() != bytes_of(v)) b = buffer(bytes_of(v), name, CL_MEM_READ_ONLY);
    write(b, v);
  }
  void read(const ClBuffer& b, void* data, size_t bytes, size_t offset = 0) const;
  void fill_zero(const ClBuffer& b) const;
  // Every launch names its local size. PoCL compiles (and caches on disk) one work-group function
  // per kernel, local size, zero/non-zero global offset and "small grid" (every grid dimension under
  // kSmallGridLimit work-items). A local size left to PoCL follows the global size, so data-dependent
  // counts (the MTAs of a frame) meant a new compilation of seconds for almost every frame. With
  // explicit local sizes and grids kept small, a configuration compiles a fixed set of functions,
  // once (Pipeline::configure builds them all before the first frame).
  static constexpr size_t kSmallGridLimit = 65535;  // PoCL's grid_width_specialization_limit (USHRT_MAX)
  // Launches `items` work-items (kernels index them with pmr_item_id(), cl/common.h) in work-groups of
  // `local`. Counts of up to a row (the largest multiple of `local` below kSmallGridLimit) run as one
  // row; longer launches are folded into rows of that width (a 2D grid); the padding work-items past
  // `items` must return at once. items == 0 enqueues a marker. Returns the event (caller releases).
  cl_event launch(const ClKernel& k, size_t items, size_t local) const;
  // 2D launch; the global size is rounded up to a multiple of the local size. Throws if a dimension
  // would reach kSmallGridLimit.
  cl_event launch_2d(const ClKernel& k, size_t gx, size_t gy, size_t lx, size_t ly) const;
  // One work-group of the given local size, for building a kernel's work-group function ahead of
  // time (the kernel must do nothing harmful for its arguments at the time).
  cl_event launch_one_group(const ClKernel& k, size_t lx, size_t ly = 1) const;
  void finish() const;

 private:
  cl_device_id device_ = nullptr;
  cl_context context_ = nullptr;
  cl_command_queue queue_ = nullptr;
};

// Elapsed device time of a finished event in milliseconds (profiling start to end).
double event_ms(cl_event e);
// Device time from the start of `first` to the end of `last`.
double event_span_ms(cl_event first, cl_event last);

}  // namespace pmr
