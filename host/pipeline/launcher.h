// Every kernel launch and program build of a pipeline goes through its Launcher, which owns the two
// things all stages share about launching: the frame's profiling events (tagged by stage) and the
// warm-up. PoCL compiles a kernel's work-group function when a launch first needs it (seconds each on
// a cold cache), so Pipeline::configure renders one empty frame with the launcher warming: every
// launch then runs a single work-group of its real local size (the kernels find nothing to do), and
// the (kernel, local size) pairs are recorded. No stage knows whether it is warming.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "runtime/cl_runtime.h"

namespace pmr {

struct StageTimes;

enum Stage { kVertex, kSetup, kBin, kFine, kEncode, kShadow, kStages };

// The profiling events of one frame, each tagged with its stage; released with the frame.
class FrameEvents {
 public:
  FrameEvents() = default;
  FrameEvents(const FrameEvents&) = delete;
  FrameEvents& operator=(const FrameEvents&) = delete;
  ~FrameEvents();
  cl_event add(Stage s, cl_event e);
  cl_event last() const { return all_.empty() ? nullptr : all_.back().second; }
  // Adds up the device time per stage into t (after the queue has finished).
  void collect(StageTimes& t) const;

 private:
  std::vector<std::pair<Stage, cl_event>> all_;
};

class Launcher {
 public:
  explicit Launcher(const ClRuntime& rt) : rt_(rt) {}
  const ClRuntime& runtime() const { return rt_; }

  // The real grid of `items` work-items (ClRuntime::launch), or while warming one work-group.
  cl_event launch(const ClKernel& k, size_t items, size_t local);
  cl_event launch_2d(const ClKernel& k, size_t gx, size_t gy, size_t lx, size_t ly);
  // A program from the embedded sources; its build time counts as kernel build time.
  ClProgram build(const std::vector<std::string>& files, const std::string& options);

  // Runs `frame` (an empty frame's render) with every launch warming; its time counts as build time.
  template <class F>
  void warm_up(F&& frame) {
    Warming w(*this);
    frame();
  }
  double build_seconds() const { return build_seconds_; }
  const std::vector<std::string>& variants() const { return variants_; }

 private:
  struct Warming {  // warming for its lifetime, even if the frame throws
    explicit Warming(Launcher& l);
    ~Warming();
    Launcher& l;
    double start;
  };
  cl_event warm(const ClKernel& k, size_t lx, size_t ly);

  const ClRuntime& rt_;
  bool warming_ = false;
  double build_seconds_ = 0.0;
  std::vector<std::string> variants_;  // the (kernel, local size) pairs the warm-up launched
};

}  // namespace pmr
