#include "cli/bench_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "cli/options.h"
#include "cli/render_command.h"
#include "pipeline/pipeline.h"
#include "pmr/error.h"
#include "pmr/memory_budget.h"
#include "pmr/output.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"
#include "sequence/frame_renderer.h"
#include "shading/environment.h"

namespace pmr {

namespace {

struct BenchOptions {
  std::string scene;
  std::string generator;                // "synthetic" or "objects": procedural scenes instead of SCENE
  std::vector<size_t> triangle_counts;  // one generated scene per count (the triangle sweep)
  std::string save_scene;               // write the generated scene as .glb and exit
  std::vector<int> views = {1, 2, 4, 8, 16, 32, 48, 64, 96};
  std::vector<Method> methods = {Method::Pmr, Method::Multipass, Method::Duplicate};
  std::vector<Sampling> samplings = {Sampling::View};  // subpixel applies to pmr only
  bool samplings_given = false;  // else the preset's default sampling (view for methods other than pmr)
  Shading shading = Shading::Pbr;
  double exposure_ev = 0.0, environment_intensity = 1.0;
  bool views_given = false;
  int frames = 5;
  std::string csv;
  std::string keep = "view";
  int view_w = 1024, view_h = 512;  // per-view raster at N = 96 (keep total) or always (keep view)
  RigConfig rig;                    // cone, field of view (views and sizes come from the options above)
  bool offset_given = false;        // --offset, or a Looking Glass preset's calibrated offset
  Display display;
  int tile[3] = {16, 2, 16};
  bool check = true;
  bool help = false;
  // Timed frames are frames 0..K-1 of this sequence (animation and turntable as for pmr render).
  std::string animation;
  double fps = 24.0;
  bool turntable = false;
  double turntable_deg = 0.0;
  long turntable_frames = 1;
  // --environment FILE and --environment-rotation DEG (pbr), prefiltered once for every point
  std::string environment_file;
  double environment_rotation_deg = 0.0;
  bool environment_rotation_given = false;
  std::shared_ptr<const Environment> environment;
  InputLimits limits;  // --limit, --allow-outside-scene-folder (docs/SECURITY.md)
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string w;
  while (std::getline(ss, w, ',')) out.push_back(w);
  return out;
}

BenchOptions parse(const std::vector<std::string>& args) {
  BenchOptions o;
  std::vector<std::string> rest;  // options shared with render go through its parser
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw Error("option " + a + " needs a value (see pmr bench --help)");
      return args[++i];
    };
    if (a == "-h" || a == "--help") o.help = true;
    else if (a == "--views") {
      o.views_given = true;
      o.views.clear();
      for (const auto& v : split(value())) {
        const RenderOptions r = parse_render_options({"--views", v});
        o.views.push_back(r.job.rig.views);
      }
    } else if (a == "--method") {
      o.methods.clear();
      for (const auto& m : split(value())) o.methods.push_back(parse_method(m));
    } else if (a == "--sampling") {
      o.samplings.clear();
      o.samplings_given = true;
      for (const auto& m : split(value())) o.samplings.push_back(parse_sampling(m));
    } else if (a == "--shading") {
      o.shading = parse_shading(value());
    } else if (a == "--exposure") {
      o.exposure_ev = parse_exposure(value());
    } else if (a == "--environment-intensity") {
      o.environment_intensity = parse_environment_intensity(value());
    } else if (a == "--environment") {
      o.environment_file = value();
      if (o.environment_file.empty()) throw Error("invalid --environment '': expected a .hdr or .exr file");
    } else if (a == "--environment-rotation") {
      o.environment_rotation_deg = parse_environment_rotation(value());
      o.environment_rotation_given = true;
    } else if (a == "--frames") {
      const std::string v = value();
      o.frames = std::atoi(v.c_str());
      if (o.frames < 1 || o.frames > 1000) throw Error("invalid --frames '" + v + "': expected 1..1000");
    } else if (a == "--csv") o.csv = value();
    else if (a == "--keep") {
      o.keep = value();
      if (o.keep != "view" && o.keep != "total") throw Error("invalid --keep '" + o.keep + "': expected view or total");
    } else if (a == "--synthetic" || a == "--objects") {
      if (!o.generator.empty()) throw Error("give one of --synthetic and --objects, once");
      o.generator = a.substr(2);
      for (const auto& v : split(value())) {
        char* end = nullptr;
        const double n = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(n >= 1 && n <= 5e7))
          throw Error("invalid " + a + " '" + v + "': expected triangle counts (1 to 5e7), comma-separated");
        o.triangle_counts.push_back(size_t(n));
      }
      if (o.triangle_counts.empty()) throw Error("invalid " + a + ": expected triangle counts");
    } else if (a == "--save-scene") o.save_scene = value();
    else if (a == "--no-check") o.check = false;
    else if (a == "--view-size" || a == "--display" || a == "--tile" || a == "--lens-pitch" || a == "--tan-slant" ||
             a == "--offset" || a == "--cone" || a == "--yfov" || a == "--display-size" || a == "--animation" ||
             a == "--fps" || a == "--turntable" || a == "--preset" || a == "--camera-spacing") {
      rest.push_back(a);
      rest.push_back(value());
    } else if (a == "--bilinear" || a == "--reverse-views") {
      rest.push_back(a);
    } else if (a == "--limit") {
      parse_limits(value(), o.limits);
    } else if (a == "--allow-outside-scene-folder") {
      o.limits.allow_outside_scene_folder = true;
    } else if (!a.empty() && a[0] == '-') throw Error("unknown option " + a + " (see pmr bench --help)");
    else if (o.scene.empty()) o.scene = a;
    else throw Error("more than one scene given");
  }
  RenderOptions r = parse_render_options(rest);
  o.view_w = r.job.rig.view_w, o.view_h = r.job.rig.view_h;
  o.rig = r.job.rig;  // a Looking Glass preset's angular camera spacing included
  if (!o.views_given && std::find(rest.begin(), rest.end(), "--preset") != rest.end()) o.views = {r.job.rig.views};
  if (!o.samplings_given) o.samplings = {r.job.pipeline.sampling};  // the preset's default
  o.display = r.job.display;
  o.offset_given = r.offset_given;
  o.tile[0] = r.job.pipeline.tile_x, o.tile[1] = r.job.pipeline.tile_y, o.tile[2] = r.job.pipeline.tile_v;
  o.animation = r.job.animation, o.fps = r.job.fps;
  o.turntable = r.job.turntable, o.turntable_deg = r.job.turntable_deg,
  o.turntable_frames = r.job.turntable ? r.job.turntable_frames : 1;
  if (o.methods.empty() || o.views.empty() || o.samplings.empty()) throw Error("nothing to measure");
  std::vector<std::string> warnings;
  check_environment_options(o.environment_file, o.environment_rotation_given, o.shading, warnings);
  for (const std::string& w : warnings) std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());
  const bool subpixel = std::find(o.samplings.begin(), o.samplings.end(), Sampling::Subpixel) != o.samplings.end();
  // subpixel rows are measured for pmr alone (the other methods' rows are skipped)
  if (subpixel) {
    const bool pmr = std::find(o.methods.begin(), o.methods.end(), Method::Pmr) != o.methods.end();
    check_subpixel_sampling(pmr ? Method::Pmr : o.methods[0], o.display);
  }
  if (!o.generator.empty() && !o.scene.empty())
    throw Error("give a SCENE or a generator (--synthetic, --objects), not both");
  if (!o.save_scene.empty() && o.triangle_counts.size() != 1)
    throw Error("--save-scene needs exactly one generated scene (--synthetic TRIS or --objects TRIS)");
  return o;
}

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

