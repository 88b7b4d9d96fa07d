// The per-frame JSON sidecar (DESIGN section 6): everything needed to reproduce or check a frame.

#include <map>

#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "output/sidecar.h"
#include "output/backdrop.h"

#include "output/checksum.h"
#include "output/sidecar_names.h"
#include "pmr/error.h"
#include "pmr/json_text.h"
#include "pmr/output.h"
#include "pmr/printable.h"
#include "pmr/version.h"
#include "shading/lights.h"
#include "scene/ground_catcher.h"
#include "shading/environment_occlusion.h"

namespace pmr {
namespace {

// Insertion order kept, so "format" comes first and related fields stay together.
using json = nlohmann::ordered_json;

// What a sidecar lists in full: beyond these a count (and, for lights, a digest) stands for the rest.
constexpr size_t kSidecarLights = 256, kSidecarWarnings = 64;

std::string scalar_text(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

// Pretty printing with two-space indentation like json::dump(2), except that arrays of scalars (the
// matrices and vectors) stay on one line. Numbers are printed by nlohmann::json (round-trip precision).
void emit(const json& j, int indent, std::string& out) {
  const std::string pad(size_t(indent) + 2, ' ');
  if (j.is_object() && !j.empty()) {
    out += "{\n";
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!first) out += ",\n";
      first = false;
      out += pad + scalar_text(json(it.key())) + ": ";
      emit(it.value(), indent + 2, out);
    }
    out += "\n" + std::string(size_t(indent), ' ') + "}";
  } else if (j.is_array() && !j.empty()) {
    bool flat = true;
    for (const json& e : j) flat = flat && !e.is_structured();
    out += flat ? "[" : "[\n";
    bool first = true;
    for (const json& e : j) {
      if (!first) out += flat ? ", " : ",\n";
      first = false;
      if (flat) {
        out += scalar_text(e);
      } else {
        out += pad;
        emit(e, indent + 2, out);
      }
    }
    out += flat ? "]" : "\n" + std::string(size_t(indent), ' ') + "]";
  } else {
    out += scalar_text(j);
  }
}

// 16 numbers, column-major as glTF stores them: element c * 4 + r is row r of column c (glm: m[c][r]).
json matrix_json(const glm::dmat4& m) {
  json a = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);
  return a;
}

json vec3_json(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }

// One light as pbr used it, world space, with what its type reads: a position for point, spot and area
// lights, a direction (where the light travels) for all but point lights, a range (null: none) for
// point and spot lights, the cone angles (radians) for spots, an area light's axes (right, up: its
// width and height run along them) and world width and height (a disk's: its diameter).
json light_json(const SceneLight& l) {
  const bool is_default = is_default_light(l), from_file = !is_default && !l.distant;
  json j = {{"name", bounded_text(l.name)}, {"source", is_default ? "default" : from_file ? "file" : "environment"}};
  if (from_file) j["light"] = l.light, j["node"] = l.node;
  if (l.distant) j["distant"] = true;  // position: the unit direction toward it; its shape at distance 1
  j["type"] = light_type_name(l.type);
  j["color"] = {double(l.color[0]), double(l.color[1]), double(l.color[2])};
  j["intensity"] = double(l.intensity);
  if (l.type != SceneLightType::Directional) j["position"] = vec3_json(l.position);
  if (l.type != SceneLightType::Point) j["direction"] = vec3_json(l.direction);
  const bool area = is_area_light(l);
  if (l.type != SceneLightType::Directional && !area) j["range"] = l.range > 0.0f ? json(double(l.range)) : json();
  if (l.type == SceneLightType::Spot)
    j["inner_cone_angle"] = double(l.inner_cone), j["outer_cone_angle"] = double(l.outer_cone);
  if (l.radius > 0.0f) j["radius"] = double(l.radius);  // absent: point-like, as every older sidecar
  if (l.angle > 0.0f) j["angle"] = double(l.angle);
  if (area) {  // as placed: the plane's axes and the world size
    j["right"] = vec3_json(l.right), j["up"] = vec3_json(l.up);
    j["width"] = l.width, j["height"] = l.height;
  }
  return j;
}

