#include "cli/bench_command.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>

#include "cli/bench_options.h"
#include "cli/queue_stats.h"
#include "cli/render_command.h"
#include "pipeline/pipeline.h"
#include "pmr/error.h"
#include "pmr/memory_budget.h"
#include "pmr/output.h"
#include "pmr/printable.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"
#include "sequence/frame_renderer.h"
#include "shading/environment.h"

namespace pmr {

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Device copy bandwidth in bytes per second (best of a few 256 MiB copies).
double copy_bandwidth(const ClRuntime& rt) {
  const size_t bytes = size_t(256) << 20;
  ClBuffer a = rt.buffer(bytes, "bandwidth probe"), b = rt.buffer(bytes, "bandwidth probe");
  rt.fill_zero(a);
  rt.fill_zero(b);
  rt.finish();
  double best = 0;
  for (int k = 0; k < 4; ++k) {
    cl_event e = nullptr;
    cl_check(clEnqueueCopyBuffer(rt.queue(), a.get(), b.get(), 0, 0, bytes, 0, nullptr, &e), "clEnqueueCopyBuffer");
    clWaitForEvents(1, &e);
    const double ms = event_ms(e);
    clReleaseEvent(e);
    if (ms > 0) best = std::max(best, 2.0 * double(bytes) / (ms * 1e-3));  // read + write
  }
  return best;
}

// Fraction of display pixels whose coverage (alpha != 0) differs between two encoded images.
double coverage_mismatch(const std::vector<uint16_t>& a, const std::vector<uint16_t>& b) {
  if (a.size() != b.size() || a.empty()) return 1.0;
  size_t diff = 0;
  for (size_t i = 3; i < a.size(); i += 4) diff += (a[i] != 0) != (b[i] != 0);
  return double(diff) / double(a.size() / 4);
}

// The pipeline of one bench row: the encoded-only job, as pmr render runs it.
PipelineConfig bench_config(const BenchOptions& o, Method method, Sampling sampling, int samples) {
  PipelineConfig pc;
  pc.method = method;
  pc.sampling = sampling;
  pc.samples = samples;
  pc.texture_filter = o.texture_filter;
  pc.shadows = o.shadows;
  pc.environment_occlusion = o.environment_occlusion;
  pc.shading = o.shading, pc.exposure_ev = o.exposure_ev, pc.environment_intensity = o.environment_intensity;
  pc.environment = o.environment;
  pc.tile_queue_limit = o.limits.tile_queue;
  pc.tile_x = o.tile[0], pc.tile_y = o.tile[1], pc.tile_v = o.tile[2];
  pc.fuse_encode = true;
  return pc;
}

// One point of the sweep: a scene's rig and display at one view count, a method, a sampling and a
// sample count per pixel.
struct BenchPoint {
  const BenchOptions& o;
  const std::string& scene_name;
  size_t triangles;
  FrameRenderer& renderer;
  const Display& display;
  int views;
  Method method;
  Sampling sampling;
  int samples;
};

// Times the point's frames and prints its table row (and CSV row). `first`: the first method's image
// of the same sampling and samples, for the coverage check (filled by the first method).
void bench_point(const BenchPoint& b, const ClRuntime& rt, double bw, std::vector<uint16_t>& first,
                 std::ofstream* csv) {
  const BenchOptions& o = b.o;
  const Rig& rig = b.renderer.rig();
  const double voxels = double(b.views) * rig.view_w * rig.view_h;
  const bool subpixel = b.sampling == Sampling::Subpixel;
  const double samples = subpixel ? 3.0 * b.display.width * b.display.height : voxels;  // per frame
  // the least a frame must move: every sample written once, the display image written once (half RGBA)
  const double floor_bytes = (subpixel ? 0.0 : voxels * 8.0) + double(b.display.width) * b.display.height * 8.0;
  const double floor_ms = floor_bytes / bw * 1e3;
  Pipeline p(rt, bench_config(o, b.method, b.sampling, b.samples));
  b.renderer.attach(p, &b.display);
  b.renderer.render(0);  // warm-up: first-touch of buffers, queue growth
  std::vector<double> wall, setup, tile, fine, encode, pose, upload;
  StageTimes t;
  for (int f = 0; f < o.frames; ++f) {
    const FrameRenderer::Frame fr = b.renderer.render(f);
    t = fr.times;
    wall.push_back(t.wall), pose.push_back(fr.pose_ms), upload.push_back(fr.upload_ms);
    setup.push_back(t.vertex + t.setup), tile.push_back(t.bin), fine.push_back(t.fine), encode.push_back(t.encode);
  }
  double mismatch = 0.0;
  if (o.check) {
    std::vector<uint16_t> image;
    p.read_display(image);
    if (first.empty()) first.swap(image);
    else mismatch = coverage_mismatch(first, image);
    if (mismatch > 0.001)
      std::fprintf(stderr, "pmr: warning: %s at N = %d differs from %s on %.3f%% of display pixels\n",
                   to_string(b.method), b.views, to_string(o.methods[0]), 100.0 * mismatch);
  }
  const double med = median(wall), mn = *std::min_element(wall.begin(), wall.end());
  const double msmp = samples / (med * 1e-3) * 1e-6;
  char view[32];
  std::snprintf(view, sizeof view, "%dx%d", rig.view_w, rig.view_h);
  std::printf("%-10s %-8s %3d %5d %9s %9.2f %9.1f %9.1f %8.1f %8.1f %8.1f %8.1f %9.0f %8.0f %7.1f %8.5f\n",
              to_string(b.method), to_string(b.sampling), b.samples, b.views, view, samples * 1e-6, med, mn,
              median(setup), median(tile), median(fine), median(encode), msmp, floor_bytes / 1e6, med / floor_ms,
              mismatch);
  if (median(pose) > 0.0)
    std::printf("#   on the host per frame (not in ms_median): pose %.2f ms, upload %.2f ms\n", median(pose),
                median(upload));
  if (o.queue_stats) print_queue_stats(p, t);
  std::fflush(stdout);
  if (csv)
    *csv << b.scene_name << ',' << to_string(b.method) << ',' << b.views << ',' << rig.view_w << ',' << rig.view_h
         << ',' << b.display.width << ',' << b.display.height << ',' << b.triangles << ',' << o.frames << ',' << med
         << ',' << mn << ',' << median(setup) << ',' << median(tile) << ',' << median(fine) << ',' << median(encode)
         << ',' << (subpixel ? 0.0 : voxels / (med * 1e-3) * 1e-6) << ',' << double(p.device_bytes()) / (1 << 20) << ','
         << floor_bytes / 1e6 << ',' << floor_ms << ',' << med / floor_ms << ',' << mismatch << ','
         << to_string(b.sampling) << ',' << samples << ',' << msmp << ',' << b.samples << '\n';
}

// One scene: every view count, method, sampling and sample count of the options, a table row (and CSV
// row) per point.
void bench_scene(const BenchOptions& o, const ClRuntime& rt, double bw, const Scene& scene,
                 const std::string& scene_name, std::ofstream* csv) {
  const SequenceSpec spec = resolve_sequence(scene, o.sequence, o.limits);
  std::printf("# %s: %zu triangles; device %s; copy bandwidth %.1f GB/s\n", scene_name.c_str(), scene.triangles.size(),
              rt.device_name().c_str(), bw * 1e-9);
  std::printf("%-10s %-8s %3s %5s %9s %9s %9s %9s %8s %8s %8s %8s %9s %8s %7s %8s\n", "method", "sampling", "spp",
              "views", "view", "Msamples", "ms_median", "ms_min", "setup", "tile", "fine", "encode", "Msmp/s",
              "floor_MB", "xfloor", "mismatch");
  const double total_voxels = 96.0 * o.view_w * o.view_h;
  for (int N : o.views) {
    RigConfig rc = o.rig;
    rc.views = N;
    rc.view_w = o.view_w, rc.view_h = o.view_h;
    if (o.keep == "total") {
      // same total voxels, aspect 2:1, multiples of 4; views at most 4096 px wide, because the
      // fixed-point guard band bounds disparity (a wider view at an 80 degree cone would not fit),
      // so below N = 6 the total is not held (the CSV's view size says so)
      const double h = std::sqrt(total_voxels / N / 2.0);
      rc.view_h = std::max(4, std::min(2048, int(std::lround(h / 4.0)) * 4));
      rc.view_w = 2 * rc.view_h;
    }
    Display display = o.display;
    if (!o.offset_given)  // else the panel's own
      display.offset = as_usage([&] { return default_offset(display.lens_pitch, N); });
    FrameRenderer renderer(scene, spec, rc, display, nullptr);
    std::map<std::pair<Sampling, int>, std::vector<uint16_t>> first;  // per (sampling, samples): the first image
    for (Method method : o.methods)
      for (Sampling asked : o.samplings) {
        // subpixel sampling is PMR's: asked for, the other methods skip it; as a preset's default they
        // render with view sampling, as pmr render does
        if (asked == Sampling::Subpixel && method != Method::Pmr && o.samplings_given) continue;
        const Sampling sampling = method == Method::Pmr ? asked : Sampling::View;
        for (int samples : o.samples) {
          const BenchPoint b{o, scene_name, scene.triangles.size(), renderer, display, N, method, sampling, samples};
          bench_point(b, rt, bw, first[{sampling, samples}], csv);
        }
      }
  }
}

Scene generate(const std::string& generator, size_t triangles) {
  return generator == "objects" ? make_objects_scene(triangles) : make_synthetic_scene(triangles);
}

}  // namespace

