#include "cli/render_command.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "cli/options.h"
#include "pipeline/pipeline.h"
#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"

#ifndef PMR_DEFAULT_DATA_DIR
#define PMR_DEFAULT_DATA_DIR ""
#endif

namespace pmr {

namespace {

bool file_exists(const std::string& p) { return std::ifstream(p).good(); }

std::string exe_dir() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  std::string s(buf, size_t(n));
  return s.substr(0, s.rfind('/'));
}

std::string frame_name(const std::string& dir, int frame, const char* suffix) {
  char name[64];
  std::snprintf(name, sizeof name, "/frame_%04d%s", frame, suffix);
  return dir + name;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

std::string default_scene_path() {
  std::vector<std::string> candidates;
  if (const char* d = std::getenv("PMR_DATA_DIR")) candidates.push_back(std::string(d) + "/default_scene.glb");
  candidates.push_back(exe_dir() + "/data/default_scene.glb");
  candidates.push_back(exe_dir() + "/../data/default_scene.glb");
  candidates.push_back(std::string(PMR_DEFAULT_DATA_DIR) + "/default_scene.glb");
  for (const auto& c : candidates)
    if (file_exists(c)) return c;
  throw Error("the default scene data/default_scene.glb was not found (set PMR_DATA_DIR or give a scene file)");
}

int run_render(const std::vector<std::string>& args) {
  RenderOptions o = parse_render_options(args);
  if (o.help) {
    std::fputs(render_help().c_str(), stdout);
    return 0;
  }
  finalize_render_options(o);
  const auto t0 = std::chrono::steady_clock::now();
  const ExrCompression compression = parse_exr_compression(o.compression);
  if (o.scene.empty()) o.scene = default_scene_path();
  // Everything that can be checked cheaply is checked before the long work starts.
  prepare_output_dir(o.out_dir);
  make_encode_params(o.display, o.rig.views, o.rig.view_w, o.rig.view_h);

  Scene scene = load_scene(o.scene);
  for (const auto& w : scene.warnings) std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());
  glm::dvec3 lo, hi;
  scene_bounds(scene, lo, hi);
  const glm::dmat4* pose = nullptr;
  double cam_yfov = 0.0;
  if (o.rig.camera >= 0) {
    if (o.rig.camera >= int(scene.cameras.size()))
      throw Error("--camera " + std::to_string(o.rig.camera) + ": the scene has " +
                  std::to_string(scene.cameras.size()) + " camera(s)");
    const SceneCamera& cam = scene.cameras[size_t(o.rig.camera)];
    if (!cam.perspective || !cam.placed)
      throw Error("--camera " + std::to_string(o.rig.camera) + " is not a perspective camera placed in the scene");
    pose = &cam.world_from_camera;
    cam_yfov = cam.yfov;
  }
  std::vector<std::string> warnings;
  const Rig rig = make_rig(o.rig, o.display, lo, hi, pose, cam_yfov, &warnings);
  for (const auto& w : warnings) std::fprintf(stderr, "pmr: warning: %s\n", w.c_str());

  std::fprintf(stderr, "pmr: %s: %zu triangles, %d views of %dx%d -> %dx%d display\n", o.scene.c_str(),
               scene.triangles.size(), rig.views, rig.view_w, rig.view_h, o.display.width, o.display.height);
  ClRuntime runtime;
  const auto t_build = std::chrono::steady_clock::now();
  PipelineConfig pc = o.pipeline;
  pc.fuse_encode = !o.write_views;  // the volume is only kept when the views are written
  Pipeline pipeline(runtime, pc);
  if (o.verbose)
    std::fprintf(stderr, "pmr: device %s; kernels built in %.2f s\n", runtime.device_name().c_str(), seconds_since(t_build));
  pipeline.set_scene(scene);
  pipeline.configure(rig, o.write_encoded ? &o.display : nullptr);
  const StageTimes t = pipeline.render(rig);
  std::fprintf(stderr, "pmr: rendered in %.1f ms (device %.1f ms)\n", t.wall, t.device_total);
  if (o.verbose) {
    if (pipeline.fused())
      std::fprintf(stderr,
                   "pmr: stage times (ms): vertex %.2f, setup %.2f, tile raster %.2f, fine raster + encode (fused) "
                   "%.2f, straddling alpha %.2f\n",
                   t.vertex, t.setup, t.bin, t.fine, t.encode);
    else
      std::fprintf(stderr,
                   "pmr: stage times (ms): vertex %.2f, setup %.2f, tile raster %.2f, fine raster %.2f, encode %.2f\n",
                   t.vertex, t.setup, t.bin, t.fine, t.encode);
    std::fprintf(stderr, "pmr: %u MTAs, %llu tile-queue entries, %d queue regrowth(s)\n", t.mtas,
                 (unsigned long long)t.bin_entries, t.retries);
  }

  const auto t_write = std::chrono::steady_clock::now();
  SidecarInfo info;
  info.scene = o.scene;
  info.frame = o.frame;
  info.tile_x = o.pipeline.tile_x;
  info.tile_y = o.pipeline.tile_y;
  info.tile_v = o.pipeline.tile_v;
  info.method = to_string(o.pipeline.method);
  info.camera = o.rig.camera;
  info.has_bounds = true;
  info.bounds_lo = lo;
  info.bounds_hi = hi;
  info.compression = to_string(compression);
  info.warnings = scene.warnings;
  info.warnings.insert(info.warnings.end(), warnings.begin(), warnings.end());
  auto base = [](const std::string& path) { return path.substr(path.rfind('/') + 1); };
  if (o.write_encoded) {
    std::vector<uint16_t> image;
    pipeline.read_display(image);
    const std::string path = frame_name(o.out_dir, o.frame, ".exr");
    write_rgba_exr(path, o.display.width, o.display.height, image.data(), compression, 2);
    info.outputs.push_back({"encoded", base(path)});
    std::fprintf(stderr, "pmr: wrote %s\n", path.c_str());
  }
  if (o.write_views) {
    std::vector<uint16_t> volume;
    pipeline.read_volume(volume);
    const std::string path = frame_name(o.out_dir, o.frame, ".views.exr");
    // pixels of a view are non-square: the view spans the display's aspect A
    const float pixel_aspect = float(rig.aspect * rig.view_h / rig.view_w);
    write_views_exr(path, rig.view_w, rig.view_h, rig.views, volume.data(), nullptr, compression, 2, pixel_aspect);
    info.outputs.push_back({"views", base(path)});
    std::fprintf(stderr, "pmr: wrote %s\n", path.c_str());
  }
  const std::string sidecar = frame_name(o.out_dir, o.frame, ".json");
  write_sidecar(sidecar, rig, o.display, info);
  std::fprintf(stderr, "pmr: wrote %s\n", sidecar.c_str());
  if (o.verbose) std::fprintf(stderr, "pmr: writing took %.2f s\n", seconds_since(t_write));
  std::fprintf(stderr, "pmr: done in %.2f s\n", seconds_since(t0));
  return 0;
}

}  // namespace pmr