// The shading model and its lights as used (docs/SHADING.md). Sidecars written before --shading existed
// have none: they were lambert at exposure 0. Lambert's one light is the top-level light_dir_*. An
// environment image is recorded by its file (as given), the checksum of its bytes, rotation and
// intensity, so --resume renders again when any of them changes.
// The first kSidecarLights lights (a file may hold 100,000: the sidecar stays readable); with more,
// the whole list is compared through lights_total and lights_digest.
json lights_json(const std::vector<SceneLight>& lights) {
  json list = json::array();
  for (size_t i = 0; i < lights.size() && i < kSidecarLights; ++i) list.push_back(light_json(lights[i]));
  return list;
}

// XXH3 of every light as recorded, without what follows the frame (position, direction): equal for two
// frames of one configuration, as the comparison of other frames' listed lights is.
std::string lights_digest(const std::vector<SceneLight>& lights) {
  std::string all;
  for (const SceneLight& l : lights) {
    json j = light_json(l);
    j.erase("position"), j.erase("direction");
    all += scalar_text(j) + "\n";
  }
  return checksum_hex(all.data(), all.size());
}

json shading_json(const SidecarInfo& info) {
  const RenderSettings& p = info.render;
  json s = {{"model", to_string(p.shading)}, {"exposure_ev", p.exposure_ev}};
  if (p.shading != Shading::Pbr) return s;
  const EnvironmentSource::Kind kind = info.environment.kind;
  if (kind == EnvironmentSource::Kind::Uniform)
    s["environment"] = {
        {"kind", "uniform"}, {"radiance", 0.2 * p.environment_intensity}, {"intensity", p.environment_intensity}};
  else if (kind == EnvironmentSource::Kind::Studio)
    s["environment"] = {
        {"kind", "studio"}, {"rotation_deg", info.environment_rotation_deg}, {"intensity", p.environment_intensity}};
  else
    s["environment"] = {{"kind", "image"},
                        {"file", info.environment.file},
                        {"checksum", info.environment_checksum},
                        {"checksum_algorithm", kChecksumAlgorithm},
                        {"rotation_deg", info.environment_rotation_deg},
                        {"intensity", p.environment_intensity}};
  if (kind == EnvironmentSource::Kind::File && !is_utf8(info.environment.file))
    s["environment"]["file_hex"] = to_hex(info.environment.file);
  s["lights"] = lights_json(info.lights);
  if (info.render.shadows)  // absent: off, as every sidecar before shadows
    s["shadows"] = {
        {"map_size", info.render.shadow_sizes.directional},
        {"local_map_size", info.render.shadow_sizes.local},
        {"light_samples", kShadowSamples},
        {"environment_occlusion",
         {{"directions", info.render.environment_occlusion ? kOcclusionDirections : 0}, {"map_size", kOcclusionSize}}}};
  // where glass sees past the scene: the background shows through (a lower alpha), or the environment
  // is drawn there (absent: drawn, as every sidecar before clear glass)
  if (info.render.clear_glass) s["glass"] = "clear";
  if (info.render.ground_shadow)  // the catcher's plane (scene/ground_catcher.h); absent: none
    s["ground"] = {{"kind", "shadow"}, {"height", ground_height(info.bounds_lo, info.bounds_hi)}};
  if (info.lights.size() > kSidecarLights) {
    s["lights_total"] = info.lights.size();
    s["lights_digest"] = lights_digest(info.lights);
  }
  return s;
}

double degrees(double rad) { return rad * (180.0 / glm::pi<double>()); }

// The --display-config file's checksum; "" without one.
std::string display_config_checksum(const SidecarInfo& info) {
  return info.display_source.calibration ? info.display_source.calibration->checksum : "";
}