int run_bench(const std::vector<std::string>& args) {
  BenchOptions o = as_usage([&] { return parse_bench_options(args); });
  if (o.help) {
    std::fputs(bench_help().c_str(), stdout);
    return 0;
  }
  if (!o.save_scene.empty()) {
    const Scene scene = generate(o.generator, o.triangle_counts[0]);
    save_glb(scene, o.save_scene);
    std::printf("wrote %s: %zu triangles\n", printable_text(o.save_scene).c_str(), scene.triangles.size());
    return 0;
  }
  std::unique_ptr<std::ofstream> csv;
  if (!o.csv.empty()) {
    csv.reset(new std::ofstream(o.csv));
    if (!*csv) throw Error("cannot write " + printable_text(o.csv) + ": " + write_failure(errno));
  }
  if (o.shading == Shading::Pbr) {  // made once, before the first point
    o.environment = make_pipeline_environment(
        {o.environment_source, o.environment_rotation_deg, o.environment_intensity, o.shadows});
    std::printf("# environment %s\n", environment_summary(o.environment_source, o.environment.get()).c_str());
  }
  set_memory_budget(o.limits.memory);
  ClRuntime rt;
  const double bw = copy_bandwidth(rt);
  if (csv)
    *csv << "scene,method,views,view_w,view_h,display_w,display_h,triangles,frames,ms_median,ms_min,ms_setup,ms_tile,"
            "ms_fine,ms_encode,mvoxels_per_s,peak_mem_mb,floor_mb,floor_ms,x_floor,coverage_mismatch,sampling,samples,"
            "msamples_per_s,samples_per_pixel\n";
  if (o.generator.empty()) {
    const std::string path = o.scene.empty() ? default_scene_path() : o.scene;
    bench_scene(o, rt, bw, load_scene(path, o.limits), path.substr(path.rfind('/') + 1), csv.get());
  }
  for (size_t n : o.triangle_counts)
    bench_scene(o, rt, bw, generate(o.generator, n), o.generator + "-" + std::to_string(n), csv.get());
  if (csv && !csv->flush())  // a full disk (or /dev/full) shows when the buffer is written
    throw Error("cannot write " + printable_text(o.csv) + ": " + write_failure(errno));
  return 0;
}

}  // namespace pmr
