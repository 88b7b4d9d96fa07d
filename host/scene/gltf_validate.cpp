// glTF checks that tinygltf 2.7 does not do: the container and JSON before parsing, the structure
// (references, bufferView bounds, node hierarchy) after. See gltf_internal.h.
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "output/checksum.h"
#include "pmr/error.h"
#include "pmr/json_text.h"
#include "pmr/memory_budget.h"
#include "pmr/printable.h"
#include "pmr/scene.h"
#include "scene/gltf_internal.h"

namespace pmr::gltf {

using nlohmann::json;

void fail(const std::string& file, const std::string& what) { throw pmr::Error(file + ": " + what); }

std::string one_line(const std::string& text, bool ascii_only) {
  constexpr size_t kMax = 300;
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (out.size() >= kMax) return out + "...";
    // well-formed UTF-8 of a printable character is kept; C1 controls in their UTF-8 form (U+009B is
    // CSI), stray bytes and every other control are not
    const size_t n = ascii_only && static_cast<unsigned char>(text[i]) >= 0x80 ? 0 : printable_utf8_length(text, i);
    if (n > 0) {
      out.append(text, i, n);
      i += n;
    } else {
      out += text[i++] == '\n' ? ' ' : '?';
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

namespace {

// tinygltf's extras/extensions parser recurses once per nesting level, so a hostile file nested a
// million levels deep would overflow the stack: kMaxJsonDepth (pmr/json_text.h) bounds it.
// Memory per JSON value once parsed by both parsers (see read_source).
constexpr uint64_t kJsonBytesPerValue = 200;

// Extensions we implement. KHR_mesh_quantization only widens the component types the generic accessor
// reader already accepts; KHR_texture_transform is applied per texture slot; the material and light
// extensions are read into the scene (DESIGN 4b, 4c).
bool extension_supported(const std::string& name) {
  return name == "KHR_mesh_quantization" || name == "KHR_texture_transform" || name == "KHR_lights_punctual" ||
         name == "EXT_lights_area" || name == "KHR_materials_emissive_strength" || name == "KHR_materials_unlit" ||
         name == "KHR_materials_ior" || name == "KHR_materials_transmission" || name == "KHR_materials_volume" ||
         name == "KHR_materials_variants" || name == "KHR_materials_clearcoat" || name == "KHR_materials_specular" ||
         name == "KHR_materials_anisotropy" || name == "KHR_materials_iridescence" || name == "KHR_materials_sheen";
}

uint32_t read_u32le(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The scene file itself is the user's choice (no confinement), but still a regular file under the
// file-bytes budget: /dev/zero or a FIFO is refused, not read.
std::vector<unsigned char> read_whole_file(const std::string& path, const InputLimits& limits) {
  OpenInput in = open_input(path, nullptr, limits.file_bytes);
  if (in.status == InputFile::Status::NotFound) fail(path, "file not found");
  if (in.status == InputFile::Status::NotRegular && in.reason.find("directory") != std::string::npos)
    fail(path, "is a directory, not a glTF file");
  if (in.status != InputFile::Status::Ok) fail(path, in.reason);
  // tinygltf takes the length as unsigned int; a GLB cannot exceed 4 GiB anyway.
  if (in.size > std::numeric_limits<uint32_t>::max())
    fail(path, "file is larger than 4 GiB, which glTF loading does not support");
  // held twice while the parser copies a GLB's BIN chunk into its model
  check_memory(2 * in.size, "reading the scene file (" + std::to_string(in.size) + " bytes)");
  std::vector<unsigned char> bytes;
  if (!in.read(bytes)) fail(path, in.reason);
  if (bytes.empty()) fail(path, "file is empty");
  return bytes;
}

// Validates the GLB container strictly (tinygltf 2.7 lets the BIN chunk header run past the end) and
// returns the JSON chunk. bin_length gets the BIN chunk payload size, or -1 without a BIN chunk.
std::string glb_json(const std::string& path, std::vector<unsigned char>& bytes, int64_t& bin_length) {
  const uint64_t size = bytes.size();
  if (size < 12) fail(path, "truncated GLB: " + std::to_string(size) + " bytes, the header alone needs 12");
  const uint32_t version = read_u32le(&bytes[4]);
  if (version != 2)
    fail(path, "GLB container version " + std::to_string(version) + " is not supported (glTF 2.0 uses 2)");
  const uint64_t length = read_u32le(&bytes[8]);
  if (length > size)
    fail(path, "truncated GLB: the header says " + std::to_string(length) + " bytes but the file has " +
                   std::to_string(size));
  bytes.resize(size_t(length));  // anything after the declared length is not part of the GLB
  if (length < 20) fail(path, "truncated GLB: no room for the JSON chunk header");
  const uint64_t json_length = read_u32le(&bytes[12]);
  if (read_u32le(&bytes[16]) != 0x4E4F534Au) fail(path, "invalid GLB: the first chunk is not JSON");
  if (json_length == 0) fail(path, "invalid GLB: the JSON chunk is empty");
  if (20 + json_length > length)
    fail(path, "truncated GLB: the JSON chunk needs " + std::to_string(json_length) + " bytes but only " +
                   std::to_string(length - 20) + " remain");
  bin_length = -1;
  const uint64_t next = 20 + json_length;
  if (next < length) {
    if (next + 8 > length) fail(path, "truncated GLB: incomplete chunk header at byte " + std::to_string(next));
    const uint64_t chunk_length = read_u32le(&bytes[size_t(next)]);
    if (next + 8 + chunk_length > length)
      fail(path, "truncated GLB: the BIN chunk needs " + std::to_string(chunk_length) + " bytes but only " +
                     std::to_string(length - next - 8) + " remain");
    if (read_u32le(&bytes[size_t(next) + 4]) == 0x004E4942u) bin_length = int64_t(chunk_length);
  }
  return std::string(reinterpret_cast<const char*>(&bytes[20]), size_t(json_length));
}

// An index-like JSON value (non-negative integer); -1 when absent or of another type.
int64_t json_index(const json* v) {
  if (!v || !v->is_number_integer()) return -1;
  if (v->is_number_unsigned()) {
    uint64_t u = v->get<uint64_t>();
    return u > uint64_t(std::numeric_limits<int>::max()) ? -1 : int64_t(u);
  }
  return std::max<int64_t>(-1, v->get<int64_t>());
}

void check_extensions(const std::string& path, const json& doc, SourceFile& src) {
  if (const json* req = member(doc, "extensionsRequired")) {
    if (!req->is_array()) fail(path, "extensionsRequired is not an array");
    for (const json& e : *req) {
      if (!e.is_string()) fail(path, "extensionsRequired contains a non-string entry");
      const std::string name = e.get<std::string>();
      if (name == "KHR_draco_mesh_compression")
        fail(path,
             "requires KHR_draco_mesh_compression (Draco-compressed meshes), which this renderer does not support");
      // A material extension only changes how a surface looks: drawn without it, with one warning
      // per extension (the loader's), even when required.
      if (!extension_supported(name) && !material_extension_fallback(name))
        fail(path, "requires extension " + one_line(name) + ", which this renderer does not support");
    }
  }
  if (const json* used = member(doc, "extensionsUsed")) {
    if (!used->is_array()) return;
    for (const json& e : *used)
      if (e.is_string() && !extension_supported(e.get<std::string>()) &&
          !material_extension_fallback(e.get<std::string>()))
        src.ignored_extensions.push_back(e.get<std::string>());
  }
}

// A light's size from its extras (DESIGN section 4d): pmr_radius (metres, point and spot lights, at
// most 1e6) and pmr_angle (radians, directional lights, below pi / 2); absent: point-like.
void read_light_size(const std::string& path, const std::string& where, const json& light, SceneLight& out) {
  const json* extras = member(light, "extras");
  if (!extras || !extras->is_object()) return;
  const bool directional = out.type == SceneLightType::Directional;
  const char* key = directional ? "pmr_angle" : "pmr_radius";
  const json* v = member(*extras, key);
  if (!v) return;
  const double limit = directional ? 1.5707963267948966 : 1e6;
  if (!v->is_number() || !(v->get<double>() >= 0.0 && v->get<double>() < limit))
    fail(path, where + " extras." + key + " must be a number from 0 to " + (directional ? "pi/2" : "1e6") + " (is " +
                   one_line(v->dump(), true) + ")");
  (directional ? out.angle : out.radius) = float(v->get<double>());
}

// The nodes' references to the lights of extension `name` (KHR_lights_punctual: slot 0, EXT_lights_area:
// slot 1 of SourceFile::node_light), whose definitions are src.lights[first, end).
void read_node_lights(const std::string& path, const json& doc, const char* name, int slot, size_t first,
                      SourceFile& src) {
  const json* nodes = member(doc, "nodes");
  const size_t count = src.lights.size() - first;
  for (size_t n = 0; n < src.node_light.size(); ++n) {
    const json* next = member((*nodes)[n], "extensions");
    const json* use = next ? member(*next, name) : nullptr;
    if (!use) continue;
    const std::string where = "node " + std::to_string(n) + " " + name;
    const json* light = use->is_object() ? member(*use, "light") : nullptr;
    if (!light || !light->is_number_integer()) fail(path, where + " has no integer light index");
    const int64_t index = json_index(light);
    if (index < 0 || size_t(index) >= count)
      fail(path, where + " refers to light " + light->dump() + ", which does not exist (the file has " +
                     std::to_string(count) + ")");
    src.node_light[n][size_t(slot)] = int(first + size_t(index));
  }
}

// A light's name, and how messages name it ("EXT_lights_area light 2 'Key'").
std::string read_light_name(const char* extension, size_t i, const json& l, SceneLight& out) {
  const json* name = l.is_object() ? member(l, "name") : nullptr;
  if (name && name->is_string()) out.name = name->get<std::string>();
  return std::string(extension) + " light " + std::to_string(i) +
         (out.name.empty() ? std::string() : " '" + one_line(out.name, true) + "'");
}

// A light's colour: 3 finite, non-negative numbers (absent: white).
void read_light_color(const std::string& path, const std::string& where, const json& l, SceneLight& out) {
  const json* color = member(l, "color");
  if (!color) return;
  if (!color->is_array() || color->size() != 3) fail(path, where + " color is not an array of 3 numbers");
  for (size_t c = 0; c < 3; ++c) {
    const json& v = (*color)[c];
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      fail(path, where + " color has a non-finite or non-numeric value");
    if (v.get<double>() < 0.0) fail(path, where + " color has a negative value (" + v.dump() + ")");
    out.color[c] = float(v.get<double>());
  }
}

// A positive, finite number at most `limit` (absent: `fallback`).
double area_number(const std::string& path, const std::string& where, const json& parent, const char* key,
                   double fallback, double limit) {
  const json* v = member(parent, key);
  if (!v) return fallback;
  if (!v->is_number() || !(v->get<double>() > 0.0 && v->get<double>() <= limit))
    fail(path, where + " " + key + " must be a number above 0 and at most " + one_line(json(limit).dump()) + " (is " +
                   one_line(v->dump(), true) + ")");
  return v->get<double>();
}

// EXT_lights_area (DESIGN section 4d; a draft Khronos vendor extension): rect and disk lights, appended
// to src.lights, with their nodes in slot 1 of src.node_light. intensity is the surface's luminance in
// nits (default 1000), size the rect's height or the disk's diameter (default 1 m), rect.aspect its
// width over its height (default 1).
void read_area_lights(const std::string& path, const json& doc, SourceFile& src) {
  const json* ext = member(doc, "extensions");
  const json* area = ext ? member(*ext, "EXT_lights_area") : nullptr;
  const json* lights = area && area->is_object() ? member(*area, "lights") : nullptr;
  if (area && (!area->is_object() || (lights && !lights->is_array())))
    fail(path, "EXT_lights_area: lights is not an array");
  const size_t first = src.lights.size();
  for (size_t i = 0; lights && i < lights->size(); ++i) {
    const json& l = (*lights)[i];
    SceneLight out;
    out.light = int(i);
    const std::string where = read_light_name("EXT_lights_area", i, l, out);
    if (!l.is_object()) fail(path, where + " is not an object");
    const json* type = member(l, "type");
    const std::string t = type && type->is_string() ? type->get<std::string>() : std::string();
    if (t == "rect") out.type = SceneLightType::Rect;
    else if (t == "disk") out.type = SceneLightType::Disk;
    else
      fail(path,
           where + (type ? " has unknown type " +
                               (type->is_string() ? "'" + one_line(t, true) + "'" : std::string("(not a string)")) +
                               " (rect or disk expected)"
                         : std::string(" has no type")));
    read_light_color(path, where, l, out);
    const json* intensity = member(l, "intensity");
    if (intensity &&
        !(intensity->is_number() && intensity->get<double>() >= 0.0 && std::isfinite(intensity->get<double>())))
      fail(path, where + " intensity must be a finite number >= 0 (is " + one_line(intensity->dump(), true) + ")");
    out.intensity = float(intensity ? intensity->get<double>() : 1000.0);
    out.size = float(area_number(path, where, l, "size", 1.0, 1e6));
    const json* rect = out.type == SceneLightType::Rect ? member(l, "rect") : nullptr;
    if (rect && !rect->is_object()) fail(path, where + " rect is not an object");
    if (rect) out.aspect = float(area_number(path, where, *rect, "aspect", 1.0, 1e6));
    if (out.aspect < 1e-6f) fail(path, where + " rect.aspect must be at least 1e-6");
    src.lights.push_back(out);
  }
  read_node_lights(path, doc, "EXT_lights_area", 1, first, src);
}

// KHR_lights_punctual on the raw JSON: tinygltf reads an absent range as 0 and coerces odd values, so
// the checks that matter for lighting (DESIGN 4b) are made here, each a one-line error.
void read_lights(const std::string& path, const json& doc, SourceFile& src) {
  const json* nodes = member(doc, "nodes");
  const size_t node_count = nodes && nodes->is_array() ? nodes->size() : 0;
  src.node_light.assign(node_count, {-1, -1});
  const json* ext = member(doc, "extensions");
  const json* khr = ext ? member(*ext, "KHR_lights_punctual") : nullptr;
  const json* lights = khr ? member(*khr, "lights") : nullptr;
  if (khr && (!khr->is_object() || (lights && !lights->is_array())))
    fail(path, "KHR_lights_punctual: lights is not an array");
  const double pi = 3.14159265358979323846;
  if (lights) {
    for (size_t i = 0; i < lights->size(); ++i) {
      const json& l = (*lights)[i];
      SceneLight out;
      out.light = int(i);
      const std::string where = read_light_name("KHR_lights_punctual", i, l, out);
      if (!l.is_object()) fail(path, where + " is not an object");
      auto number = [&](const json& parent, const char* key, double fallback) {
        const json* v = member(parent, key);
        if (!v) return fallback;
        if (!v->is_number()) fail(path, where + " " + key + " is not a number");
        const double d = v->get<double>();
        if (!std::isfinite(d)) fail(path, where + " " + key + " is not finite");
        return d;
      };
      const json* type = member(l, "type");
      const std::string t = type && type->is_string() ? type->get<std::string>() : std::string();
      if (t == "directional") out.type = SceneLightType::Directional;
      else if (t == "point") out.type = SceneLightType::Point;
      else if (t == "spot") out.type = SceneLightType::Spot;
      else if (!type) fail(path, where + " has no type");
      else
        fail(path, where + " has unknown type " +
                       (type->is_string() ? "'" + one_line(t, true) + "'" : std::string("(not a string)")) +
                       " (directional, point or spot expected)");
      read_light_color(path, where, l, out);
      const double intensity = number(l, "intensity", 1.0);
      if (intensity < 0.0) fail(path, where + " has a negative intensity (" + member(l, "intensity")->dump() + ")");
      out.intensity = float(intensity);
      if (member(l, "range")) {
        const double range = number(l, "range", 0.0);
        if (!(range > 0.0)) fail(path, where + " range must be positive (is " + member(l, "range")->dump() + ")");
        out.range = float(range);
      }
      if (out.type == SceneLightType::Spot) {
        const json* spot = member(l, "spot");
        if (spot && !spot->is_object()) fail(path, where + " spot is not an object");
        const json empty = json::object();
        const double inner = number(spot ? *spot : empty, "innerConeAngle", 0.0);
        const double outer = number(spot ? *spot : empty, "outerConeAngle", pi / 4.0);
        if (!(inner >= 0.0 && inner < outer && outer <= pi / 2.0))
          fail(path, where + " spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2 (inner " +
                         std::to_string(inner) + ", outer " + std::to_string(outer) + ")");
        out.inner_cone = float(inner), out.outer_cone = float(outer);
      }
      read_light_size(path, where, l, out);
      src.lights.push_back(out);
    }
  }
  read_node_lights(path, doc, "KHR_lights_punctual", 0, 0, src);
  read_area_lights(path, doc, src);
}

// Reads an external file the scene names into src.external (once, however many buffers and images
// name it): the URI's file, opened beneath `folder` (nullptr = anywhere) and kept under the path
// tinygltf asks for (resolve_uri); a regular file, within the file-bytes budget and, for a buffer,
// exactly `byte_length` bytes (-1: any). `what` names it in messages ("buffer 0: file 'a.bin'").
// Returns false when the file does not exist and `missing_ok`.
bool read_external(const std::string& path, SourceFile& src, const std::string& uri, const std::string& what,
                   const InputFolder* folder, const InputLimits& limits, int64_t byte_length, bool missing_ok) {
  const std::string relative = decode_uri(uri), file = resolve_uri(src.base_dir, uri);
  // a %00 would cut the name where the C library reads it: another file than the URI says
  if (file.find('\0') != std::string::npos) fail(path, what + " names a file with a NUL byte (%00)");
  if (auto known = src.external.find(file); known != src.external.end()) {
    ++known->second.uses;
    if (byte_length >= 0 && uint64_t(byte_length) != known->second.bytes.size())
      fail(path, what + " has " + std::to_string(known->second.bytes.size()) + " bytes but byteLength is " +
                     std::to_string(byte_length));
    return true;
  }
  // What was opened is what is read: no path is resolved twice.
  OpenInput in =
      folder ? open_input(relative, folder, limits.file_bytes) : open_input(file, nullptr, limits.file_bytes);
  if (in.status == InputFile::Status::NotFound) {
    if (missing_ok) return false;
    fail(path, what + " not found (looked for " + one_line(file) + ")");
  }
  if (in.status == InputFile::Status::Outside) {
    const std::string real = real_folder(file);  // for the message only
    fail(path, what + " " + in.reason + (real.empty() ? "" : " (it resolves to " + one_line(real) + ")") +
                   "; --allow-outside-scene-folder reads it");
  }
  if (in.status != InputFile::Status::Ok) fail(path, what + " " + in.reason);
  if (byte_length >= 0 && in.size != uint64_t(byte_length))
    fail(path, what + " has " + std::to_string(in.size) + " bytes but byteLength is " + std::to_string(byte_length));
  // the files read so far and this one, each held twice while the parser copies it into its model
  uint64_t held = in.size;
  for (const auto& [name, read] : src.external) held += read.bytes.size();
  check_memory(2 * held, "reading the scene's files (" + what + ": " + std::to_string(in.size) + " bytes)");
  SourceFile::External e;
  if (!in.read(e.bytes)) fail(path, what + " " + in.reason);
  e.uses = 1;
  src.external[file] = std::move(e);
  return true;
}

// Buffers are checked here so that a missing or short .bin gets a message naming the file (tinygltf
// would say "File not found", or fail later with an unrelated error), and read here (read_external).
void check_buffers(const std::string& path, const json& doc, SourceFile& src, int64_t bin_length,
                   const InputFolder* folder, const InputLimits& limits) {
  const json* buffers = member(doc, "buffers");
  if (!buffers || !buffers->is_array()) return;
  for (size_t i = 0; i < buffers->size(); ++i) {
    const json& b = (*buffers)[i];
    const std::string name = "buffer " + std::to_string(i);
    const json* len = member(b, "byteLength");
    if (!len || !len->is_number_unsigned()) fail(path, name + " has no valid byteLength");
    const uint64_t byte_length = len->get<uint64_t>();
    const json* uri = member(b, "uri");
    if (uri && !uri->is_string()) fail(path, name + ": uri is not a string");
    const std::string u = uri ? uri->get<std::string>() : std::string();
    if (u.empty()) {
      if (!src.glb) fail(path, name + " has no uri (only a .glb can store a buffer inside the file)");
      if (bin_length < 0) fail(path, name + " refers to the GLB BIN chunk, but the file has none");
      if (byte_length > uint64_t(bin_length))
        fail(path, name + " declares " + std::to_string(byte_length) + " bytes but the GLB BIN chunk has " +
                       std::to_string(bin_length));
      continue;
    }
    if (u.rfind("data:", 0) == 0) {
      if (!tinygltf::IsDataURI(u))
        fail(path, name +
                       " uses an unsupported data URI (base64 application/octet-stream or "
                       "application/gltf-buffer expected)");
      continue;  // tinygltf decodes it and checks the decoded size against byteLength
    }
    if (byte_length > uint64_t(INT64_MAX)) fail(path, name + " has an impossible byteLength");
    if (!src.needed_buffers.count(int(i))) {  // no accessor the loader reads uses it: never opened
      src.unread_buffers[int(i)] = byte_length;
      continue;
    }
    read_external(path, src, u, name + ": file '" + one_line(u) + "'", folder, limits, int64_t(byte_length), false);
  }
}

// The files of the images some material samples (sampled_images), read like buffers; a missing one
// is a warning later (the material is drawn untextured), any other refusal an error.
void read_sampled_images(const std::string& path, const json& doc, SourceFile& src, const InputFolder* folder,
                         const InputLimits& limits) {
  const json* images = member(doc, "images");
  if (!images || !images->is_array()) return;
  for (int i : src.sampled_images) {
    if (i < 0 || size_t(i) >= images->size()) continue;
    const json* uri = member((*images)[size_t(i)], "uri");
    if (!uri || !uri->is_string()) continue;
    const std::string u = uri->get<std::string>();
    if (u.empty() || u.rfind("data:", 0) == 0) continue;  // tinygltf decodes data URIs
    read_external(path, src, u, "image " + std::to_string(i) + ": file '" + one_line(u) + "'", folder, limits, -1,
                  true);
  }
}

// Only images some implemented material slot samples are decoded (and read): the core slots and those
// of the material extensions pmr draws (texture_slot_extension). Images of unimplemented extensions
// (sheen, ...) never are.
std::set<int> sampled_images(const json& doc) {
  std::set<int> images;
  const json* materials = member(doc, "materials");
  const json* textures = member(doc, "textures");
  if (!materials || !materials->is_array() || !textures || !textures->is_array()) return images;
  for (const json& m : *materials) {
    const json* pbr = member(m, "pbrMetallicRoughness");
    const json* ext = member(m, "extensions");
    std::vector<const json*> infos = {
        pbr ? member(*pbr, "baseColorTexture") : nullptr, pbr ? member(*pbr, "metallicRoughnessTexture") : nullptr,
        member(m, "normalTexture"), member(m, "occlusionTexture"), member(m, "emissiveTexture")};
    for (int slot = kSlotEmissive + 1; slot < kTextureSlots; ++slot) {
      const json* holder = ext ? member(*ext, texture_slot_extension(slot)) : nullptr;
      infos.push_back(holder ? member(*holder, texture_slot_name(slot)) : nullptr);
    }
    for (const json* info : infos) {
      const int64_t t = json_index(info ? member(*info, "index") : nullptr);
      if (t < 0 || size_t(t) >= textures->size()) continue;
      const int64_t image = json_index(member((*textures)[size_t(t)], "source"));
      if (image >= 0) images.insert(int(image));
    }
  }
  return images;
}

// The buffers the loader can read from: those of the bufferViews of every accessor a mesh primitive
// (attributes, indices, morph targets), an animation sampler or a skin names, of their sparse parts,
// and of the sampled images stored in bufferViews. Any other buffer is never read, however large.
std::set<int> needed_buffers(const json& doc, const std::set<int>& sampled) {
  const json* accessors = member(doc, "accessors");
  const json* views = member(doc, "bufferViews");
  std::set<int64_t> used_accessors, used_views;
  auto use = [&](const json* index) {
    if (const int64_t a = json_index(index); a >= 0) used_accessors.insert(a);
  };
  auto use_all = [&](const json* object) {
    if (object && object->is_object())
      for (const auto& [key, value] : object->items()) use(&value);
  };
  if (const json* meshes = member(doc, "meshes"); meshes && meshes->is_array())
    for (const json& mesh : *meshes)
      if (const json* prims = member(mesh, "primitives"); prims && prims->is_array())
        for (const json& p : *prims) {
          use_all(member(p, "attributes"));
          use(member(p, "indices"));
          if (const json* targets = member(p, "targets"); targets && targets->is_array())
            for (const json& t : *targets) use_all(&t);
        }
  if (const json* animations = member(doc, "animations"); animations && animations->is_array())
    for (const json& a : *animations)
      if (const json* samplers = member(a, "samplers"); samplers && samplers->is_array())
        for (const json& smp : *samplers) use(member(smp, "input")), use(member(smp, "output"));
  if (const json* skins = member(doc, "skins"); skins && skins->is_array())
    for (const json& skin : *skins) use(member(skin, "inverseBindMatrices"));
  if (accessors && accessors->is_array())
    for (int64_t a : used_accessors) {
      if (size_t(a) >= accessors->size()) continue;
      const json& acc = (*accessors)[size_t(a)];
      if (const int64_t v = json_index(member(acc, "bufferView")); v >= 0) used_views.insert(v);
      if (const json* sparse = member(acc, "sparse"))
        for (const char* part : {"indices", "values"})
          if (const json* p = member(*sparse, part))
            if (const int64_t v = json_index(member(*p, "bufferView")); v >= 0) used_views.insert(v);
    }
  if (const json* images = member(doc, "images"); images && images->is_array())
    for (int i : sampled)
      if (i >= 0 && size_t(i) < images->size())
        if (const int64_t v = json_index(member((*images)[size_t(i)], "bufferView")); v >= 0) used_views.insert(v);
  std::set<int> buffers;
  if (views && views->is_array())
    for (int64_t v : used_views)
      if (size_t(v) < views->size())
        if (const int64_t b = json_index(member((*views)[size_t(v)], "buffer")); b >= 0) buffers.insert(int(b));
  return buffers;
}

// tinygltf loads every buffer it is given. An unread one is handed over as one byte in a data URI
// (validate_model checks its bufferViews against the length the file declares instead): the JSON
// text, or the GLB's JSON chunk, is rewritten for it.
void replace_unread_buffers(json& doc, const SourceFile& src) {
  for (const auto& [index, length] : src.unread_buffers)
    doc["buffers"][size_t(index)] = {{"byteLength", 1}, {"uri", "data:application/octet-stream;base64,AA=="}};
}

// What tinygltf parses becomes `doc` (the GLB's BIN chunk kept as it was).
void replace_json(const json& doc, SourceFile& src) {
  std::string text = doc.dump();
  if (!src.glb) {
    src.bytes.assign(text.begin(), text.end());
    return;
  }
  while (text.size() % 4) text += ' ';  // chunks are 4-byte aligned, JSON padded with spaces
  const uint64_t old_json = read_u32le(&src.bytes[12]);
  const size_t rest = size_t(20 + old_json);  // the BIN chunk (and anything after it), as it was
  std::vector<unsigned char> out(src.bytes.begin(), src.bytes.begin() + 12);
  auto put32 = [&](uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k)));
  };
  put32(uint32_t(text.size()));
  put32(0x4E4F534Au);
  out.insert(out.end(), text.begin(), text.end());
  out.insert(out.end(), src.bytes.begin() + long(rest), src.bytes.end());
  const uint32_t total = uint32_t(out.size());
  for (int k = 0; k < 4; ++k) out[size_t(8 + k)] = uint8_t(total >> (8 * k));
  src.bytes = std::move(out);
}

bool is_data_uri(const std::string& uri) { return uri.rfind("data:", 0) == 0; }

// Files named only by images that are never decoded (tinygltf would read them; load_model skips them).
std::set<std::string> unused_image_files(const json& doc, const std::string& base_dir, const std::set<int>& used) {
  std::set<std::string> unused, needed;
  auto uri_of = [](const json& o) -> std::string {
    const json* u = member(o, "uri");
    return u && u->is_string() ? u->get<std::string>() : std::string();
  };
  if (const json* images = member(doc, "images"); images && images->is_array())
    for (size_t i = 0; i < images->size(); ++i) {
      const std::string u = uri_of((*images)[i]);
      if (u.empty() || is_data_uri(u)) continue;
      (used.count(int(i)) ? needed : unused).insert(resolve_uri(base_dir, u));
    }
  if (const json* buffers = member(doc, "buffers"); buffers && buffers->is_array())
    for (const json& b : *buffers)
      if (const std::string u = uri_of(b); !u.empty() && !is_data_uri(u)) needed.insert(resolve_uri(base_dir, u));
  for (const std::string& f : needed) unused.erase(f);
  return unused;
}

std::string base_dir_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

const char* material_extension_fallback(const std::string& name) {
  static const std::pair<const char*, const char*> table[] = {
      {"KHR_materials_dispersion", "drawn without dispersion (one ior for every wavelength)"},
      {"KHR_materials_diffuse_transmission", "drawn without diffuse transmission (opaque where not glass)"},
      {"KHR_materials_pbrSpecularGlossiness",
       "drawn from their metallic-roughness properties (the defaults where absent), not specular-glossiness"},
  };
  for (const auto& [ext, fallback] : table)
    if (name == ext) return fallback;
  return nullptr;
}

const json* member(const json& object, const char* key) {
  if (!object.is_object()) return nullptr;
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

std::string decode_uri(const std::string& uri) {
  // Same decoding as tinygltf's dlib::urldecode ('+' is a space, %XX a byte), so that the file checked
  // here is the file tinygltf then opens.
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
  };
  std::string decoded;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      decoded += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      decoded += char(hex(uri[i + 1]) << 4 | hex(uri[i + 2]));
      i += 2;
    } else {
      decoded += uri[i];
    }
  }
  return decoded;
}