// What the render read, so that --resume and pmr verify notice a changed input.
json checksums_json(const SidecarInfo& info) {
  json c;
  c["algorithm"] = kChecksumAlgorithm;
  if (!info.scene_checksum.empty()) {
    c["scene"] = info.scene_checksum;
    json files = json::object();
    json files_hex = json::object();  // the names that are not UTF-8, byte-exact
    for (const auto& [file, sum] : info.scene_files) (is_utf8(file) ? files[file] : files_hex[to_hex(file)]) = sum;
    c["scene_files"] = files;
    if (!files_hex.empty()) c["scene_files_hex"] = files_hex;
  }
  if (!display_config_checksum(info).empty()) c["display_config"] = display_config_checksum(info);
  return c;
}

json output_checksums_json(const SidecarInfo& info) {
  json files = json::object();
  for (const OutputChecksum& o : info.output_checksums) {
    files[o.file] = {{"bytes", o.bytes}, {"checksum", o.checksum}};
    if (!is_utf8(o.file)) files[o.file]["name_hex"] = to_hex(o.file);
  }
  return {{"algorithm", kChecksumAlgorithm}, {"files", files}};
}

json warnings_json(const std::vector<std::string>& warnings) {
  json list = json::array();
  for (size_t i = 0; i < warnings.size() && i < kSidecarWarnings; ++i) list.push_back(bounded_text(warnings[i], 1024));
  return list;
}

json quilt_json(const Rig& rig, const SidecarInfo& info) {
  return {
      {"columns", info.quilt_columns}, {"rows", info.quilt_rows},
      {"aspect", rig.aspect},          {"tile_width", rig.view_w},
      {"tile_height", rig.view_h},     {"order", "view 0 in the bottom-left tile, then left to right, then upward"}};
}

// null, not absent, when the frame has no animation or turntable: sidecar_config_difference requires
// both keys.
json animation_json(const SidecarInfo& info) {
  if (info.sequence.animation == kNoAnimation) return nullptr;
  return {{"index", info.sequence.animation}, {"name", bounded_text(info.sequence.animation_label)}};
}

json turntable_json(const SidecarInfo& info) {
  if (!info.sequence.turntable) return nullptr;
  return {{"degrees", info.sequence.turntable_deg},
          {"frames", info.sequence.turntable_frames},
          {"angle_deg", info.turntable_angle},
          {"pivot", vec3_json(info.pivot)},
          {"axis", vec3_json(glm::dvec3(0, 1, 0))}};
}

// A calibration file's values as read, by the file's names (every value a number).
json calibration_json(const LookingGlassCalibration& c) {
  const std::pair<const char*, double> values[] = {{"pitch", c.pitch},
                                                   {"slope", c.slope},
                                                   {"center", c.center},
                                                   {"DPI", c.dpi},
                                                   {"screenW", c.screen_w},
                                                   {"screenH", c.screen_h},
                                                   {"viewCone", c.view_cone},
                                                   {"fringe", c.fringe},
                                                   {"flipImageX", c.flip_x},
                                                   {"flipImageY", c.flip_y},
                                                   {"flipSubp", c.flip_subp},
                                                   {"invView", c.inv_view},
                                                   {"CellPatternMode", c.cell_pattern},
                                                   {"subpixelCells", double(c.cells.size())}};
  json cal = json::object();
  cal["serial"] = c.serial;
  for (const auto& [key, value] : values) cal[key] = value;
  return cal;
}