// One scene: every view count and method of the options, a table row (and CSV row) per point.
// The pipeline of one bench row: the encoded-only job, as pmr render runs it.
PipelineConfig bench_config(const BenchOptions& o, Method method, Sampling sampling) {
  PipelineConfig pc;
  pc.method = method;
  pc.sampling = sampling;
  pc.shading = o.shading, pc.exposure_ev = o.exposure_ev, pc.environment_intensity = o.environment_intensity;
  pc.environment = o.environment;
  pc.tile_queue_limit = o.limits.tile_queue;
  pc.tile_x = o.tile[0], pc.tile_y = o.tile[1], pc.tile_v = o.tile[2];
  pc.fuse_encode = true;
  return pc;
}

void bench_scene(const BenchOptions& o, const ClRuntime& rt, double bw, const Scene& scene,
                 const std::string& scene_name, std::ofstream* csv) {
  SequenceSpec spec;
  spec.framing_work = o.limits.framing_work;
  select_animation(scene, o.animation, spec);
  spec.fps = o.fps;
  spec.turntable = o.turntable, spec.turntable_deg = o.turntable_deg, spec.turntable_frames = o.turntable_frames;
  std::printf("# %s: %zu triangles; device %s; copy bandwidth %.1f GB/s\n", scene_name.c_str(), scene.triangles.size(),
              rt.device_name().c_str(), bw * 1e-9);
  std::printf("%-10s %-8s %5s %9s %9s %9s %9s %8s %8s %8s %8s %9s %8s %7s %8s\n", "method", "sampling", "views", "view",
              "Msamples", "ms_median", "ms_min", "setup", "tile", "fine", "encode", "Msmp/s", "floor_MB", "xfloor",
              "mismatch");
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
    const Rig& rig = renderer.rig();
    const double voxels = double(N) * rig.view_w * rig.view_h;
    const double subpixels = 3.0 * display.width * display.height;
    std::vector<uint16_t> reference[2];  // per sampling: the first method's image
    for (Method method : o.methods)
      for (Sampling asked : o.samplings) {
        // subpixel sampling is PMR's: asked for, the other methods skip it; as a preset's default they
        // render with view sampling, as pmr render does
        if (asked == Sampling::Subpixel && method != Method::Pmr && o.samplings_given) continue;
        const Sampling sampling = method == Method::Pmr ? asked : Sampling::View;
        // samples per frame: the voxels, or each display subpixel once
        const double samples = sampling == Sampling::Subpixel ? subpixels : voxels;
        // the least a frame must move: every sample written once, the display image written once (half RGBA)
        const double floor_bytes =
            (sampling == Sampling::Subpixel ? 0.0 : voxels * 8.0) + double(display.width) * display.height * 8.0;
        const double floor_ms = floor_bytes / bw * 1e3;
        Pipeline p(rt, bench_config(o, method, sampling));
        renderer.attach(p, &display);
        renderer.render(0);  // warm-up: first-touch of buffers, queue growth
        std::vector<double> wall, setup, tile, fine, encode, pose, upload;
        for (int f = 0; f < o.frames; ++f) {
          const FrameRenderer::Frame fr = renderer.render(f);
          const StageTimes& t = fr.times;
          wall.push_back(t.wall);
          pose.push_back(fr.pose_ms);
          upload.push_back(fr.upload_ms);
          setup.push_back(t.vertex + t.setup);
          tile.push_back(t.bin);
          fine.push_back(t.fine);
          encode.push_back(t.encode);
        }
        double mismatch = 0.0;
        if (o.check) {
          std::vector<uint16_t> image;
          p.read_display(image);
          std::vector<uint16_t>& first = reference[sampling == Sampling::Subpixel];
          if (first.empty()) first.swap(image);
          else mismatch = coverage_mismatch(first, image);
          if (mismatch > 0.001)
            std::fprintf(stderr, "pmr: warning: %s at N = %d differs from %s on %.3f%% of display pixels\n",
                         to_string(method), N, to_string(o.methods[0]), 100.0 * mismatch);
        }
        const double med = median(wall), mn = *std::min_element(wall.begin(), wall.end());
        const double msmp = samples / (med * 1e-3) * 1e-6;
        const double mem_mb = double(p.device_bytes()) / (1 << 20);
        char view[32];
        std::snprintf(view, sizeof view, "%dx%d", rig.view_w, rig.view_h);
        std::printf("%-10s %-8s %5d %9s %9.2f %9.1f %9.1f %8.1f %8.1f %8.1f %8.1f %9.0f %8.0f %7.1f %8.5f\n",
                    to_string(method), to_string(sampling), N, view, samples * 1e-6, med, mn, median(setup),
                    median(tile), median(fine), median(encode), msmp, floor_bytes / 1e6, med / floor_ms, mismatch);
        if (median(pose) > 0.0)
          std::printf("#   on the host per frame (not in ms_median): pose %.2f ms, upload %.2f ms\n", median(pose),
                      median(upload));
        std::fflush(stdout);
        if (csv)
          *csv << scene_name << ',' << to_string(method) << ',' << N << ',' << rig.view_w << ',' << rig.view_h << ','
               << display.width << ',' << display.height << ',' << scene.triangles.size() << ',' << o.frames << ','
               << med << ',' << mn << ',' << median(setup) << ',' << median(tile) << ',' << median(fine) << ','
               << median(encode) << ',' << (sampling == Sampling::Subpixel ? 0.0 : voxels / (med * 1e-3) * 1e-6) << ','
               << mem_mb << ',' << floor_bytes / 1e6 << ',' << floor_ms << ',' << med / floor_ms << ',' << mismatch
               << ',' << to_string(sampling) << ',' << samples << ',' << msmp << '\n';
      }
  }
}