std::string resolve_uri(const std::string& base_dir, const std::string& uri) {
  const std::string decoded = decode_uri(uri);
  if (base_dir.empty()) return decoded;
  return base_dir.back() == '/' ? base_dir + decoded : base_dir + "/" + decoded;
}

SourceFile read_source(const std::string& path, const InputLimits& limits, const std::string& variant) {
  SourceFile src;
  src.bytes = read_whole_file(path, limits);
  src.checksum = checksum_hex(src.bytes.data(), src.bytes.size());
  src.base_dir = base_dir_of(path);
  src.glb = src.bytes.size() >= 4 && std::memcmp(src.bytes.data(), "glTF", 4) == 0;
  int64_t bin_length = -1;
  const std::string text =
      src.glb ? glb_json(path, src.bytes, bin_length) : std::string(src.bytes.begin(), src.bytes.end());
  if (text.size() > limits.json_bytes)
    fail(path, "the JSON " + std::string(src.glb ? "chunk" : "text") + " has " + std::to_string(text.size()) +
                   " bytes, more than the json-bytes limit of " + std::to_string(limits.json_bytes) +
                   " (raise it with --limit json-bytes=N)");
  uint64_t values = 0;
  const int depth = json_depth(text, &values);
  // Parsed, the JSON is held twice (here and by tinygltf, whose values for extras are larger still):
  // about 200 bytes a value where the text has two, as measured on a 40 MB array of numbers.
  check_memory(values * kJsonBytesPerValue + 2 * uint64_t(text.size()),
               "parsing the scene's JSON (" + std::to_string(values) + " values)");
  if (depth > kMaxJsonDepth)
    fail(path, "invalid JSON: nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    // Drop nlohmann's "[json.exception.parse_error.101] " prefix: the user needs the position.
    std::string what = e.what();
    const size_t close = what.find("] ");
    if (what.rfind("[json.exception", 0) == 0 && close != std::string::npos) what = what.substr(close + 2);
    fail(path, "invalid JSON: " + one_line(what, /*ascii_only=*/true));
  }
  if (!doc.is_object()) fail(path, "not a glTF file: the JSON top level is not an object");
  const json* asset = member(doc, "asset");
  const json* version = asset ? member(*asset, "version") : nullptr;
  if (!version || !version->is_string()) fail(path, "not a glTF file: asset.version is missing");
  const std::string v = version->get<std::string>();
  if (v.rfind("2.", 0) != 0) fail(path, "glTF version " + one_line(v) + " is not supported (2.x only)");
  check_schema(path, doc);
  check_extensions(path, doc, src);
  bool rewrite = apply_material_variant(path, doc, variant, src);
  InputFolder folder;  // the scene's folder, unless files may lie anywhere
  if (!limits.allow_outside_scene_folder) {
    folder = InputFolder(src.base_dir.empty() ? "." : src.base_dir);
    if (!folder.ok()) fail(path, "cannot open the scene's folder " + one_line(src.base_dir));
  }
  const InputFolder* confine = folder.ok() ? &folder : nullptr;
  src.sampled_images = sampled_images(doc);
  src.needed_buffers = needed_buffers(doc, src.sampled_images);
  check_buffers(path, doc, src, bin_length, confine, limits);
  read_lights(path, doc, src);
  src.unused_image_files = unused_image_files(doc, src.base_dir, src.sampled_images);
  read_sampled_images(path, doc, src, confine, limits);
  if (!src.unread_buffers.empty()) replace_unread_buffers(doc, src), rewrite = true;
  if (rewrite) replace_json(doc, src);
  return src;
}