json display_json(const Display& display, const SidecarInfo& info) {
  json d;
  d["width"] = display.width;
  d["height"] = display.height;
  d["size_cm"] = {display.size_w_cm, display.size_h_cm};
  d["viewing_distance_cm"] = display.viewing_distance_cm;
  d["aspect"] = display.aspect();
  d["lens_pitch"] = display.lens_pitch.value();
  d["lens_pitch_fraction"] = to_string(display.lens_pitch);
  d["tan_slant"] = display.tan_slant.value();
  d["tan_slant_fraction"] = to_string(display.tan_slant);
  d["offset"] = display.offset.value();
  d["offset_fraction"] = to_string(display.offset);
  d["reversed"] = display.reversed;
  d["phase_sign"] = display.phase_sign;
  d["subpixel_order"] = display.subpixel_bgr ? "bgr" : "rgb";
  if (!display.cell_offsets.empty()) {
    d["cell_rows"] = display.cell_rows;
    d["cell_offsets_1e14"] = display.cell_offsets;  // [(row class * 2 + j % 2) * 3 + k]
  }
  if (!info.display_source.name.empty()) d["source"] = info.display_source.name;
  if (info.display_source.calibration) d["calibration"] = calibration_json(*info.display_source.calibration);
  d["sampling"] = display.bilinear ? "bilinear" : "nearest";
  d["view_blend"] = display.blend_views;
  return d;
}

json rig_json(const Rig& rig) {
  json r;
  r["views"] = rig.views;
  r["view_width"] = rig.view_w;
  r["view_height"] = rig.view_h;
  r["cone_deg"] = degrees(rig.cone);
  r["cone_rad"] = rig.cone;
  r["yfov_deg"] = degrees(rig.yfov);
  r["yfov_rad"] = rig.yfov;
  r["aspect"] = rig.aspect;
  r["focal_distance"] = rig.focal;
  r["baseline"] = rig.baseline();
  r["camera_spacing"] = rig.angular ? "angular" : "linear";
  r["zoom"] = rig.zoom;
  r["orbit_deg"] = {rig.orbit_az_deg, rig.orbit_el_deg};
  r["near"] = rig.near;
  r["near_used"] = rig.near_eff;
  r["far"] = rig.far;
  const double k = rig.disparity_k();
  r["disparity_px_at_infinity"] = rig.views > 1 ? k : 0.0;  // Delta(inf): view 0 to view N-1
  r["disparity_px_per_view_at_infinity"] = rig.views > 1 ? k / double(rig.views - 1) : 0.0;
  return r;
}

json views_json(const Rig& rig) {
  json views = json::array();
  for (int i = 0; i < rig.views; ++i)
    views.push_back({{"index", i},
                     {"offset", rig.camera_offset(i)},
                     {"view", matrix_json(rig.view_matrix(i))},
                     {"proj", matrix_json(rig.projection(i))}});
  return views;
}

// How to read the numbers above without pmr's source at hand.
json conventions_json() {
  return {
      {"coordinates", "glTF: right-handed, +Y up, cameras look along -Z, +X right; rig distances in scene units"},
      {"raster",
       "row 0 is the top row; pixel (px, py) counts px from the left and py from the top, its center is "
       "(px + 0.5, py + 0.5)"},
      {"ndc_to_raster", "x = (x_ndc + 1) / 2 * view_width, y = (1 - y_ndc) / 2 * view_height"},
      {"views",
       "view 0 is the leftmost camera; camera i sits at 'offset' s_i along +X of the center camera: "
       "view = T(-s_i, 0, 0) * center_view; views[i] is part view_NNN of the views EXR"},
      {"matrices",
       "4x4, 16 numbers column-major as glTF stores them (element 4 * c + r is row r of column c); "
       "clip = proj * view * (x, y, z, 1); OpenGL clip space, NDC z in [-1, 1]"},
      {"depth",
       "the Z channel of the views and quilt EXRs (when written) is the view-space depth w: the distance "
       "along the view's axis, positive in front of the camera; where nothing was drawn +infinity, or "
       "depth_empty when recorded"},
      {"color", "linear-light RGB; alpha = coverage; background (0, 0, 0, 0)"},
      {"light",
       "light_dir_*: lambert's one directional light, toward the light, fixed in the center camera's "
       "view space; color = base * (0.2 + 0.8 * max(0, dot(n, l))). pbr is lit by shading.lights instead "
       "(world space; a light's direction is where it travels)"},
      {"encoding",
       "display pixel (j, i), row 0 at the top, subpixel k in {0,1,2} (R,G,B left to right): "
       "t = (3 j + k' - 3 i tan_slant - offset) / lens_pitch with k' = k (subpixel_order rgb) or 2 - k "
       "(bgr), v = floor(frac(phase_sign * t) * views) evaluated exactly, v -> views - 1 - v if "
       "reversed; with subpixel cells (display.cell_rows) k' = 0 and the offset of the pixel's cell and "
       "channel (display.cell_offsets_1e14 / 10^14); channel k of view v sampled at "
       "((j + (k + 0.5) / 3) / width, (i + 0.5) / height)"},
      {"sampling",
       "view: that position read from view v's view_width x view_height raster (nearest, or bilinear "
       "per display.sampling); subpixel: view v rasterized at that position itself, truncated to the "
       "raster's 16.16 / 24.8 fixed point (docs/SAMPLING.md)"},
  };
}

}  // namespace

