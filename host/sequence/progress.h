// Progress of a sequence on stderr: one updating line on a terminal (frame k of n, frames per second,
// elapsed, ETA), a plain log line per frame otherwise, nothing with --quiet (errors and the final
// summary still print).
#pragma once
#include <chrono>
#include <string>

namespace pmr {

class Progress {
 public:
  Progress(long total, bool quiet);
  // Frame `frame` finished rendering (the k-th of n this run).
  void frame_done(long k, long frame, double render_ms);
  // A line that must not be overwritten by the progress line (warnings).
  void message(const std::string& line);
  // Ends the updating line.
  void close();
  double elapsed_seconds() const;

 private:
  long total_;
  bool quiet_, tty_;
  bool line_open_ = false;
  std::chrono::steady_clock::time_point start_;
};

// "1:05", "12:00:07"
std::string clock_text(double seconds);

}  // namespace pmr
