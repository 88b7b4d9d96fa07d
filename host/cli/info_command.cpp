#include "cli/info_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pmr/printable.h"
#include "pmr/error.h"
#include "pmr/memory_budget.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"
#include "sequence/frame_files.h"
#include "sequence/frame_renderer.h"
#include "sequence/frame_work.h"
#include "pipeline/pipeline_config.h"
#include "shading/studio_environment.h"

namespace pmr {

namespace {

// Names come from the file: control and non-ASCII bytes are escaped, long names cut.
std::string quoted(const std::string& name) {
  return name.empty() ? "(unnamed)" : "'" + printable_text(name, 80) + "'";
}

// %g, with rounding noise below 1e-12 (a direction's zero component) printed as 0.
std::string number(double v) {
  if (std::abs(v) < 1e-12) v = 0.0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// "normal (set 1, transform offset (0, 1) rotation 1.571 scale (0.5, 0.5))"
std::string slot_text(const Scene& s, const SceneTextureSlot& slot, int kind) {
  static const char* const short_names[kTextureSlots] = {
      "base colour",       "metallic-roughness", "normal",
      "occlusion",         "emissive",           "transmission",
      "thickness",         "clear coat",         "clear coat roughness",
      "clear coat normal", "specular",           "specular colour",
      "anisotropy",        "iridescence",        "iridescence thickness",
      "sheen colour",      "sheen roughness"};
  std::string t = std::string(short_names[kind]) + " (texture " + std::to_string(slot.texture);
  if (slot.texture >= 0 && size_t(slot.texture) < s.textures.size())
    t += " " + std::to_string(s.textures[size_t(slot.texture)].width) + "x" +
         std::to_string(s.textures[size_t(slot.texture)].height);
  t += std::string(slot.srgb ? ", sRGB" : ", linear") + ", set " + std::to_string(slot.texcoord_set);
  if (slot.transform)
    t += ", transform offset (" + number(slot.offset[0]) + ", " + number(slot.offset[1]) + ") rotation " +
         number(slot.rotation) + " scale (" + number(slot.scale[0]) + ", " + number(slot.scale[1]) + ")";
  return t + ")";
}

// KHR_materials_transmission, _volume, _clearcoat, _specular, _anisotropy, _iridescence and _sheen where
// the material has them, and KHR_materials_ior's ior where it is not the default 1.5.
std::string layer_text(const SceneMaterialInputs& in) {
  std::string t;
  if (in.has_transmission) t += ", transmission " + number(in.transmission);
  if (in.has_volume) {
    t += ", thickness " + number(in.thickness) + ", attenuation (" + number(in.attenuation_color[0]) + ", " +
         number(in.attenuation_color[1]) + ", " + number(in.attenuation_color[2]) + ") over " +
         number(in.attenuation_distance);
  }
  if (in.ior != 1.5f) t += ", ior " + number(in.ior);
  if (in.has_clearcoat) {
    t += ", clear coat " + number(in.clearcoat) + " roughness " + number(in.clearcoat_roughness);
    if (in.slots[kSlotClearcoatNormal].texture >= 0) t += " normal scale " + number(in.clearcoat_normal_scale);
  }
  if (in.has_specular)
    t += ", specular " + number(in.specular) + " colour (" + number(in.specular_color[0]) + ", " +
         number(in.specular_color[1]) + ", " + number(in.specular_color[2]) + ")";
  if (in.has_anisotropy)
    t += ", anisotropy " + number(in.anisotropy_strength) + " rotation " + number(in.anisotropy_rotation);
  if (in.has_iridescence)
    t += ", iridescence " + number(in.iridescence) + " ior " + number(in.iridescence_ior) + " thickness " +
         number(in.iridescence_thickness[0]) + "-" + number(in.iridescence_thickness[1]) + " nm";
  if (in.has_sheen)
    t += ", sheen (" + number(in.sheen_color[0]) + ", " + number(in.sheen_color[1]) + ", " + number(in.sheen_color[2]) +
         ") roughness " + number(in.sheen_roughness);
  return t;
}

void describe_materials(const Scene& s) {
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const PmrMaterial& m = s.materials[i];
    const SceneMaterialInputs in = i < s.material_inputs.size() ? s.material_inputs[i] : SceneMaterialInputs{};
    std::string line = "  " + std::to_string(i) + " " + (i == 0 ? std::string("(default)") : quoted(in.name)) + ": ";
    line += m.alpha_mode == PMR_ALPHA_MASK    ? "alpha MASK (cutoff " + number(m.alpha_cutoff) + ")"
            : m.alpha_mode == PMR_ALPHA_BLEND ? std::string("alpha BLEND")
                                              : std::string("alpha OPAQUE");
    line += m.double_sided ? ", double sided" : ", single sided";
    if (in.unlit) line += ", unlit";
    line += ", base (" + number(m.base_color[0]) + ", " + number(m.base_color[1]) + ", " + number(m.base_color[2]) +
            ", " + number(m.base_color[3]) + ")";
    line += ", metallic " + number(in.metallic) + ", roughness " + number(in.roughness);
    if (in.emissive[0] > 0 || in.emissive[1] > 0 || in.emissive[2] > 0 || in.slots[kSlotEmissive].texture >= 0)
      line += ", emissive (" + number(in.emissive[0]) + ", " + number(in.emissive[1]) + ", " + number(in.emissive[2]) +
              ") x strength " + number(in.emissive_strength);
    if (in.slots[kSlotNormal].texture >= 0) line += ", normal scale " + number(in.normal_scale);
    if (in.slots[kSlotOcclusion].texture >= 0) line += ", occlusion strength " + number(in.occlusion_strength);
    line += layer_text(in);
    std::printf("%s\n", line.c_str());
    for (int k = 0; k < kTextureSlots; ++k)
      if (in.slots[size_t(k)].texture >= 0) std::printf("      %s\n", slot_text(s, in.slots[size_t(k)], k).c_str());
    if (!in.unimplemented.empty()) {
      std::string list;
      for (const std::string& e : in.unimplemented) list += (list.empty() ? "" : ", ") + printable_text(e, 80);
      std::printf("      not drawn: %s\n", list.c_str());
    }
  }
}

void describe_lights(const Scene& s) {
  std::printf("lights: %zu%s\n", s.lights.size(),
              s.lights.empty() ? "" : " (KHR_lights_punctual, EXT_lights_area; rest pose, world space)");
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const SceneLight& l = s.lights[i];
    const char* type = light_type_name(l.type);
    const bool area = is_area_light(l);
    std::string line = "  " + std::to_string(i) + " " + quoted(l.name) + " (light " + std::to_string(l.light) +
                       "): " + type + ", node " + std::to_string(l.node) + " " + quoted(l.node_name) + ", color (" +
                       number(l.color[0]) + ", " + number(l.color[1]) + ", " + number(l.color[2]) + "), intensity " +
                       number(l.intensity) +
                       (l.type == SceneLightType::Directional ? " lux"
                        : area                                ? " nits"
                                                              : " cd");
    if (l.type != SceneLightType::Directional && !area)
      line += l.range > 0 ? ", range " + number(l.range) : ", no range";
    if (l.type == SceneLightType::Spot)
      line += ", cones inner " + number(l.inner_cone * 180.0 / 3.14159265358979323846) + " deg outer " +
              number(l.outer_cone * 180.0 / 3.14159265358979323846) + " deg";
    if (l.type != SceneLightType::Directional)
      line += ", at (" + number(l.position.x) + ", " + number(l.position.y) + ", " + number(l.position.z) + ")";
    if (l.type != SceneLightType::Point)
      line += ", toward (" + number(l.direction.x) + ", " + number(l.direction.y) + ", " + number(l.direction.z) + ")";
    if (l.radius > 0.0f) line += ", radius " + number(l.radius) + " m (soft shadows)";
    if (l.angle > 0.0f) line += ", angle " + number(l.angle * 180.0 / 3.14159265358979323846) + " deg (soft shadows)";
    if (l.type == SceneLightType::Rect) line += ", " + number(l.width) + " x " + number(l.height) + " m";
    if (l.type == SceneLightType::Disk) line += ", diameter " + number(l.width) + " m";
    std::printf("%s\n", line.c_str());
  }
}

// Whether a perspective camera can drive the rig, and how to select it.
std::string camera_use(const SceneCamera& c, size_t index) {
  if (!c.placed) return "not placed by any node of the scene";
  if (!c.invalid.empty()) return "invalid: " + c.invalid;
  const std::string shared =
      c.shared_with >= 0 ? ", a further node of camera " + std::to_string(c.shared_with) : std::string();
  return "placed by node " + quoted(c.node_name) + shared + " (--camera '#" + std::to_string(index) + "')";
}

// The frame-work estimate of a frame at the defaults (paper-8k: 96 views of 1024x512, 4 samples, pbr
// shading under the studio with shadows on, whose soft boxes are lights besides the file's, the rest
// pose framed): the light part exact, the BLEND part an upper bound.
void describe_default_frame_work(const Scene& s, const InputLimits& limits) {
  glm::dvec3 lo(-1.0), hi(1.0);
  scene_bounds(s, lo, hi);
  PipelineConfig config;
  config.samples = 4;
  const Rig rig = make_rig(RigConfig(), Display(), lo, hi);
  std::vector<SceneLight> lights = s.lights;
  for (SceneLight& box : studio_box_lights()) lights.push_back(std::move(box));
  const FrameWork work = estimate_frame_work(s, rig, light_evaluations_per_point(lights), config,
                                             shadow_cost(lights, kOcclusionDirections, config.shadow_sizes));
  std::printf("frame work at paper-8k: %s; the limit is %llu (--limit frame-work; docs/SECURITY.md)\n",
              describe_frame_work(work).c_str(), (unsigned long long)limits.frame_work);
}

// What a user needs to pick --camera and --animation, and to see what the loader made of the file.
void describe_scene(const std::string& path, const InputLimits& limits) {
  set_memory_budget(limits.memory);
  const Scene s = load_scene(path, limits);
  const SceneStructure& d = s.structure;
  std::printf("scene: %s%s\n", terminal_text(path).c_str(),
              d.generator.empty() ? "" : (" (generator: " + printable_text(d.generator, 120) + ")").c_str());
  std::printf("triangles: %zu, vertices: %zu (%zu mesh instance(s) of %zu mesh(es), %zu primitive(s), %zu node(s))\n",
              s.triangles.size(), s.positions.size(), d.mesh_instances, d.meshes, d.primitives, d.nodes);
  size_t textured = 0;  // with a base colour texture
  for (const SceneMaterialInputs& in : s.material_inputs) textured += in.slots[kSlotBaseColor].texture >= 0;
  std::printf("materials: %zu (with the default one; %zu textured), textures: %zu\n", s.materials.size(), textured,
              s.textures.size());
  describe_materials(s);
  if (!s.variants.empty()) {
    std::printf("material variants: %zu (KHR_materials_variants; --variant NAME or #K, default: none)\n",
                s.variants.size());
    for (size_t i = 0; i < s.variants.size(); ++i) std::printf("  %zu %s\n", i, quoted(s.variants[i]).c_str());
  }
  if (d.generated_tangent_primitives)
    std::printf("tangents: generated for %zu primitive(s) with a normal texture and no TANGENT\n",
                d.generated_tangent_primitives);
  describe_lights(s);
  std::printf("cameras: %zu\n", s.cameras.size());
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    const SceneCamera& c = s.cameras[i];
    if (!c.perspective) {
      std::printf("  %zu %s: orthographic (not usable with --camera)\n", i, quoted(c.name).c_str());
      continue;
    }
    char zfar[32] = "infinite";
    if (c.zfar > 0) std::snprintf(zfar, sizeof zfar, "%g", c.zfar);
    std::printf("  %zu %s: perspective, yfov %.2f deg, znear %g, zfar %s, %s\n", i, quoted(c.name).c_str(),
                c.yfov * 180.0 / 3.14159265358979323846, c.znear, zfar, camera_use(c, i).c_str());
  }
  std::printf("animations: %zu\n", s.animations.size());
  for (size_t i = 0; i < s.animations.size(); ++i) {
    const SceneAnimation& a = s.animations[i];
    SequenceSpec spec;  // what --frames all renders at the default fps
    spec.animation = int(i);
    long first = 0, last = 0;
    std::string frames;
    try {
      frames = animation_key_frames(s, spec, first, last) ? std::to_string(first) + ":" + std::to_string(last)
                                                          : "none (no frame time lies inside the keys)";
    } catch (const Error&) {
      frames = "too long to render";
    }
    std::printf("  %zu %s: %zu channel(s), keys %.3f to %.3f s; --frames all at 24 fps: %s\n", i,
                quoted(a.name).c_str(), a.channels, a.start, a.end, frames.c_str());
  }
  if (!s.animations.empty())
    std::printf("posing: %llu units a frame with --animation all (--limit pose-work; docs/SECURITY.md, \"Posing\")\n",
                (unsigned long long)pose_work(s, kAllAnimations));
  std::printf("skins: %zu\n", d.skin_joints.size());
  for (size_t i = 0; i < d.skin_joints.size(); ++i) std::printf("  %zu: %zu joint(s)\n", i, d.skin_joints[i]);
  std::printf("morph targets: %zu mesh(es)\n", d.morph_meshes.size());
  for (const auto& [mesh, targets] : d.morph_meshes) std::printf("  mesh %d: %zu target(s)\n", mesh, targets);
  glm::dvec3 lo, hi;
  if (scene_bounds(s, lo, hi))
    std::printf("bounds (rest pose): min (%g, %g, %g), max (%g, %g, %g), center (%g, %g, %g), radius %g\n", lo.x, lo.y,
                lo.z, hi.x, hi.y, hi.z, 0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z),
                0.5 * glm::length(hi - lo));
  else std::printf("bounds: none (no triangles)\n");
  describe_default_frame_work(s, limits);
  std::printf("warnings: %zu\n", s.warnings.size());
  for (const std::string& w : s.warnings) std::printf("  %s\n", terminal_text(w).c_str());
}

}  // namespace