std::string sidecar_json(const Rig& rig, const Display& display, const SidecarInfo& info) {
  json j;
  j["format"] = "pmr-sidecar-1";
  j["program_version"] = program_version();
  j["scene"] = info.scene;
  if (!is_utf8(info.scene)) j["scene_hex"] = to_hex(info.scene);
  if (!info.scene_checksum.empty() || !display_config_checksum(info).empty()) j["checksums"] = checksums_json(info);
  j["frame"] = info.frame;
  j["method"] = to_string(info.render.method);
  j["sampling"] = to_string(info.render.sampling);
  j["samples_per_pixel"] = info.render.samples;
  j["texture_filter"] = to_string(info.render.texture_filter);
  j["shading"] = shading_json(info);
  j["tile"] = {{"x", info.render.tile_x}, {"y", info.render.tile_y}, {"v", info.render.tile_v}};
  j["camera"] = info.rig_config.camera;
  if (info.rig_config.camera >= 0) j["camera_name"] = bounded_text(info.camera_name);
  if (info.variant) j["variant"] = bounded_text(*info.variant), j["variant_index"] = info.variant_index;
  if (info.has_bounds) j["scene_bounds"] = {{"min", vec3_json(info.bounds_lo)}, {"max", vec3_json(info.bounds_hi)}};
  if (info.compression) j["compression"] = to_string(*info.compression);
  if (const auto& t = info.view_transform)
    j["view_transform"] = {{"config", t->config}, {"display", t->display},       {"view", t->view},
                           {"look", t->look},     {"colorspace", t->colorspace}, {"exposure", t->exposure},
                           {"gamma", t->gamma}};
  json outputs = json::object(), outputs_hex = json::object();
  for (const auto& [kind, file] : info.outputs) {
    outputs[kind] = file;
    if (!is_utf8(file)) outputs_hex[kind] = to_hex(file);
  }
  j["outputs"] = outputs;
  if (!outputs_hex.empty()) j["outputs_hex"] = outputs_hex;
  const Background& bg = info.background;
  if (bg.environment)  // the plane it is drawn on: parallax f = 1 - D / depth, clamped (output/backdrop.h)
    j["background"] = {{"kind", "environment"},
                       {"depth", to_string(bg.depth)},
                       {"parallax", backdrop_parallax(rig, bg.depth).fraction}};
  else if (!bg.transparent())
    j["background"] = {bg.r, bg.g, bg.b, bg.a};
  if (!info.output_checksums.empty()) j["output_checksums"] = output_checksums_json(info);
  if (info.quilt_columns > 0) j["quilt"] = quilt_json(rig, info);
  if (info.center_view >= 0) j["preview_center_view"] = info.center_view;
  j["depth_channel"] = info.depth;
  // recorded when it is not the default +infinity (JSON has no infinity), so resume tells them apart
  if (info.depth && std::isfinite(info.depth_empty)) j["depth_empty"] = info.depth_empty;
  // the scene's files were read without confinement to its folder (docs/SECURITY.md)
  if (info.input_limits.allow_outside_scene_folder) j["allow_outside_scene_folder"] = true;
  j["warnings"] = warnings_json(info.warnings);
  if (info.warnings.size() > kSidecarWarnings) j["warnings_total"] = info.warnings.size();
  j["time"] = info.time;
  j["fps"] = info.sequence.fps;
  j["animation"] = animation_json(info);
  j["turntable"] = turntable_json(info);
  j["display"] = display_json(display, info);
  j["rig"] = rig_json(rig);
  if (info.rig_config.camera < 0) j["rig"]["framing"] = to_string(rig.framing);  // a glTF camera frames itself
  j["center_view"] = matrix_json(rig.center_view);
  j["light_dir_view"] = vec3_json(rig.light_view());
  j["light_dir_world"] = vec3_json(rig.light_world());
  j["views"] = views_json(rig);
  j["conventions"] = conventions_json();
  std::string text;
  emit(j, 0, text);
  return text + "\n";
}

