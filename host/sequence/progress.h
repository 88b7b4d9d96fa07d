// Progress of a sequence on stderr, counting the frames written: one updating line on a terminal (frame
// k of n, frames per second,
// elapsed, ETA), a plain log line per frame otherwise, nothing with --quiet (errors and the final
// summary still print).
#pragma once
#include <chrono>
#include <map>
#include <mutex>
#include <string>

namespace pmr {

class Progress {
 public:
  Progress(long total, bool quiet);
  // Frame `frame` finished rendering in `render_ms` (frame loop): remembered for its progress line.
  void frame_rendered(long frame, double render_ms);
  // Every file of `frame` is on disk, its sidecar last (writer thread): the progress line counts it.
  // Only written frames are counted, so the count agrees with what an interrupted run leaves.
  void frame_written(long frame);
  // A line that must not be overwritten by the progress line (warnings).
  void message(const std::string& line);
  // Ends the updating line.
  void close();
  double elapsed_seconds() const;

 private:
  long total_;
  bool quiet_, tty_;
  std::mutex mutex_;  // the frame loop and the writer thread both print
  bool line_open_ = false;
  long written_ = 0;
  std::map<long, double> render_ms_;  // rendered, not yet written
  std::chrono::steady_clock::time_point start_;
};

// "1:05", "12:00:07"
std::string clock_text(double seconds);

}  // namespace pmr