int run_info(const std::vector<std::string>& args) {
  std::string scene;
  InputLimits limits;
  bool options = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::printf(
          "usage: pmr info            list OpenCL platforms and devices\n"
          "       pmr info SCENE [--limit KEY=VALUE[,...]] [--allow-outside-scene-folder]\n"
          "                           what a glTF scene holds: triangles, materials and their textures,\n"
          "                           lights, cameras, animations, skins, morph targets, bounds, and the\n"
          "                           loader's warnings; the options as for pmr render (docs/SECURITY.md)\n");
      return 0;
    }
    if (a == "--limit") {
      if (i + 1 >= args.size()) throw UsageError("option --limit needs a value (see pmr info --help)");
      as_usage([&] { parse_limits(args[++i], limits); });
      options = true;
    } else if (a == "--allow-outside-scene-folder") {
      limits.allow_outside_scene_folder = true;
      options = true;
    } else if (!a.empty() && a[0] == '-') {
      throw UsageError("unknown option " + a + " (see pmr info --help)");
    } else if (scene.empty()) {
      scene = a;
    } else {
      throw UsageError("pmr info takes at most one scene file");
    }
  }
  if (!scene.empty()) {
    describe_scene(scene, limits);
    return 0;
  }
  if (options) throw UsageError("--limit and --allow-outside-scene-folder apply to a scene: pmr info SCENE ...");
  for (const auto& line : describe_opencl_devices()) std::printf("%s\n", line.c_str());
  return 0;
}

}  // namespace pmr
