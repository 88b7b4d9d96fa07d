#include "sequence/frame_writer.h"

#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>

#include "output/checksum.h"
#include "output/exr_zip.h"
#include "output/interrupt.h"
#include "pmr/error.h"

namespace pmr {

namespace {

uint64_t file_size(const std::string& path) {
  std::error_code ec;
  const auto n = std::filesystem::file_size(path, ec);
  return ec ? 0 : uint64_t(n);
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Thrown inside write() when an interrupt arrives between two files of a frame.
struct Abandoned {};

}  // namespace

FrameWriter::FrameWriter(int exr_threads, std::function<void(long)> on_written)
    : exr_threads_(exr_threads), on_written_(std::move(on_written)), thread_([this] { run(); }) {}

FrameWriter::~FrameWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
  }
  changed_.notify_all();
  thread_.join();
}

void FrameWriter::rethrow() {
  if (error_) std::rethrow_exception(error_);
}

void FrameWriter::submit(FrameFiles&& frame) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return queue_.empty() || error_; });
  rethrow();
  queue_.push_back(std::move(frame));
  changed_.notify_all();
}

void FrameWriter::finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return (queue_.empty() && !busy_) || error_; });
  rethrow();
}

std::vector<uint16_t> FrameWriter::spare_buffer() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (spare_.empty()) return {};
  std::vector<uint16_t> b = std::move(spare_.back());
  spare_.pop_back();
  return b;
}

long FrameWriter::frames_written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}
double FrameWriter::write_seconds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return seconds_;
}
double FrameWriter::cpu_seconds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cpu_seconds_;
}
uint64_t FrameWriter::bytes_written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

void FrameWriter::run() {
  for (;;) {
    FrameFiles f;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_ || error_) return;
      f = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = thread_cpu_seconds(), helpers0 = exr_zip_helper_cpu_seconds();
    std::exception_ptr error;
    uint64_t bytes = 0;
    bool done = false;
    try {
      write(f);
      done = true;
      for (const std::string* p : {&f.sidecar_path, &f.encoded_path, &f.views_path, &f.quilt_path, &f.encoded_png,
                                   &f.center_png, &f.quilt_png})
        if (!p->empty()) bytes += file_size(*p);
    } catch (const Abandoned&) {
    } catch (...) {
      error = std::current_exception();
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = thread_cpu_seconds() - cpu0 + exr_zip_helper_cpu_seconds() - helpers0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
      if (error && !error_) error_ = error;
      if (interrupt_signal()) queue_.clear();  // nothing more is written after an interrupt
      if (done) ++written_, seconds_ += s, cpu_seconds_ += cpu, bytes_ += bytes;
      for (std::vector<uint16_t>* b : {&f.display, &f.volume, &f.sub_alpha})
        if (!b->empty() && spare_.size() < 6) spare_.push_back(std::move(*b));
    }
    if (done && on_written_) on_written_(f.frame);
    changed_.notify_all();
  }
}