Scene generate(const std::string& generator, size_t triangles) {
  return generator == "objects" ? make_objects_scene(triangles) : make_synthetic_scene(triangles);
}

}  // namespace

std::string bench_help() {
  return "usage: pmr bench [SCENE] [options]\n"
         "Times whole frames (render + encode, no file I/O) per view count and method.\n"
         "  --views LIST        view counts (default 1,2,4,8,16,32,48,64,96)\n"
         "  --method LIST       pmr, multipass, duplicate (default all three)\n"
         "  --shading S, --exposure EV, --environment FILE, --environment-rotation DEG,\n"
         "  --environment-intensity X   as for pmr render (default pbr)\n"
         "  --sampling LIST     view, subpixel (subpixel with pmr only; default view, or a --preset's\n"
         "                      default): samples per frame are the voxels, or each display subpixel once\n"
         "  --frames K          timed frames per point after one warm-up frame (default 5)\n"
         "  --csv FILE          write one row per point\n"
         "  --keep view|total   view: every view is --view-size (default 1024x512); total: the total voxel\n"
         "                      count of 96 views of --view-size is held fixed (the paper's Fig. 15; views\n"
         "                      are capped at 4096x2048)\n"
         "  --synthetic LIST    procedural scenes of about these triangle counts instead of SCENE (a sweep:\n"
         "                      1000,10000,100000): UV spheres of ~200 triangles in a 4 x 2 x 3 box\n"
         "  --objects LIST      the same with a CAD-like scene: 100 closed double-sided tori and rounded\n"
         "                      boxes at different depths, tiny triangles at 1M (1e6 is accepted)\n"
         "  --save-scene FILE   write the one generated scene to FILE (.glb) and exit: `pmr bench FILE` on\n"
         "                      any build then renders the very same triangles\n"
         "  --no-check          skip comparing the methods' images\n"
         "  --limit KEY=VALUE[,...], --allow-outside-scene-folder  budgets and confinement for SCENE's\n"
         "                      files, as for pmr render (docs/SECURITY.md)\n"
         "  --preset, --camera-spacing, --view-size, --display, --tile and the display options are as for\n"
         "  pmr render (a preset as a user gets it: its view count, camera spacing and default sampling\n"
         "  unless --views, --camera-spacing, --sampling), and so are\n"
         "  --animation, --fps and --turntable: the timed frames are then frames 0..K-1 of that sequence.\n"
         "Per point it prints the frame time, the per-stage device times, and the floor: the bytes a frame\n"
         "must move (each voxel written once, the display image written once) at the measured copy bandwidth.\n";
}

