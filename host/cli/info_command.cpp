#include "cli/info_command.h"

#include <cmath>
#include <cstdio>

#include "pmr/error.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"
#include "sequence/frame_renderer.h"

namespace pmr {

namespace {

std::string quoted(const std::string& name) { return name.empty() ? "(unnamed)" : "'" + name + "'"; }

// What a user needs to pick --camera and --animation, and to see what the loader made of the file.
void describe_scene(const std::string& path) {
  const Scene s = load_scene(path);
  const SceneStructure& d = s.structure;
  std::printf("scene: %s%s\n", path.c_str(), d.generator.empty() ? "" : (" (generator: " + d.generator + ")").c_str());
  std::printf("triangles: %zu, vertices: %zu (%zu mesh instance(s) of %zu mesh(es), %zu primitive(s), %zu node(s))\n",
              s.triangles.size(), s.positions.size(), d.mesh_instances, d.meshes, d.primitives, d.nodes);
  size_t textured = 0;
  for (const PmrMaterial& m : s.materials) textured += m.texture >= 0;
  std::printf("materials: %zu (with the default one; %zu textured), textures: %zu\n", s.materials.size(), textured,
              s.textures.size());
  std::printf("cameras: %zu\n", s.cameras.size());
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    const SceneCamera& c = s.cameras[i];
    if (!c.perspective) {
      std::printf("  %zu %s: orthographic (not usable with --camera)\n", i, quoted(c.name).c_str());
      continue;
    }
    char zfar[32] = "infinite";
    if (c.zfar > 0) std::snprintf(zfar, sizeof zfar, "%g", c.zfar);
    std::printf("  %zu %s: perspective, yfov %.2f deg, znear %g, zfar %s%s\n", i, quoted(c.name).c_str(),
                c.yfov * 180.0 / 3.14159265358979323846, c.znear, zfar,
                (c.placed ? ", placed (--camera " + std::to_string(i) + ")" : ", not placed by any node of the scene").c_str());
  }
  std::printf("animations: %zu\n", s.animations.size());
  for (size_t i = 0; i < s.animations.size(); ++i) {
    const SceneAnimation& a = s.animations[i];
    SequenceSpec spec;  // what --frames all renders at the default fps
    spec.animation = int(i);
    long first = 0, last = 0;
    std::string frames;
    try {
      animation_frame_range(s, spec, first, last);
      frames = std::to_string(first) + ":" + std::to_string(last);
    } catch (const Error&) {
      frames = "too long to render";
    }
    std::printf("  %zu %s: %zu channel(s), keys %.3f to %.3f s; --frames all at 24 fps: %s\n", i,
                quoted(a.name).c_str(), a.channels, a.start, a.end, frames.c_str());
  }
  std::printf("skins: %zu\n", d.skin_joints.size());
  for (size_t i = 0; i < d.skin_joints.size(); ++i) std::printf("  %zu: %zu joint(s)\n", i, d.skin_joints[i]);
  std::printf("morph targets: %zu mesh(es)\n", d.morph_meshes.size());
  for (const auto& [mesh, targets] : d.morph_meshes) std::printf("  mesh %d: %zu target(s)\n", mesh, targets);
  glm::dvec3 lo, hi;
  if (scene_bounds(s, lo, hi))
    std::printf("bounds (rest pose): min (%g, %g, %g), max (%g, %g, %g), center (%g, %g, %g), radius %g\n", lo.x, lo.y,
                lo.z, hi.x, hi.y, hi.z, 0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z),
                0.5 * glm::length(hi - lo));
  else
    std::printf("bounds: none (no triangles)\n");
  std::printf("warnings: %zu\n", s.warnings.size());
  for (const std::string& w : s.warnings) std::printf("  %s\n", w.c_str());
}

}  // namespace

int run_info(const std::vector<std::string>& args) {
  if (args.size() > 1) throw Error("pmr info takes at most one scene file");
  if (args.size() == 1 && (args[0] == "-h" || args[0] == "--help")) {
    std::printf("usage: pmr info            list OpenCL platforms and devices\n"
                "       pmr info SCENE      what a glTF scene holds: triangles, materials, cameras, animations,\n"
                "                           skins, morph targets, bounds, and the loader's warnings\n");
    return 0;
  }
  if (args.size() == 1) {
    describe_scene(args[0]);
    return 0;
  }
  for (const auto& line : describe_opencl_devices()) std::printf("%s\n", line.c_str());
  return 0;
}

}  // namespace pmr