// ---- after tinygltf ----------------------------------------------------------------------------------

namespace {

template <class T>
bool in_range(int index, const std::vector<T>& v) {
  return index >= 0 && size_t(index) < v.size();
}

std::string ref_error(const std::string& owner, const char* kind, int index, size_t count) {
  return owner + " refers to " + kind + " " + std::to_string(index) + ", which does not exist (the file has " +
         std::to_string(count) + ")";
}

void check_buffer_views(const tinygltf::Model& m, const std::map<int, uint64_t>& unread, const std::string& file) {
  for (size_t i = 0; i < m.bufferViews.size(); ++i) {
    const tinygltf::BufferView& bv = m.bufferViews[i];
    const std::string name = "bufferView " + std::to_string(i);
    if (!in_range(bv.buffer, m.buffers)) fail(file, ref_error(name, "buffer", bv.buffer, m.buffers.size()));
    const auto declared = unread.find(bv.buffer);
    const uint64_t size = declared != unread.end() ? declared->second : m.buffers[size_t(bv.buffer)].data.size();
    uint64_t end = 0;
    if (__builtin_add_overflow(uint64_t(bv.byteOffset), uint64_t(bv.byteLength), &end) || end > size)
      fail(file, name + " (byteOffset " + std::to_string(bv.byteOffset) + ", byteLength " +
                     std::to_string(bv.byteLength) + ") overruns buffer " + std::to_string(bv.buffer) + ", which has " +
                     std::to_string(size) + " bytes");
  }
}

void check_meshes(const tinygltf::Model& m, const std::string& file) {
  for (size_t i = 0; i < m.meshes.size(); ++i) {
    for (size_t p = 0; p < m.meshes[i].primitives.size(); ++p) {
      const tinygltf::Primitive& prim = m.meshes[i].primitives[p];
      const std::string name = "mesh " + std::to_string(i) + " primitive " + std::to_string(p);
      if (prim.mode < -1 || prim.mode > 6)
        fail(file, name + " has mode " + std::to_string(prim.mode) + ", which is not a glTF primitive mode");
      if (prim.indices != -1 && !in_range(prim.indices, m.accessors))
        fail(file, ref_error(name + " indices", "accessor", prim.indices, m.accessors.size()));
      for (const auto& [semantic, accessor] : prim.attributes)
        if (!in_range(accessor, m.accessors))
          fail(file, ref_error(name + " attribute " + semantic, "accessor", accessor, m.accessors.size()));
      if (prim.material != -1 && !in_range(prim.material, m.materials))
        fail(file, ref_error(name, "material", prim.material, m.materials.size()));
    }
  }
}

void check_materials(const tinygltf::Model& m, const std::string& file) {
  for (size_t i = 0; i < m.materials.size(); ++i) {
    const tinygltf::Material& mat = m.materials[i];
    const std::pair<int, int> infos[] = {
        {mat.pbrMetallicRoughness.baseColorTexture.index, mat.pbrMetallicRoughness.baseColorTexture.texCoord},
        {mat.pbrMetallicRoughness.metallicRoughnessTexture.index,
         mat.pbrMetallicRoughness.metallicRoughnessTexture.texCoord},
        {mat.normalTexture.index, mat.normalTexture.texCoord},
        {mat.occlusionTexture.index, mat.occlusionTexture.texCoord},
        {mat.emissiveTexture.index, mat.emissiveTexture.texCoord}};
    for (int slot = 0; slot < int(std::size(infos)); ++slot) {  // the core slots (extensions': the loader)
      const std::string name = "material " + std::to_string(i) + " " + texture_slot_name(slot);
      const auto [index, texcoord] = infos[slot];
      if (index != -1 && !in_range(index, m.textures)) fail(file, ref_error(name, "texture", index, m.textures.size()));
      if (texcoord < 0) fail(file, name + " has a negative texCoord");
    }
  }
  for (size_t i = 0; i < m.textures.size(); ++i) {
    const tinygltf::Texture& t = m.textures[i];
    const std::string name = "texture " + std::to_string(i);
    if (t.source != -1 && !in_range(t.source, m.images))
      fail(file, ref_error(name, "image", t.source, m.images.size()));
    if (t.sampler != -1 && !in_range(t.sampler, m.samplers))
      fail(file, ref_error(name, "sampler", t.sampler, m.samplers.size()));
  }
}

// Iterative DFS with an on-stack mark: node chains can be as long as the file is big, so recursion
// could overflow the stack.
void check_cycles(const tinygltf::Model& m, const std::string& file) {
  enum : uint8_t { kNew, kOnStack, kDone };
  std::vector<uint8_t> state(m.nodes.size(), kNew);
  std::vector<std::pair<int, size_t>> stack;  // node, next child to visit
  for (size_t start = 0; start < m.nodes.size(); ++start) {
    if (state[start] != kNew) continue;
    stack.push_back({int(start), 0});
    state[start] = kOnStack;
    while (!stack.empty()) {
      auto& [node, next] = stack.back();
      const std::vector<int>& children = m.nodes[size_t(node)].children;
      if (next == children.size()) {
        state[size_t(node)] = kDone;
        stack.pop_back();
        continue;
      }
      const int child = children[next++];
      if (state[size_t(child)] == kOnStack) fail(file, "node cycle through node " + std::to_string(child));
      if (state[size_t(child)] == kNew) {
        state[size_t(child)] = kOnStack;
        stack.push_back({child, 0});
      }
    }
  }
}

std::vector<int> check_nodes(const tinygltf::Model& m, const std::string& file) {
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    const tinygltf::Node& n = m.nodes[i];
    const std::string name = "node " + std::to_string(i);
    for (int child : n.children)
      if (!in_range(child, m.nodes)) fail(file, ref_error(name + " children", "node", child, m.nodes.size()));
    if (n.mesh != -1 && !in_range(n.mesh, m.meshes)) fail(file, ref_error(name, "mesh", n.mesh, m.meshes.size()));
    if (n.camera != -1 && !in_range(n.camera, m.cameras))
      fail(file, ref_error(name, "camera", n.camera, m.cameras.size()));
  }
  check_cycles(m, file);
  // A node shared by two parents would be instanced once per path; the spec forbids it, and chains of
  // such nodes would multiply the instance count exponentially.
  std::vector<int> parent(m.nodes.size(), -1);
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    for (int child : m.nodes[i].children) {
      if (parent[size_t(child)] != -1)
        fail(file, "node " + std::to_string(child) + " has two parents (nodes " +
                       std::to_string(parent[size_t(child)]) + " and " + std::to_string(i) + ")");
      parent[size_t(child)] = int(i);
    }
  }
  return parent;
}