int run_bench(const std::vector<std::string>& args) {
  BenchOptions o = as_usage([&] { return parse(args); });
  if (o.help) {
    std::fputs(bench_help().c_str(), stdout);
    return 0;
  }
  if (!o.save_scene.empty()) {
    const Scene scene = generate(o.generator, o.triangle_counts[0]);
    save_glb(scene, o.save_scene);
    std::printf("wrote %s: %zu triangles\n", o.save_scene.c_str(), scene.triangles.size());
    return 0;
  }
  std::unique_ptr<std::ofstream> csv;
  if (!o.csv.empty()) {
    csv.reset(new std::ofstream(o.csv));
    if (!*csv) throw Error("cannot write " + o.csv);
  }
  if (!o.environment_file.empty()) {  // prefiltered once, before the first point
    o.environment = std::make_shared<const Environment>(
        Environment::make({o.environment_file, o.environment_rotation_deg, o.environment_intensity}));
    const PmrEnvironment& h = o.environment->tables().header;
    std::printf("# environment %s: %ux%u, prefiltered in %.2f s (%.1f MB of tables)\n", o.environment_file.c_str(),
                h.levels[0].width, h.levels[0].height, o.environment->prefilter_seconds(),
                double(o.environment->tables().data.size() * sizeof(float)) / 1e6);
  }
  set_memory_budget(o.limits.memory);
  ClRuntime rt;
  const double bw = copy_bandwidth(rt);
  if (csv)
    *csv << "scene,method,views,view_w,view_h,display_w,display_h,triangles,frames,ms_median,ms_min,ms_setup,ms_tile,"
            "ms_fine,ms_encode,mvoxels_per_s,peak_mem_mb,floor_mb,floor_ms,x_floor,coverage_mismatch,sampling,samples,"
            "msamples_per_s\n";
  if (o.generator.empty()) {
    const std::string path = o.scene.empty() ? default_scene_path() : o.scene;
    bench_scene(o, rt, bw, load_scene(path, o.limits), path.substr(path.rfind('/') + 1), csv.get());
  }
  for (size_t n : o.triangle_counts)
    bench_scene(o, rt, bw, generate(o.generator, n), o.generator + "-" + std::to_string(n), csv.get());
  return 0;
}

}  // namespace pmr
