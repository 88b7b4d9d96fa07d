// The materials of a glTF file (DESIGN 4b, 4c): each material's factors, its texture slots with their
// TEXCOORD sets and KHR_texture_transform, and the material extensions pmr reads.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>

#include "pmr/error.h"
#include "pmr/printable.h"
#include "scene/gltf_loader_state.h"

namespace pmr::gltf {
namespace {

// ---- materials and textures ---------------------------------------------------------------------------

// A textureInfo's TEXCOORD set and KHR_texture_transform, uv' = T * R * S * uv, kept as the extension's
// values: the kernels apply it to the stored set (the matrix: texture_transform_matrix,
// host/pipeline/material_tables.cpp). The extension's GLSL reads as
// u' = cos*sx*u + sin*sy*v + ox, v' = -sin*sx*u + cos*sy*v + oy: this is what the Khronos sample viewer
// does and what the extension's own example needs (offset (0,1), rotation pi/2, scale 0.5 selects the
// lower-left quadrant of the image).
struct MaterialUv {
  int set = 0;                                                // TEXCOORD_n of the texture
  bool transform = false;                                     // the extension is present and valid
  float offset[2] = {0, 0}, rotation = 0, scale[2] = {1, 1};  // the extension's values (when present)
};

bool finite_numbers(const tinygltf::Value& v, size_t n, double* out) {
  if (!v.IsArray() || v.ArrayLen() != n) return false;
  for (size_t i = 0; i < n; ++i) {
    const tinygltf::Value& e = v.Get(int(i));
    if (!e.IsNumber() || !std::isfinite(e.GetNumberAsDouble())) return false;
    out[i] = e.GetNumberAsDouble();
  }
  return true;
}

// `slot_name` is "" for the base colour texture (its messages predate the other slots).
MaterialUv material_uv(Loader& L, int texcoord, const tinygltf::ExtensionMap& extensions, int material,
                       const std::string& slot_name = "") {
  MaterialUv uv;
  uv.set = texcoord;
  auto ext = extensions.find("KHR_texture_transform");
  if (ext == extensions.end()) return uv;
  const tinygltf::Value& t = ext->second;
  const std::string name =
      "material " + std::to_string(material) + (slot_name.empty() ? "" : " " + slot_name) + " KHR_texture_transform";
  if (!t.IsObject()) {
    L.warn(name + " is not an object; ignored");
    return uv;
  }
  double offset[2] = {0, 0}, scale[2] = {1, 1}, rotation = 0;
  bool ok = (!t.Has("offset") || finite_numbers(t.Get("offset"), 2, offset)) &&
            (!t.Has("scale") || finite_numbers(t.Get("scale"), 2, scale));
  if (t.Has("rotation")) {
    const tinygltf::Value& r = t.Get("rotation");
    ok = ok && r.IsNumber() && std::isfinite(r.GetNumberAsDouble());
    if (ok) rotation = r.GetNumberAsDouble();
  }
  if (!ok) {
    L.warn(name + " has an invalid offset, rotation or scale; ignored");
    return uv;
  }
  if (t.Has("texCoord")) {
    const tinygltf::Value& tc = t.Get("texCoord");
    if (tc.IsInt() && tc.GetNumberAsInt() >= 0) uv.set = tc.GetNumberAsInt();
    else L.warn(name + " has an invalid texCoord; ignored");
  }
  uv.transform = true;
  uv.offset[0] = float(offset[0]), uv.offset[1] = float(offset[1]);
  uv.rotation = float(rotation);
  uv.scale[0] = float(scale[0]), uv.scale[1] = float(scale[1]);
  return uv;
}

// Any tinygltf image (1..4 channels, 8 or 16 bits) to RGBA8, rows top first as decoded.
bool to_rgba8(const tinygltf::Image& img, SceneTexture& out, std::string& why) {
  const int bytes = img.bits == 16 ? 2 : img.bits == 8 ? 1 : 0;
  if (img.width <= 0 || img.height <= 0 || img.component < 1 || img.component > 4 || bytes == 0) {
    why = "unsupported image layout (" + std::to_string(img.component) + " channels, " + std::to_string(img.bits) +
          " bits)";
    return false;
  }
  const uint64_t pixels = uint64_t(img.width) * uint64_t(img.height);
  if (img.image.size() != pixels * uint64_t(img.component) * uint64_t(bytes)) {
    why = "image data size does not match its dimensions";
    return false;
  }
  out.width = img.width;
  out.height = img.height;
  out.rgba.resize(size_t(pixels) * 4);
  const unsigned char* src = img.image.data();
  auto channel = [&](size_t i) -> uint8_t {
    if (bytes == 1) return src[i];
    uint16_t v;
    std::memcpy(&v, src + 2 * i, 2);  // stb_image gives native-endian 16-bit samples
    return uint8_t((uint32_t(v) * 255u + 32767u) / 65535u);
  };
  const size_t n = size_t(img.component);
  for (size_t p = 0; p < size_t(pixels); ++p) {
    uint8_t* dst = &out.rgba[4 * p];
    const size_t i = p * n;
    if (n <= 2) {  // grey, grey + alpha
      dst[0] = dst[1] = dst[2] = channel(i);
      dst[3] = n == 2 ? channel(i + 1) : 255;
    } else {
      dst[0] = channel(i), dst[1] = channel(i + 1), dst[2] = channel(i + 2);
      dst[3] = n == 4 ? channel(i + 3) : 255;
    }
  }
  return true;
}

int wrap_mode(Loader& L, int mode, int sampler) {
  if (mode == PMR_WRAP_REPEAT || mode == PMR_WRAP_CLAMP || mode == PMR_WRAP_MIRROR) return mode;
  L.warn("sampler " + std::to_string(sampler) + " has wrap mode " + std::to_string(mode) + "; using REPEAT");
  return PMR_WRAP_REPEAT;
}

// tinygltf decodes data URIs of PNG and JPEG only and treats any other as a file name: say what the
// data URI holds instead ("image/ktx2", "image/webp").
std::string data_uri_problem(const std::string& uri) {
  const size_t end = uri.find_first_of(";,");
  const std::string type = uri.substr(5, end == std::string::npos ? 0 : end - 5);
  if (type == "image/png" || type == "image/jpeg") return "its data URI cannot be decoded (base64 expected)";
  return "its data URI holds " + (type.empty() ? std::string("no media type") : "type " + printable_text(type, 40)) +
         ", which is not supported (PNG and JPEG only)";
}

// The Scene::textures index of a glTF texture, decoding its image on first use; -1 when unusable (with
// a warning). One image sampled with the same wrap modes is stored once, whichever textures and slots
// name it.
int scene_texture(Loader& L, int texture, int slot) {
  auto cached = L.scene_texture_of.find(texture);
  if (cached != L.scene_texture_of.end()) {
    if (cached->second >= 0) L.scene.textures[size_t(cached->second)].slots |= 1u << slot;
    return cached->second;
  }
  int& result = L.scene_texture_of[texture] = -1;
  const tinygltf::Texture& t = L.model.textures[size_t(texture)];
  const std::string name = "texture " + std::to_string(texture);
  if (t.source < 0) {
    L.warn(name + " has no PNG/JPEG image (other formats are not supported); drawn untextured");
    return result;
  }
  const tinygltf::Image& img = L.model.images[size_t(t.source)];
  const std::string image_name =
      "image " + std::to_string(t.source) +
      (img.uri.empty() ? (img.name.empty() ? "" : " '" + img.name + "'") : " '" + img.uri + "'");
  SceneTexture st;
  std::string why;
  if (img.image.empty()) {
    auto f = L.images.failures.find(t.source);
    why = f != L.images.failures.end()     ? f->second
          : img.uri.empty()                ? std::string("no image data")
          : img.uri.rfind("data:", 0) == 0 ? data_uri_problem(img.uri)
                                           : "file not found";
  } else {
    to_rgba8(img, st, why);
  }
  if (!why.empty()) {
    L.warn(name + " (" + image_name + "): " + why + "; drawn untextured");
    return result;
  }
  if (t.sampler >= 0) {
    const tinygltf::Sampler& s = L.model.samplers[size_t(t.sampler)];
    st.wrap_s = wrap_mode(L, s.wrapS, t.sampler);
    st.wrap_t = wrap_mode(L, s.wrapT, t.sampler);
  }
  const std::array<int, 3> key = {t.source, st.wrap_s, st.wrap_t};
  auto same = L.scene_texture_of_image.find(key);
  if (same != L.scene_texture_of_image.end()) {
    L.scene.textures[size_t(same->second)].slots |= 1u << slot;
    return result = same->second;
  }
  st.slots = 1u << slot;
  L.scene.textures.push_back(std::move(st));
  result = int(L.scene.textures.size() - 1);
  L.scene_texture_of_image[key] = result;
  return result;
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A number property of a material, checked finite and within [lo, hi] (clamped, with a warning).
float material_number(Loader& L, double value, double fallback, double lo, double hi, const std::string& what) {
  if (!std::isfinite(value)) {
    L.warn(what + " is not finite; using " + one_line(std::to_string(fallback)));
    return float(fallback);
  }
  if (value < lo || value > hi) {
    const double clamped = std::min(hi, std::max(lo, value));
    L.warn(what + " is outside [" + std::to_string(lo).substr(0, 3) + ", " +
           (std::isfinite(hi) ? std::to_string(hi).substr(0, 3) : std::string("inf")) + "]; clamped");
    return float(clamped);
  }
  return float(std::clamp(value, -double(FLT_MAX), double(FLT_MAX)));  // finite as a float too
}

// The number `key` of material extension `ext` (its JSON object `value`): `fallback` when absent, or,
// with a warning, when not a number; checked as material_number does.
float extension_number(Loader& L, const tinygltf::Value& value, const std::string& ext, const char* key,
                       double fallback, double lo, double hi, const std::string& material) {
  const tinygltf::Value* v = value.IsObject() && value.Has(key) ? &value.Get(key) : nullptr;
  if (v && v->IsNumber()) return material_number(L, v->GetNumberAsDouble(), fallback, lo, hi, material + " " + key);
  if (v || !value.IsObject())
    L.warn(material + " " + ext + " has no valid " + key + "; using " + number_text(fallback));
  return float(fallback);
}

// The factors of KHR_materials_transmission and KHR_materials_volume (DESIGN 4c), checked.
void read_volume_factors(Loader& L, const std::string& ext, const tinygltf::Value& value, const std::string& name,
                         SceneMaterialInputs& m) {
  const double inf = std::numeric_limits<double>::infinity();
  if (ext == "KHR_materials_transmission") {
    m.has_transmission = true;
    m.transmission = extension_number(L, value, ext, "transmissionFactor", 0.0, 0.0, 1.0, name);
  } else if (ext == "KHR_materials_volume") {
    m.has_volume = true;
    m.thickness = extension_number(L, value, ext, "thicknessFactor", 0.0, 0.0, inf, name);
    m.attenuation_distance = extension_number(L, value, ext, "attenuationDistance", inf, 0.0, inf, name);
    if (!(m.attenuation_distance > 0.0f)) {
      L.warn(name + " attenuationDistance must be positive; using infinity (no attenuation)");
      m.attenuation_distance = float(inf);
    }
    double c[3];
    if (value.IsObject() && value.Has("attenuationColor")) {
      if (finite_numbers(value.Get("attenuationColor"), 3, c))
        for (int k = 0; k < 3; ++k)
          m.attenuation_color[k] = material_number(L, c[k], 1.0, 0.0, 1.0, name + " attenuationColor");
      else L.warn(name + " KHR_materials_volume has no valid attenuationColor; using (1, 1, 1)");
    }
  }
}

// KHR_materials_clearcoat's factors and its normal texture's scale, checked.
void read_clearcoat(Loader& L, const tinygltf::Value& value, const std::string& name, SceneMaterialInputs& m) {
  const std::string ext = "KHR_materials_clearcoat";
  m.has_clearcoat = true;
  m.clearcoat = extension_number(L, value, ext, "clearcoatFactor", 0.0, 0.0, 1.0, name);
  m.clearcoat_roughness = extension_number(L, value, ext, "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, name);
  if (!value.IsObject() || !value.Has("clearcoatNormalTexture")) return;
  const tinygltf::Value& normal = value.Get("clearcoatNormalTexture");
  if (normal.IsObject() && normal.Has("scale"))
    m.clearcoat_normal_scale =
        extension_number(L, normal, ext, "scale", 1.0, -std::numeric_limits<double>::infinity(),
                         std::numeric_limits<double>::infinity(), name + " clearcoatNormalTexture");
}

// KHR_materials_specular's factors, checked: the weight in [0, 1], the colour's channels at least 0.
void read_specular(Loader& L, const tinygltf::Value& value, const std::string& name, SceneMaterialInputs& m) {
  const std::string ext = "KHR_materials_specular";
  m.has_specular = true;
  m.specular = extension_number(L, value, ext, "specularFactor", 1.0, 0.0, 1.0, name);
  if (!value.IsObject() || !value.Has("specularColorFactor")) return;
  double c[3];
  if (!finite_numbers(value.Get("specularColorFactor"), 3, c)) {
    L.warn(name + " KHR_materials_specular has no valid specularColorFactor; using (1, 1, 1)");
    return;
  }
  for (int k = 0; k < 3; ++k)
    m.specular_color[k] =
        material_number(L, c[k], 1.0, 0.0, std::numeric_limits<double>::infinity(), name + " specularColorFactor");
}

// KHR_materials_anisotropy's strength (in [0, 1]) and rotation (finite), checked.
void read_anisotropy(Loader& L, const tinygltf::Value& value, const std::string& name, SceneMaterialInputs& m) {
  const std::string ext = "KHR_materials_anisotropy";
  const double inf = std::numeric_limits<double>::infinity();
  m.has_anisotropy = true;
  m.anisotropy_strength = extension_number(L, value, ext, "anisotropyStrength", 0.0, 0.0, 1.0, name);
  m.anisotropy_rotation = extension_number(L, value, ext, "anisotropyRotation", 0.0, -inf, inf, name);
}

// KHR_materials_iridescence's factor (in [0, 1]), film ior (at least 1) and thickness range (nm, at
// least 0), checked.
void read_iridescence(Loader& L, const tinygltf::Value& value, const std::string& name, SceneMaterialInputs& m) {
  const std::string ext = "KHR_materials_iridescence";
  const double inf = std::numeric_limits<double>::infinity();
  m.has_iridescence = true;
  m.iridescence = extension_number(L, value, ext, "iridescenceFactor", 0.0, 0.0, 1.0, name);
  m.iridescence_ior = extension_number(L, value, ext, "iridescenceIor", 1.3, 1.0, inf, name);
  m.iridescence_thickness[0] = extension_number(L, value, ext, "iridescenceThicknessMinimum", 100.0, 0.0, inf, name);
  m.iridescence_thickness[1] = extension_number(L, value, ext, "iridescenceThicknessMaximum", 400.0, 0.0, inf, name);
}

// KHR_materials_sheen's colour and roughness factors, checked: each in [0, 1].
void read_sheen(Loader& L, const tinygltf::Value& value, const std::string& name, SceneMaterialInputs& m) {
  const std::string ext = "KHR_materials_sheen";
  m.has_sheen = true;
  m.sheen_roughness = extension_number(L, value, ext, "sheenRoughnessFactor", 0.0, 0.0, 1.0, name);
  if (!value.IsObject() || !value.Has("sheenColorFactor")) return;
  double c[3];
  if (!finite_numbers(value.Get("sheenColorFactor"), 3, c)) {
    L.warn(name + " KHR_materials_sheen has no valid sheenColorFactor; using (0, 0, 0), no sheen");
    return;
  }
  for (int k = 0; k < 3; ++k) m.sheen_color[k] = material_number(L, c[k], 0.0, 0.0, 1.0, name + " sheenColorFactor");
}

// KHR_materials_ior's ior: 0 or at least 1 (0: the extension's compatibility mode, a Fresnel term of 1).
float read_ior(Loader& L, const tinygltf::Value& value, const std::string& name) {
  const float ior =
      extension_number(L, value, "KHR_materials_ior", "ior", 1.5, 0.0, std::numeric_limits<double>::infinity(), name);
  if (ior > 0.0f && ior < 1.0f) {
    L.warn(name + " ior " + number_text(ior) + " is neither 0 nor at least 1; using 1.5");
    return 1.5f;
  }
  return ior;
}

// A textureInfo inside a material extension (e.g. KHR_materials_transmission's transmissionTexture),
// which tinygltf leaves as JSON values: its texture index (-1: none, or not a texture of the file, with
// a warning), texCoord and extensions (KHR_texture_transform).
struct NestedTextureInfo {
  int index = -1, texcoord = 0;
  tinygltf::ExtensionMap extensions;
};

NestedTextureInfo nested_texture_info(Loader& L, const tinygltf::Material& g, const char* ext, const char* key,
                                      int material) {
  NestedTextureInfo info;
  auto e = g.extensions.find(ext);
  if (e == g.extensions.end() || !e->second.IsObject() || !e->second.Has(key)) return info;
  const tinygltf::Value& v = e->second.Get(key);
  const std::string name = "material " + std::to_string(material) + " " + key;
  const tinygltf::Value* index = v.IsObject() && v.Has("index") ? &v.Get("index") : nullptr;
  const double t = index && index->IsNumber() ? index->GetNumberAsDouble() : -1.0;
  if (!(t >= 0.0 && t < double(L.model.textures.size()) && t == std::floor(t))) {
    L.warn(name + " names no texture of the file; ignored");
    return info;
  }
  info.index = int(t);
  if (v.Has("texCoord")) {
    const tinygltf::Value& c = v.Get("texCoord");
    const double set = c.IsNumber() ? c.GetNumberAsDouble() : -1.0;
    info.texcoord = set >= 0.0 && set < 65536.0 && set == std::floor(set) ? int(set) : 0;
    if (info.texcoord != set) L.warn(name + " has an invalid texCoord; using 0");
  }
  if (v.Has("extensions") && v.Get("extensions").IsObject())
    for (const std::string& k : v.Get("extensions").Keys()) info.extensions[k] = v.Get("extensions").Get(k);
  return info;
}

// The PBR inputs of glTF material i (DESIGN 4b). Records each slot's TEXCOORD set in L.slot_sets.
SceneMaterialInputs material_inputs(Loader& L, const tinygltf::Material& g, int i) {
  const std::string name = "material " + std::to_string(i);
  SceneMaterialInputs m;
  m.name = g.name;
  const double inf = std::numeric_limits<double>::infinity();
  m.metallic = material_number(L, g.pbrMetallicRoughness.metallicFactor, 1.0, 0.0, 1.0, name + " metallicFactor");
  m.roughness = material_number(L, g.pbrMetallicRoughness.roughnessFactor, 1.0, 0.0, 1.0, name + " roughnessFactor");
  m.normal_scale = material_number(L, g.normalTexture.scale, 1.0, -inf, inf, name + " normalTexture.scale");
  m.occlusion_strength =
      material_number(L, g.occlusionTexture.strength, 1.0, 0.0, 1.0, name + " occlusionTexture.strength");
  if (g.emissiveFactor.size() == 3)
    for (int c = 0; c < 3; ++c)
      m.emissive[c] = material_number(L, g.emissiveFactor[size_t(c)], 0.0, 0.0, 1.0, name + " emissiveFactor");
  for (const auto& [ext, value] : g.extensions) {
    if (ext == "KHR_materials_emissive_strength") {
      m.emissive_strength = extension_number(L, value, ext, "emissiveStrength", 1.0, 0.0, inf, name);
    } else if (ext == "KHR_materials_unlit") {
      m.unlit = true;
    } else if (ext == "KHR_materials_ior") {
      m.ior = read_ior(L, value, name);
    } else if (ext == "KHR_materials_transmission" || ext == "KHR_materials_volume") {
      read_volume_factors(L, ext, value, name, m);
    } else if (ext == "KHR_materials_clearcoat") {
      read_clearcoat(L, value, name, m);
    } else if (ext == "KHR_materials_specular") {
      read_specular(L, value, name, m);
    } else if (ext == "KHR_materials_anisotropy") {
      read_anisotropy(L, value, name, m);
    } else if (ext == "KHR_materials_iridescence") {
      read_iridescence(L, value, name, m);
    } else if (ext == "KHR_materials_sheen") {
      read_sheen(L, value, name, m);
    } else if (material_extension_fallback(ext)) {
      m.unimplemented.push_back(ext);
    }
  }
  struct Info {
    int index, texcoord;
    const tinygltf::ExtensionMap* extensions;
  };
  const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
  std::array<Info, kTextureSlots> infos = {
      Info{pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, &pbr.baseColorTexture.extensions},
      Info{pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
           &pbr.metallicRoughnessTexture.extensions},
      Info{g.normalTexture.index, g.normalTexture.texCoord, &g.normalTexture.extensions},
      Info{g.occlusionTexture.index, g.occlusionTexture.texCoord, &g.occlusionTexture.extensions},
      Info{g.emissiveTexture.index, g.emissiveTexture.texCoord, &g.emissiveTexture.extensions}};
  std::array<NestedTextureInfo, kTextureSlots> nested;  // the extensions' slots, which tinygltf leaves as JSON
  for (int slot = kSlotEmissive + 1; slot < kTextureSlots; ++slot) {
    NestedTextureInfo& n = nested[size_t(slot)];
    n = nested_texture_info(L, g, texture_slot_extension(slot), texture_slot_name(slot), i);
    infos[size_t(slot)] = Info{n.index, n.texcoord, &n.extensions};
  }
  std::array<int, kTextureSlots> sets;
  for (int slot = 0; slot < kTextureSlots; ++slot) {
    SceneTextureSlot& out = m.slots[size_t(slot)];
    out.srgb = texture_slot_is_srgb(slot);
    sets[size_t(slot)] = -1;
    const Info& info = infos[size_t(slot)];
    if (info.index < 0) continue;
    // the base colour slot's messages name no slot (they predate the other slots)
    const MaterialUv uv =
        material_uv(L, info.texcoord, *info.extensions, i, slot == kSlotBaseColor ? "" : texture_slot_name(slot));
    out.texcoord_set = uv.set;  // Scene::texcoords index: set by the loader (assign_texcoord_sets)
    out.transform = uv.transform;
    if (out.transform) {
      out.offset[0] = uv.offset[0], out.offset[1] = uv.offset[1];
      out.rotation = uv.rotation;
      out.scale[0] = uv.scale[0], out.scale[1] = uv.scale[1];
    }
    out.texture = scene_texture(L, info.index, slot);
    sets[size_t(slot)] = uv.set;
  }
  L.slot_sets.push_back(sets);
  return m;
}

}  // namespace

// Scene::materials[0] is the default material; glTF material i is Scene::materials[i + 1].
void build_materials(Loader& L) {
  L.scene.materials.push_back(default_material());
  L.scene.material_inputs.emplace_back();
  for (int slot = 0; slot < kTextureSlots; ++slot)
    L.scene.material_inputs[0].slots[size_t(slot)].srgb = texture_slot_is_srgb(slot);
  for (size_t i = 0; i < L.model.materials.size(); ++i) {
    const tinygltf::Material& g = L.model.materials[i];
    const std::string name = "material " + std::to_string(i);
    PmrMaterial m = default_material();
    const std::vector<double>& f = g.pbrMetallicRoughness.baseColorFactor;
    if (f.size() == 4 && std::all_of(f.begin(), f.end(), [](double x) { return std::isfinite(x); })) {
      for (int c = 0; c < 4; ++c) m.base_color[c] = float(f[size_t(c)]);
    } else {
      L.warn(name + " has an invalid baseColorFactor; using white");
    }
    if (g.alphaMode == "MASK") m.alpha_mode = PMR_ALPHA_MASK;
    else if (g.alphaMode == "BLEND") m.alpha_mode = PMR_ALPHA_BLEND;
    else if (g.alphaMode != "OPAQUE") L.warn(name + " has unknown alphaMode '" + g.alphaMode + "'; drawn opaque");
    if (std::isfinite(g.alphaCutoff) && g.alphaCutoff >= 0.0) m.alpha_cutoff = float(g.alphaCutoff);
    else L.warn(name + " has an invalid alphaCutoff; using 0.5");
    m.double_sided = g.doubleSided ? 1u : 0u;
    L.scene.materials.push_back(m);
    L.scene.material_inputs.push_back(material_inputs(L, g, int(i)));
    // the factors the kernels read, as material_inputs checked them
    const SceneMaterialInputs& in = L.scene.material_inputs.back();
    apply_material_inputs(in, L.scene.materials.back());
  }
}

}  // namespace pmr::gltf