namespace {

// The path and values of the first leaf where a and b differ (objects by key, arrays by index).
bool first_difference(const nlohmann::json& a, const nlohmann::json& b, std::string& path, std::string& va,
                      std::string& vb) {
  if (a == b) return false;
  if (a.is_object() && b.is_object()) {
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key()) || a[it.key()] != it.value()) {
        path += "." + it.key();
        return a.contains(it.key()) ? first_difference(a[it.key()], it.value(), path, va, vb)
                                    : (va = "absent", vb = it.value().dump(), true);
      }
    for (auto it = a.begin(); it != a.end(); ++it)
      if (!b.contains(it.key())) return path += "." + it.key(), va = it.value().dump(), vb = "absent", true;
  }
  if (a.is_array() && b.is_array() && a.size() == b.size())
    for (size_t i = 0; i < a.size(); ++i)
      if (a[i] != b[i]) return path += "[" + std::to_string(i) + "]", first_difference(a[i], b[i], path, va, vb);
  va = a.dump(), vb = b.dump();
  return true;
}

std::string short_value(const std::string& v) { return printable_text(v.size() > 40 ? v.substr(0, 37) + "..." : v); }

}  // namespace

std::string config_difference_text(const std::string& existing, const std::string& expected, const std::string& key,
                                   const std::string& existing_label, const std::string& expected_label) {
  const std::string plain = key + " differs";
  try {
    const nlohmann::json a = parse_json_text(existing), b = parse_json_text(expected);
    if (!a.is_object() || !b.is_object() || !a.contains(key) || !b.contains(key)) return plain;
    nlohmann::json x = a[key], y = b[key];
    for (nlohmann::json* t : {&x, &y})  // the frame's own angle is no difference (sidecar_config_difference)
      if (key == "turntable" && t->is_object()) t->erase("angle_deg");
    std::string path = key, va, vb;
    if (!first_difference(x, y, path, va, vb)) return plain;
    return plain + ": " + printable_text(path) + " " + short_value(va) + " in " + existing_label + ", " +
           short_value(vb) + " in " + expected_label;
  } catch (const std::exception&) {
    return plain;
  }
}

