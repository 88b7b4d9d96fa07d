#include "pipeline/launcher.h"

#include <algorithm>
#include <chrono>

#include "pipeline/pipeline.h"

namespace pmr {

namespace {

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

FrameEvents::~FrameEvents() {
  for (const auto& se : all_) clReleaseEvent(se.second);
}

cl_event FrameEvents::add(Stage s, cl_event e) {
  all_.push_back({s, e});
  return e;
}

void FrameEvents::collect(StageTimes& t) const {
  double ms[kStages] = {};
  for (const auto& se : all_) ms[se.first] += event_ms(se.second);
  t.vertex = ms[kVertex], t.setup = ms[kSetup], t.bin = ms[kBin], t.fine = ms[kFine], t.encode = ms[kEncode];
  t.shadow = ms[kShadow];
  if (!all_.empty()) t.device_total = event_span_ms(all_.front().second, all_.back().second);
}

cl_event Launcher::launch(const ClKernel& k, size_t items, size_t local) {
  return warming_ ? warm(k, local, 1) : rt_.launch(k, items, local);
}

cl_event Launcher::launch_2d(const ClKernel& k, size_t gx, size_t gy, size_t lx, size_t ly) {
  return warming_ ? warm(k, lx, ly) : rt_.launch_2d(k, gx, gy, lx, ly);
}

cl_event Launcher::warm(const ClKernel& k, size_t lx, size_t ly) {
  const std::string v = k.name() + " " + std::to_string(lx) + "x" + std::to_string(ly);
  if (std::find(variants_.begin(), variants_.end(), v) == variants_.end()) variants_.push_back(v);
  return rt_.launch_one_group(k, lx, ly);
}

ClProgram Launcher::build(const std::vector<std::string>& files, const std::string& options) {
  const double t0 = seconds_now();
  ClProgram p = rt_.build_program(files, options);
  build_seconds_ += seconds_now() - t0;
  return p;
}

Launcher::Warming::Warming(Launcher& launcher) : l(launcher), start(seconds_now()) {
  l.warming_ = true;
  l.variants_.clear();
}

Launcher::Warming::~Warming() {
  l.warming_ = false;
  l.build_seconds_ += seconds_now() - start;
}

}  // namespace pmr