// The samplers' data (their structure was checked on the JSON, gltf_schema.cpp): key times finite and
// strictly increasing, as the specification requires; outputs readable within their buffers.
void check_animation_data(const tinygltf::Model& m, const std::string& file) {
  for (size_t a = 0; a < m.animations.size(); ++a)
    for (size_t s = 0; s < m.animations[a].samplers.size(); ++s) {
      const tinygltf::AnimationSampler& smp = m.animations[a].samplers[s];
      const std::string where = "animation " + std::to_string(a) + " sampler " + std::to_string(s);
      const AttributeData t = read_attribute(m, smp.input, Semantic::KeyTimes, "input of " + where, file);
      for (size_t k = 0; k < t.values.size(); ++k) {
        if (!std::isfinite(t.values[k]))
          fail(file, where + " key time " + std::to_string(k) + " is not a finite number");
        if (k > 0 && !(t.values[k] > t.values[k - 1]))
          fail(file, where + " key times are not strictly increasing (key " + std::to_string(k) + ": " +
                         std::to_string(t.values[k]) + " after " + std::to_string(t.values[k - 1]) + ")");
      }
      check_accessor(m, smp.output, Semantic::AnimationOutput, "output of " + where, file);
    }
}

}  // namespace

std::vector<int> validate_model(const tinygltf::Model& model, const std::map<int, uint64_t>& unread_buffers,
                                const std::string& file) {
  check_buffer_views(model, unread_buffers, file);
  check_meshes(model, file);
  check_materials(model, file);
  check_animation_data(model, file);
  return check_nodes(model, file);
}

