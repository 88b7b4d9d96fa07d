#include "sequence/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace pmr {

std::string clock_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = long(seconds + 0.5);
  char buf[32];
  if (s >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

Progress::Progress(long total, bool quiet)
    : total_(total), quiet_(quiet), tty_(::isatty(2) == 1), start_(std::chrono::steady_clock::now()) {}

double Progress::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::frame_rendered(long frame, double render_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  render_ms_[frame] = render_ms;
}

void Progress::frame_written(long frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  const long k = ++written_;
  const auto it = render_ms_.find(frame);
  const double render_ms = it == render_ms_.end() ? NAN : it->second;
  if (it != render_ms_.end()) render_ms_.erase(it);
  if (quiet_) return;
  const double elapsed = elapsed_seconds();
  const double fps = elapsed > 0 ? double(k) / elapsed : 0.0;
  const double eta = fps > 0 ? double(total_ - k) / fps : NAN;
  if (tty_) {
    std::fprintf(stderr, "\r\033[Kpmr: frame %ld/%ld (#%ld) %.2f frames/s, elapsed %s, ETA %s", k, total_, frame, fps,
                 clock_text(elapsed).c_str(), clock_text(eta).c_str());
    line_open_ = true;
  } else {
    std::fprintf(stderr, "pmr: frame %ld written (%ld/%ld): render %.0f ms, elapsed %s, ETA %s\n", frame, k, total_,
                 render_ms, clock_text(elapsed).c_str(), clock_text(eta).c_str());
  }
  std::fflush(stderr);
}

void Progress::message(const std::string& line) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (line_open_) std::fputs("\r\033[K", stderr);
  std::fprintf(stderr, "%s\n", line.c_str());
  line_open_ = false;
}

void Progress::close() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (line_open_) std::fputc('\n', stderr);
  line_open_ = false;
}

}  // namespace pmr
