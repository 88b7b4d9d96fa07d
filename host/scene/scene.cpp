// Scene-wide helpers shared by the loader, the synthetic scenes and the renderer.
#include <algorithm>
#include <cmath>
#include <limits>

#include "pmr/error.h"
#include "pmr/printable.h"
#include "pmr/scene.h"

namespace pmr {

PmrMaterial default_material() {
  PmrMaterial m{};
  for (float& c : m.base_color) c = 1.0f;
  m.alpha_mode = PMR_ALPHA_OPAQUE;
  m.alpha_cutoff = 0.5f;
  m.double_sided = 0;
  m.metallic = 1.0f;  // glTF's defaults
  m.roughness = 1.0f;
  for (PmrTextureMap& map : m.maps) map = PmrTextureMap{-1, 0, {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}};
  m.normal_scale = 1.0f;
  m.occlusion_strength = 1.0f;
  m.f0_dielectric = dielectric_f0(1.5);
  m.ior = 1.5f;
  m.transmission = 0.0f, m.thickness = 0.0f;  // opaque, thin
  m.attenuation_distance = std::numeric_limits<float>::infinity();
  for (float& c : m.attenuation_color) c = 1.0f;
  m.clearcoat = 0.0f, m.clearcoat_roughness = 0.0f, m.clearcoat_normal_scale = 1.0f;  // no coat
  m.specular = 1.0f;
  for (float& c : m.specular_color) c = 1.0f;
  m.anisotropy[0] = 0.0f, m.anisotropy[1] = 1.0f, m.anisotropy[2] = 0.0f;  // isotropic
  m.iridescence[0] = 0.0f, m.iridescence[1] = 1.3f, m.iridescence[2] = 100.0f, m.iridescence[3] = 400.0f;
  for (float& c : m.sheen) c = 0.0f;  // no sheen
  return m;
}

void apply_material_inputs(const SceneMaterialInputs& in, PmrMaterial& m) {
  m.metallic = in.metallic, m.roughness = in.roughness, m.unlit = in.unlit ? 1u : 0u;
  for (int c = 0; c < 3; ++c) m.emissive[c] = in.emissive[c] * in.emissive_strength;
  m.normal_scale = in.normal_scale, m.occlusion_strength = in.occlusion_strength;
  m.ior = in.ior, m.f0_dielectric = dielectric_f0(in.ior);
  m.transmission = in.transmission, m.thickness = in.thickness;
  m.attenuation_distance = in.attenuation_distance;
  for (int c = 0; c < 3; ++c) m.attenuation_color[c] = in.attenuation_color[c];
  m.clearcoat = in.clearcoat, m.clearcoat_roughness = in.clearcoat_roughness;
  m.clearcoat_normal_scale = in.clearcoat_normal_scale;
  m.specular = in.specular;
  for (int c = 0; c < 3; ++c) m.specular_color[c] = in.specular_color[c];
  m.anisotropy[0] = in.anisotropy_strength;
  m.anisotropy[1] = float(std::cos(double(in.anisotropy_rotation)));
  m.anisotropy[2] = float(std::sin(double(in.anisotropy_rotation)));
  m.iridescence[0] = in.iridescence, m.iridescence[1] = in.iridescence_ior;
  m.iridescence[2] = in.iridescence_thickness[0], m.iridescence[3] = in.iridescence_thickness[1];
  for (int c = 0; c < 3; ++c) m.sheen[c] = in.sheen_color[c];
  m.sheen[3] = in.sheen_roughness;
}

bool scene_transmissive(const Scene& scene) {
  auto transmission = [&](uint32_t m) {
    return m < scene.material_inputs.size() ? scene.material_inputs[m].transmission
                                            : (m < scene.materials.size() ? scene.materials[m].transmission : 0.0f);
  };
  for (const PmrTriangle& t : scene.triangles)
    if (transmission(t.material) > 0.0f) return true;
  return false;
}

bool scene_blended(const Scene& scene, bool pbr) {
  for (const PmrTriangle& t : scene.triangles) {
    if (t.material >= scene.materials.size() || scene.materials[t.material].alpha_mode != PMR_ALPHA_BLEND) continue;
    const bool glass = t.material < scene.material_inputs.size() ? scene.material_inputs[t.material].transmission > 0.0f
                                                                 : scene.materials[t.material].transmission > 0.0f;
    if (!(pbr && glass)) return true;
  }
  return false;
}

float dielectric_f0(double ior) {
  if (ior == 1.5) return 0.04f;  // glTF's default, exactly as the core specification writes it
  const double f = (ior - 1.0) / (ior + 1.0);
  return float(f * f);  // ior 0 (KHR_materials_ior's compatibility mode): 1
}

const char* texture_slot_name(int slot) {
  static const char* const names[kTextureSlots] = {
      "baseColorTexture",       "metallicRoughnessTexture", "normalTexture",
      "occlusionTexture",       "emissiveTexture",          "transmissionTexture",
      "thicknessTexture",       "clearcoatTexture",         "clearcoatRoughnessTexture",
      "clearcoatNormalTexture", "specularTexture",          "specularColorTexture",
      "anisotropyTexture",      "iridescenceTexture",       "iridescenceThicknessTexture",
      "sheenColorTexture",      "sheenRoughnessTexture"};
  return slot >= 0 && slot < kTextureSlots ? names[slot] : "?";
}

const char* texture_slot_extension(int slot) {
  static const char* const extensions[kTextureSlots] = {nullptr,
                                                        nullptr,
                                                        nullptr,
                                                        nullptr,
                                                        nullptr,
                                                        "KHR_materials_transmission",
                                                        "KHR_materials_volume",
                                                        "KHR_materials_clearcoat",
                                                        "KHR_materials_clearcoat",
                                                        "KHR_materials_clearcoat",
                                                        "KHR_materials_specular",
                                                        "KHR_materials_specular",
                                                        "KHR_materials_anisotropy",
                                                        "KHR_materials_iridescence",
                                                        "KHR_materials_iridescence",
                                                        "KHR_materials_sheen",
                                                        "KHR_materials_sheen"};
  return slot >= 0 && slot < kTextureSlots ? extensions[slot] : nullptr;
}

bool texture_slot_is_normal_map(int slot) { return slot == kSlotNormal || slot == kSlotClearcoatNormal; }

bool texture_slot_is_srgb(int slot) {
  return slot == kSlotBaseColor || slot == kSlotEmissive || slot == kSlotSpecularColor || slot == kSlotSheenColor;
}

bool scene_bounds(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi) {
  glm::dvec3 l(std::numeric_limits<double>::infinity()), h = -l;
  bool any = false;
  for (const PmrTriangle& t : scene.triangles) {
    for (uint32_t v : t.v) {
      if (v >= scene.positions.size()) throw Error("scene_bounds: triangle vertex index out of range");
      const glm::dvec3 p(scene.positions[v]);
      l = glm::min(l, p);
      h = glm::max(h, p);
      any = true;
    }
  }
  if (any) lo = l, hi = h;
  return any;
}

namespace {

// The cameras whose node name (or camera name) is `name`.
std::vector<int> cameras_named(const Scene& scene, const std::string& name, bool node) {
  std::vector<int> found;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const SceneCamera& c = scene.cameras[i];
    if (node ? c.placed && c.node_name == name : c.shared_with < 0 && c.name == name) found.push_back(int(i));
  }
  return found;
}

}  // namespace