std::vector<int> scene_roots(const tinygltf::Model& m, const std::vector<int>& parent, const std::string& file) {
  std::vector<int> roots;
  if (m.scenes.empty()) {
    if (m.defaultScene > 0)
      fail(file, "scene " + std::to_string(m.defaultScene) + " is the default but there are no scenes");
    for (size_t i = 0; i < m.nodes.size(); ++i)
      if (parent[i] == -1) roots.push_back(int(i));
    return roots;
  }
  const int s = m.defaultScene < 0 ? 0 : m.defaultScene;
  if (!in_range(s, m.scenes)) fail(file, ref_error("the default scene", "scene", s, m.scenes.size()));
  std::vector<bool> listed(m.nodes.size(), false);
  for (int n : m.scenes[size_t(s)].nodes) {
    const std::string name = "scene " + std::to_string(s);
    if (!in_range(n, m.nodes)) fail(file, ref_error(name, "node", n, m.nodes.size()));
    if (parent[size_t(n)] != -1)
      fail(file, name + " lists node " + std::to_string(n) + " as a root, but it is a child of node " +
                     std::to_string(parent[size_t(n)]));
    if (listed[size_t(n)]) fail(file, name + " lists node " + std::to_string(n) + " twice");
    listed[size_t(n)] = true;
    roots.push_back(n);
  }
  return roots;
}