std::string sidecar_config_difference(const std::string& existing, const std::string& expected,
                                      bool ignore_scene_derived) {
  // compared as plain JSON, whose objects are sorted: the order of a sidecar's keys is no difference (a
  // sidecar rewritten by another tool compares as before)
  using json = nlohmann::json;
  const json b = json::parse(expected);
  const json a = parse_json_text(existing);
  if (!a.is_object() || !b.is_object()) return "unreadable";
  // a member of either side, null when absent (so a damaged sidecar compares unequal, never crashes)
  auto get = [](const json& o, const char* key) { return o.is_object() && o.contains(key) ? o[key] : json(); };
  for (const char* key : {"format", "scene", "method", "tile", "camera", "display", "fps", "depth_channel"})
    if (!a.contains(key) || get(a, key) != get(b, key)) return key;
  if (get(a, "variant") != get(b, "variant")) return "variant";                       // absent: the default materials
  if (get(a, "depth_empty") != get(b, "depth_empty")) return "depth_empty";           // absent: +infinity
  if (get(a, "view_transform") != get(b, "view_transform")) return "view_transform";  // absent: Standard
  // the selection by index as well as by name (recorded since names come first; absent in older sidecars)
  for (const char* key : {"variant_index", "camera_name"})
    if (a.contains(key) && b.contains(key) && get(a, key) != get(b, key)) return key;
  // the animation (its name comes from the scene file)
  auto anim = [&](json t) {
    if (ignore_scene_derived && t.is_object()) t.erase("name");
    return t;
  };
  if (!a.contains("animation") || anim(get(a, "animation")) != anim(get(b, "animation"))) return "animation";
  // the turntable without this frame's angle (and its pivot, the center of the scene's bounds)
  auto turn = [&](json t) {
    if (t.is_object()) t.erase("angle_deg");
    if (ignore_scene_derived && t.is_object()) t.erase("pivot");
    return t;
  };
  if (!a.contains("turntable") || turn(get(a, "turntable")) != turn(get(b, "turntable"))) return "turntable";
  // sidecars written before --sampling existed sampled the views
  auto sampling = [&](const json& o) { return get(o, "sampling").is_null() ? json("view") : get(o, "sampling"); };
  if (sampling(a) != sampling(b)) return "sampling";
  // sidecars written before --samples existed took one sample per pixel
  auto samples = [&](const json& o) {
    return get(o, "samples_per_pixel").is_null() ? json(1) : get(o, "samples_per_pixel");
  };
  if (samples(a) != samples(b)) return "samples_per_pixel";
  // sidecars written before --texture-filter existed filtered bilinearly from level 0
  auto filter = [&](const json& o) {
    return get(o, "texture_filter").is_null() ? json("bilinear") : get(o, "texture_filter");
  };
  if (filter(a) != filter(b)) return "texture_filter";
  if (get(a, "background") != get(b, "background")) return "background";  // absent: transparent
  // the lights: their poses follow the frame, so other frames' (pmr verify, the folder scan) are compared
  // without them; they follow from the scene file (its lights, or the default light when it has none and
  // no environment image lights it)
  const bool same_frame = !get(a, "frame").is_null() && get(a, "frame") == get(b, "frame");
  auto shading = [&](const json& o) {
    json s = get(o, "shading").is_null() ? json({{"model", "lambert"}, {"exposure_ev", 0.0}}) : get(o, "shading");
    if (!s.is_object()) return s;
    if (get(s, "model") == "pbr" && !s.contains("lights")) {
      // written before pmr recorded the lights, when pbr used the default light, or none with an image
      const json toward = get(o, "light_dir_world");
      s["lights"] = json();
      if (get(get(s, "environment"), "kind") == "image") s["lights"] = json::array();
      else if (toward.is_array() && toward.size() == 3 && toward[0].is_number() && toward[1].is_number() &&
               toward[2].is_number())
        s["lights"] = json::array(
            {json::parse(light_json(default_light(glm::dvec3(toward[0].get<double>(), toward[1].get<double>(),
                                                             toward[2].get<double>())))
                             .dump())});
    }
    if (ignore_scene_derived) {
      s.erase("lights");
    } else if (!same_frame && s.contains("lights") && s["lights"].is_array()) {
      for (json& l : s["lights"])
        if (l.is_object()) l.erase("position"), l.erase("direction");
    }
    return s;
  };
  if (shading(a) != shading(b)) return "shading";
  // the rig as configured (an animated camera moves the focal plane from frame to frame)
  const json ra = get(a, "rig"), rb = get(b, "rig");
  if (!ra.is_object()) return "rig";
  for (const char* key : {"views", "view_width", "view_height", "cone_deg", "yfov_deg", "aspect", "camera_spacing"})
    if (!ra.contains(key) || get(ra, key) != get(rb, key)) return std::string("rig.") + key;
  // sidecars written before --zoom existed framed at 1
  auto zoom = [&](const json& r) { return get(r, "zoom").is_null() ? json(1.0) : get(r, "zoom"); };
  if (zoom(ra) != zoom(rb)) return "rig.zoom";
  // and before --orbit existed at 0,0
  auto orbit = [&](const json& r) { return get(r, "orbit_deg").is_null() ? json({0.0, 0.0}) : get(r, "orbit_deg"); };
  if (orbit(ra) != orbit(rb)) return "rig.orbit_deg";
  // and before --framing existed by the sphere
  auto framing = [&](const json& r) { return get(r, "framing").is_null() ? json("sphere") : get(r, "framing"); };
  if (get(a, "camera") == -1 && framing(ra) != framing(rb)) return "rig.framing";
  // the framing (it follows from the scene file's content and the animation)
  if (!ignore_scene_derived && (!a.contains("scene_bounds") || get(a, "scene_bounds") != get(b, "scene_bounds")))
    return "scene_bounds";
  // the default framing's distance follows from the above, and from how pmr frames: a portrait
  // display was framed by its height before the sphere fit both directions (a glTF camera's distance
  // moves with an animated camera)
  if (!ignore_scene_derived && get(a, "camera") == -1 && get(ra, "focal_distance") != get(rb, "focal_distance"))
    return "rig.focal_distance";
  return "";
}