IndexChoice parse_index_choice(const std::string& choice, size_t count, const std::string& things) {
  IndexChoice c;
  if (choice.empty() || choice[0] != '#') return c;
  c.is_index = true;
  const std::string digits = choice.substr(1);
  if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
    c.problem = "'#' starts an index (#0, #1, ...), and '" + printable_text(digits, 12) + "' is not a number";
  else if (std::stoul(digits) >= count) c.problem = "the scene has " + std::to_string(count) + " " + things;
  else c.index = int(std::stoul(digits));
  return c;
}

std::string unnamed_choice_hint(const std::string& choice, const std::string& lister) {
  if (!choice.empty() && choice.size() <= 9 && choice.find_first_not_of("0123456789") == std::string::npos)
    return " (an index is written #" + choice + "; " + lister + " lists them)";
  return " (" + lister + " lists them)";
}

int find_camera(const Scene& scene, const std::string& name) {
  const std::string shown = "--camera '" + printable_text(name, 60) + "'";
  for (bool node : {true, false}) {
    const std::vector<int> found = cameras_named(scene, name, node);
    if (found.size() == 1) return found[0];
    if (found.size() > 1)
      throw Error(shown + " is ambiguous: " + std::to_string(found.size()) + (node ? " camera nodes" : " cameras") +
                  " have that name (give the camera's index, #K; pmr info lists them)");
  }
  const IndexChoice index = parse_index_choice(name, scene.cameras.size(), "camera(s)");
  if (index.is_index) {
    if (!index.problem.empty()) throw Error(shown + ": " + index.problem);
    return index.index;
  }
  throw Error(shown + ": no camera node or camera of the scene has that name" + unnamed_choice_hint(name, "pmr info"));
}

const char* light_type_name(SceneLightType type) {
  switch (type) {
    case SceneLightType::Directional:
      return "directional";
    case SceneLightType::Point:
      return "point";
    case SceneLightType::Spot:
      return "spot";
    case SceneLightType::Rect:
      return "rect";
    case SceneLightType::Disk:
      return "disk";
  }
  return "unknown";
}

bool is_area_light(const SceneLight& light) {
  return light.type == SceneLightType::Rect || light.type == SceneLightType::Disk;
}

bool has_size(const SceneLight& light) {
  if (is_area_light(light)) return true;
  return light.type == SceneLightType::Directional ? light.angle > 0.0f : light.radius > 0.0f;
}

bool place_light(SceneLight& light, const glm::dmat4& world) {
  light.position = glm::dvec3(world[3]);
  const glm::dvec3 dir = -glm::dvec3(world[2]);
  const double len = glm::length(dir);
  if (!(len > 0.0 && std::isfinite(len))) return false;
  light.direction = dir / len;
  if (!is_area_light(light)) return true;
  // The plane's axes: the node's X, made orthogonal to the direction (a sheared matrix), then Y from the
  // right-handed frame; a degenerate X takes any axis of the plane.
  const glm::dvec3 x = glm::dvec3(world[0]), y = glm::dvec3(world[1]);
  glm::dvec3 right = x - glm::dot(x, light.direction) * light.direction;
  if (!(glm::length(right) > 1e-9 * len)) {
    right = glm::cross(light.direction, std::fabs(light.direction.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
  }
  light.right = glm::normalize(right);
  light.up = glm::cross(-light.direction, light.right);
  const double scale = std::max({glm::length(x), glm::length(y), len});
  // (at most 1e9 m: a node's scale can be anything finite, and the kernels take floats)
  light.height = std::min(scale * double(light.size), 1e9);
  light.width = light.type == SceneLightType::Rect ? std::min(light.height * double(light.aspect), 1e9) : light.height;
  return true;
}

}  // namespace pmr
