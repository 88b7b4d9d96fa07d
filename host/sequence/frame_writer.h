// Writes finished frames on a background thread while the next frame renders: a bounded queue of one
// frame (so memory stays at two or three frames) feeding one writer thread, which lets OpenEXR
// compress with its own thread pool. Per frame the images are committed first, each through AtomicFile,
// then the sidecar with their sizes and checksums: a frame is complete when its sidecar is there. An interrupt (output/interrupt.h)
// abandons the frame being written and removes what of it was already committed, so a frame is either
// complete or absent. The first error stops the writer; the next submit() or finish() rethrows it.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "output/background.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "pmr/quilt.h"
#include "pmr/rig.h"

namespace pmr {

// One frame's products. A path left empty is not written. The quilt and the previews are assembled
// and encoded on the writer thread, the depth converted there too.
struct FrameFiles {
  long frame = 0;
  // The sidecar: written last, from this description plus the checksums of the files written before it.
  std::string sidecar_path;
  SidecarInfo sidecar;
  Rig sidecar_rig;
  Display sidecar_display;
  std::string encoded_path, encoded_png;
  // The previews' view transform (null: Standard). A transform that mixes channels cannot follow the
  // encoder's choice of one channel per subpixel: the panel PNG is then encoded from the transformed
  // views (display_shown: half RGBA, display-referred, already over the background).
  const ViewTransform* view_transform = nullptr;
  std::vector<uint16_t> display_shown;
  std::vector<uint16_t> display;    // half RGBA, display_w x display_h
  std::vector<uint16_t> sub_alpha;  // each display subpixel's alpha: [y][x][3] halves (AR, AG, AB)
  int display_w = 0, display_h = 0;
  std::string views_path, quilt_path, quilt_png, center_png;
  std::vector<uint16_t> volume;  // half RGBA, views x view_h x view_w
  int view_w = 0, view_h = 0, views = 0;
  float pixel_aspect = 1.0f;  // of a view's pixels (A h / w)
  QuiltLayout quilt;
  int center_view = 0;
  // Window depth per voxel from the pipeline (INFINITY where empty), or empty: no depth requested.
  // Written as view-space depth w = f n / (f - z (f - n)) with the rig's near (used) and far planes.
  std::vector<float> depth;
  double near = 0.0, far = 0.0;
  float depth_empty = 0.0f;  // written where the window depth is infinite (FrameProducts::depth_empty)
  ExrCompression compression = ExrCompression::Zip;
  // The frame's EXR header attributes (docs/OUTPUTS.md): every EXR of the frame gets them when
  // has_meta; the writer builds each header from it (a rig and a few numbers, no image data).
  bool has_meta = false;
  // Composited over this before anything is written (output/background.h); the quilt PNG is made opaque
  // (over black) with quilt_png_opaque.
  Background background;
  bool quilt_png_opaque = false;
  ExrMetadata meta;
};

class FrameWriter {
 public:
  // on_written (if set) is called on the writer thread with each frame whose files are all on disk.
  explicit FrameWriter(int exr_threads, std::function<void(long frame)> on_written = {});
  ~FrameWriter();  // abandons whatever is queued (the frame being written finishes or is rolled back)

  // Queues a frame; blocks while the queue is full. Rethrows an earlier write error.
  void submit(FrameFiles&& frame);
  // Waits until every queued frame is written (or abandoned on interrupt). Rethrows a write error.
  void finish();

  // An image buffer the writer has finished with (empty if none): reusing them spares the frame loop a
  // fresh 265 MB allocation per paper-8k frame and its page faults.
  std::vector<uint16_t> spare_buffer();

  long frames_written() const;
  double write_seconds() const;  // summed time the writer spent on frames
  double cpu_seconds() const;    // summed CPU time of the writer thread and the threads compressing for it
  uint64_t bytes_written() const;

 private:
  void run();
  void write(FrameFiles& f);
  void rethrow();

  int exr_threads_;
  std::function<void(long)> on_written_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<FrameFiles> queue_;
  bool busy_ = false, stop_ = false;
  std::exception_ptr error_;
  std::vector<std::vector<uint16_t>> spare_;
  long written_ = 0;
  double seconds_ = 0.0, cpu_seconds_ = 0.0;
  uint64_t bytes_ = 0;
  std::thread thread_;
};

}  // namespace pmr