SidecarProvenance sidecar_provenance(const std::string& sidecar_text) {
  SidecarProvenance p;
  using json = nlohmann::json;  // sorted keys: linear-time lookups made ordered_json quadratic here
  const json j = parse_json_text(sidecar_text);
  if (!j.is_object()) return p;
  if (const auto v = j.find("program_version"); v != j.end() && v->is_string()) p.version = v->get<std::string>();
  const auto c = j.find("checksums");
  if (c == j.end() || !c->is_object()) return p;
  const auto algorithm = c->find("algorithm"), scene = c->find("scene"), files = c->find("scene_files");
  if (algorithm == c->end() || !algorithm->is_string() || scene == c->end() || !scene->is_string() ||
      files == c->end() || !files->is_object())
    return p;
  // canonical: files sorted by path (a name that is not UTF-8 by its bytes in hex), every value a string
  std::map<std::string, std::string> sorted;
  for (const auto& [name, sum] : recorded_scene_files(*c)) {
    if (!sum->is_string()) return p;
    sorted[is_utf8(name) ? name : "hex:" + to_hex(name)] = sum->get<std::string>();
  }
  json identity = json::array({*algorithm, *scene});
  for (const auto& [file, sum] : sorted) identity.push_back(json::array({file, sum}));
  p.scene = identity.dump(-1, ' ', false, json::error_handler_t::replace);
  return p;
}

void write_sidecar(const std::string& path, const Rig& rig, const Display& display, const SidecarInfo& info) {
  std::string text;
  try {
    text = sidecar_json(rig, display, info);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // e.g. nlohmann::json::type_error on a name that is not UTF-8
    throw Error("cannot write " + path + ": " + write_failure(e.what()));
  }
  check_sidecar_size(text.size());
  write_text_atomic(path, text);
}

void check_sidecar_size(uint64_t bytes) {
  if (bytes <= kMaxSidecarBytes) return;
  throw Error("a frame's sidecar would hold " + std::to_string(bytes) + " bytes, more than the " +
              std::to_string(kMaxSidecarBytes) +
              " pmr reads back (the scene reads too many files, or files with very long names)");
}

}  // namespace pmr