void FrameWriter::write(FrameFiles& f) {
  std::vector<std::string> committed;
  // Until the frame is whole its committed files are registered like temporaries, so that a second
  // signal (immediate exit) removes them too.
  std::vector<int> slots;
  struct Unregister {
    std::vector<int>& s;
    ~Unregister() {
      for (int i : s) unregister_temp_file(i);
    }
  } unregister{slots};
  auto roll_back = [&] {
    for (const std::string& p : committed) ::unlink(p.c_str());
  };
  auto check = [&] {
    if (interrupt_signal()) {
      roll_back();
      throw Abandoned{};
    }
  };
  // Every final path of the frame is registered before its file is written: a second signal between a
  // rename and its registration would otherwise leave that file behind.
  for (const std::string* p :
       {&f.sidecar_path, &f.encoded_path, &f.views_path, &f.quilt_path, &f.encoded_png, &f.center_png, &f.quilt_png})
    if (!p->empty()) slots.push_back(register_temp_file(*p));
  auto done = [&](const std::string& path) { committed.push_back(path); };
  const ExrMetadata* meta = f.has_meta ? &f.meta : nullptr;
  try {
    if (!f.display.empty()) composite_encoded(f.display.data(), f.sub_alpha.data(), f.display.size() / 4, f.background);
    if (!f.volume.empty()) composite_rgba(f.volume.data(), f.volume.size() / 4, f.background);
    if (!f.encoded_path.empty()) {
      check();
      write_rgba_exr(f.encoded_path, f.display_w, f.display_h, f.display.data(), f.compression, exr_threads_, nullptr,
                     1.0f, meta, ExrImage::Encoded, f.sub_alpha.empty() ? nullptr : f.sub_alpha.data());
      done(f.encoded_path);
    }
    if (!f.depth.empty()) {
      // window depth -> view-space depth (DESIGN section 6); empty voxels (+infinity) get --depth-empty
      const double n = f.near, fa = f.far;
      for (float& z : f.depth) z = std::isfinite(z) ? float(fa * n / (fa - double(z) * (fa - n))) : f.depth_empty;
    }
    const float* depth = f.depth.empty() ? nullptr : f.depth.data();
    if (!f.views_path.empty()) {
      check();
      write_views_exr(f.views_path, f.view_w, f.view_h, f.views, f.volume.data(), depth, f.compression, exr_threads_,
                      f.pixel_aspect, meta);
      done(f.views_path);
    }
    std::vector<uint16_t> quilt;
    std::vector<float> quilt_depth;
    if (!f.quilt_path.empty() || !f.quilt_png.empty())
      assemble_quilt(f.quilt, f.views, f.view_w, f.view_h, f.volume.data(), depth, quilt,
                     depth ? &quilt_depth : nullptr);
    const int qw = f.quilt.columns * f.view_w, qh = f.quilt.rows * f.view_h;
    if (!f.quilt_path.empty()) {
      check();
      write_rgba_exr(f.quilt_path, qw, qh, quilt.data(), f.compression, exr_threads_,
                     depth ? quilt_depth.data() : nullptr, f.pixel_aspect, meta, ExrImage::Quilt);
      done(f.quilt_path);
    }
    if (!f.encoded_png.empty()) {
      check();
      if (f.display_shown.empty()) {  // opaque, over black
        write_png_preview(f.encoded_png, f.display_w, f.display_h, f.display.data(), 1.0, true, f.view_transform);
      } else {
        const ViewTransform shown = ViewTransform::display_referred();
        write_png_preview(f.encoded_png, f.display_w, f.display_h, f.display_shown.data(), 1.0, true, &shown);
      }
      done(f.encoded_png);
    }
    if (!f.center_png.empty()) {
      check();
      const size_t plane = size_t(f.view_w) * size_t(f.view_h) * 4;
      int w = 0, h = 0;  // a view's pixels span the display's aspect: square them for viewers
      const std::vector<uint16_t> square =
          square_pixels(f.volume.data() + size_t(f.center_view) * plane, f.view_w, f.view_h, f.pixel_aspect, w, h);
      write_png_preview(f.center_png, w, h, square.data(), 1.0, false, f.view_transform);
      done(f.center_png);
    }
    if (!f.quilt_png.empty()) {
      check();
      write_png_preview(f.quilt_png, qw, qh, quilt.data(), f.pixel_aspect, f.quilt_png_opaque,
                        f.view_transform);  // tiles as rendered
      done(f.quilt_png);
    }
    // last, the sidecar with what was written: from here on the frame is complete
    check();
    for (const std::string& path : committed) {
      OutputChecksum c;
      c.file = std::filesystem::path(path).filename().string();
      c.bytes = file_size(path);
      c.checksum = checksum_file(path);  // from the page cache: a few ms for a paper-8k EXR
      f.sidecar.output_checksums.push_back(std::move(c));
    }
    write_sidecar(f.sidecar_path, f.sidecar_rig, f.sidecar_display, f.sidecar);
    done(f.sidecar_path);
  } catch (const Abandoned&) {
    throw;
  } catch (...) {
    roll_back();  // a frame is complete or absent: no sidecar without its images
    throw;
  }
}

}  // namespace pmr