MotionNode node_transform(const tinygltf::Node& n, int index, const std::string& file) {
  const std::string name = "node " + std::to_string(index);
  auto finite = [](const std::vector<double>& v) {
    for (double x : v)
      if (!std::isfinite(x)) return false;
    return true;
  };
  MotionNode out;
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16)
      fail(file, name + " has a matrix of " + std::to_string(n.matrix.size()) + " values (16 expected)");
    if (!finite(n.matrix)) fail(file, name + " has a non-finite matrix");
    out.has_matrix = true;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) out.matrix[c][r] = n.matrix[size_t(c * 4 + r)];  // glTF is column-major, like glm
    return out;
  }
  auto check = [&](const std::vector<double>& v, size_t size, const char* what) {
    if (!v.empty() && v.size() != size)
      fail(file, name + " has a " + what + " of " + std::to_string(v.size()) + " values (" + std::to_string(size) +
                     " expected)");
    if (!finite(v)) fail(file, name + " has a non-finite " + what);
  };
  check(n.translation, 3, "translation");
  check(n.rotation, 4, "rotation");
  check(n.scale, 3, "scale");
  if (!n.translation.empty()) out.translation = glm::dvec3(n.translation[0], n.translation[1], n.translation[2]);
  if (!n.scale.empty()) out.scale = glm::dvec3(n.scale[0], n.scale[1], n.scale[2]);
  if (!n.rotation.empty()) {
    const glm::dvec4 q(n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]);
    // The spec wants unit quaternions; exporters write them rounded to a few digits, so normalize.
    const double len = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (!(len > 0.0) || !std::isfinite(len)) fail(file, name + " has a zero-length rotation quaternion");
    out.rotation = q / len;
  }
  return out;
}

}  // namespace pmr::gltf
