#include "pipeline/material_tables.h"

#include <array>
#include <cmath>
#include <string>

#include "pipeline/texture_mips.h"
#include "pmr/error.h"
#include "pmr/memory_budget.h"

namespace pmr {

// A material's map k is its texture slot k (make_material_tables copies them by index).
static_assert(PMR_MAP_BASE_COLOR == kSlotBaseColor && PMR_MAP_METALLIC_ROUGHNESS == kSlotMetallicRoughness &&
                  PMR_MAP_NORMAL == kSlotNormal && PMR_MAP_OCCLUSION == kSlotOcclusion &&
                  PMR_MAP_EMISSIVE == kSlotEmissive && PMR_MAP_TRANSMISSION == kSlotTransmission &&
                  PMR_MAP_THICKNESS == kSlotThickness && PMR_MAP_CLEARCOAT == kSlotClearcoat &&
                  PMR_MAP_CLEARCOAT_ROUGHNESS == kSlotClearcoatRoughness &&
                  PMR_MAP_CLEARCOAT_NORMAL == kSlotClearcoatNormal && PMR_MAP_SPECULAR == kSlotSpecular &&
                  PMR_MAP_SPECULAR_COLOR == kSlotSpecularColor && PMR_MAP_ANISOTROPY == kSlotAnisotropy &&
                  PMR_MAP_IRIDESCENCE == kSlotIridescence &&
                  PMR_MAP_IRIDESCENCE_THICKNESS == kSlotIridescenceThickness &&
                  PMR_MAP_SHEEN_COLOR == kSlotSheenColor && PMR_MAP_SHEEN_ROUGHNESS == kSlotSheenRoughness &&
                  PMR_MAPS == kTextureSlots,
              "PMR_MAP_* follow SceneTextureSlotKind");

void texture_transform_matrix(const SceneTextureSlot& slot, float out[6]) {
  if (!slot.transform) {
    const float identity[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
    std::copy(identity, identity + 6, out);
    return;
  }
  // u' = sx cos(r) u + sy sin(r) v + ox, v' = -sx sin(r) u + sy cos(r) v + oy
  const double c = std::cos(double(slot.rotation)), s = std::sin(double(slot.rotation));
  const double sx = slot.scale[0], sy = slot.scale[1];
  out[0] = float(sx * c), out[1] = float(sy * s), out[2] = slot.offset[0];
  out[3] = float(-sx * s), out[4] = float(sy * c), out[5] = slot.offset[1];
}

namespace {

// The chain slot k of material `in` samples: colour maps (sRGB), normal maps, or the other data maps.
// A slot read for its alpha alone (sheen roughness, specular weight) whose texture is also its colour
// partner's (sheen colour, specular colour) samples the colour chain: both chains average alpha
// linearly, so it reads the same values, and the kernels read the packed texture once.
MipKind slot_kind(const SceneMaterialInputs& in, int k) {
  const SceneTextureSlot& slot = in.slots[size_t(k)];
  const int partner = k == kSlotSheenRoughness ? kSlotSheenColor : k == kSlotSpecular ? kSlotSpecularColor : -1;
  if (partner >= 0 && in.slots[size_t(partner)].texture == slot.texture && in.slots[size_t(partner)].srgb)
    return MipKind::Colour;
  return slot.srgb ? MipKind::Colour : texture_slot_is_normal_map(k) ? MipKind::Normal : MipKind::Data;
}
constexpr int kMipKinds = 3;

// Which chains the scene's materials sample texture i through: used[kind][i].
using TextureUses = std::array<std::vector<bool>, kMipKinds>;

TextureUses texture_uses(const Scene& scene) {
  TextureUses u;
  for (std::vector<bool>& kind : u) kind.assign(scene.textures.size(), false);
  for (const SceneMaterialInputs& in : scene.material_inputs)
    for (int k = 0; k < PMR_MAPS; ++k) {
      const SceneTextureSlot& slot = in.slots[size_t(k)];
      if (slot.texture >= 0 && size_t(slot.texture) < scene.textures.size())
        u[size_t(slot_kind(in, k))][size_t(slot.texture)] = true;
    }
  return u;
}

// The chain kinds texture i gets an entry for, first its own (the first kind used, else colour); without
// mips one entry serves every use.
std::vector<MipKind> entry_kinds(const TextureUses& uses, size_t i, bool mips) {
  std::vector<MipKind> kinds;
  for (int k = 0; k < kMipKinds; ++k)
    if (uses[size_t(k)][i] && (mips || kinds.empty())) kinds.push_back(MipKind(k));
  if (kinds.empty()) kinds.push_back(MipKind::Colour);
  return kinds;
}

// Appends texture `tex` to the table: level 0 as stored (a normal chain's alpha 0: its level 0 is unit
// normals), then its mips of `kind` when `mips`.
void add_texture(MaterialTables& t, const SceneTexture& tex, bool mips, MipKind kind) {
  if (tex.rgba.size() != size_t(tex.width) * size_t(tex.height) * 4)
    throw InternalError("a texture's texels do not match its size");
  PmrTexture d{};
  d.offset = uint32_t(t.texels.size() / 4);
  d.width = tex.width, d.height = tex.height;
  d.wrap_s = tex.wrap_s, d.wrap_t = tex.wrap_t;
  d.levels = uint32_t(mips ? mip_levels(tex.width, tex.height) : 1);
  t.texels.insert(t.texels.end(), tex.rgba.begin(), tex.rgba.end());
  if (mips && kind == MipKind::Normal)
    for (size_t a = size_t(d.offset) * 4 + 3; a < t.texels.size(); a += 4) t.texels[a] = 0;
  if (mips) {
    const std::vector<uint8_t> chain = build_mips(tex.rgba.data(), tex.width, tex.height, kind);
    t.texels.insert(t.texels.end(), chain.begin(), chain.end());
  }
  t.textures.push_back(d);
}

// The texture table: entry i is scene texture i with the chain of its first use; with mips, a texture
// sampled through more than one kind of chain gets further entries, after all the first ones.
// entry[kind][i] is the entry of texture i's chain of that kind (-1: not sampled so). The texels are
// checked against the memory budget before they are built.
std::array<std::vector<int>, kMipKinds> add_textures(MaterialTables& t, const Scene& scene, bool mips) {
  const TextureUses uses = texture_uses(scene);
  uint64_t total = 0;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const SceneTexture& tex = scene.textures[i];
    const int levels = mips ? mip_levels(tex.width, tex.height) : 1;
    total += entry_kinds(uses, i, mips).size() * mip_chain_texels(tex.width, tex.height, levels);
  }
  if (total >= (uint64_t(1) << 32))
    throw Error("the scene's textures are too large (over 4 G texels" + std::string(mips ? " with their mips)" : ")"));
  check_memory(total * 4, mips ? "the textures and their mip chains" : "the textures");
  t.texels.reserve(size_t(total) * 4);
  std::array<std::vector<int>, kMipKinds> entry;
  for (std::vector<int>& kind : entry) kind.assign(scene.textures.size(), -1);
  for (size_t pass = 0; pass < size_t(kMipKinds); ++pass)  // first entries first: entry i is texture i
    for (size_t i = 0; i < scene.textures.size(); ++i) {
      const std::vector<MipKind> kinds = entry_kinds(uses, i, mips);
      if (pass >= kinds.size()) continue;
      const int index = int(t.textures.size());
      add_texture(t, scene.textures[i], mips, kinds[pass]);
      if (mips) entry[size_t(kinds[pass])][i] = index;
      else
        for (std::vector<int>& kind : entry) kind[i] = index;
    }
  return entry;
}

}  // namespace

namespace {

// PmrMaterial.flags of a material whose maps are set.
uint32_t material_flags(const PmrMaterial& m) {
  uint32_t flags = 0;
  for (const PmrTextureMap& map : m.maps)
    if (map.texture >= 0) flags |= PMR_MATERIAL_MAPS;
  const bool white = m.specular_color[0] == 1.0f && m.specular_color[1] == 1.0f && m.specular_color[2] == 1.0f;
  if (m.specular != 1.0f || !white || m.maps[PMR_MAP_SPECULAR].texture >= 0 ||
      m.maps[PMR_MAP_SPECULAR_COLOR].texture >= 0)
    flags |= PMR_MATERIAL_SPECULAR;
  if (m.anisotropy[0] > 0.0f) flags |= PMR_MATERIAL_ANISOTROPY;
  if (m.iridescence[0] > 0.0f) flags |= PMR_MATERIAL_IRIDESCENCE;
  // the specification: a sheen colour factor of 0 disables the whole layer
  if (m.sheen[0] > 0.0f || m.sheen[1] > 0.0f || m.sheen[2] > 0.0f) flags |= PMR_MATERIAL_SHEEN;
  return flags;
}

}  // namespace

MaterialTables make_material_tables(const Scene& scene, bool mips) {
  MaterialTables t;
  const size_t vertices = scene.positions.size();
  const std::array<std::vector<int>, kMipKinds> entry = add_textures(t, scene, mips);

  for (const std::vector<glm::vec2>& set : scene.texcoords)
    if (set.size() != vertices) throw InternalError("a TEXCOORD set does not have one entry per vertex");
  t.texcoords.reserve(std::max<size_t>(1, scene.texcoords.size() * vertices));
  for (const std::vector<glm::vec2>& set : scene.texcoords)
    t.texcoords.insert(t.texcoords.end(), set.begin(), set.end());
  if (t.texcoords.empty()) t.texcoords.emplace_back(0.0f);

  const bool has_tangents = scene.tangents.size() == vertices && vertices > 0;
  t.materials = scene.materials;
  for (size_t i = 0; i < t.materials.size(); ++i) {
    PmrMaterial& m = t.materials[i];
    const PmrMaterial defaults = default_material();
    std::copy(defaults.maps, defaults.maps + PMR_MAPS, m.maps);
    m.normal_scale = 1.0f, m.occlusion_strength = 1.0f;
    if (i >= scene.material_inputs.size()) continue;  // generated scenes: no maps
    const SceneMaterialInputs& in = scene.material_inputs[i];
    apply_material_inputs(in, m);  // the factors as the loader checked them (a scene's copies may be stale)
    for (int k = 0; k < PMR_MAPS; ++k) {
      const SceneTextureSlot& slot = in.slots[size_t(k)];   // PMR_MAP_* is the slot's kind
      if (slot.texture < 0 || slot.texcoord < 0) continue;  // no map, or no drawn primitive samples it
      if (size_t(slot.texture) >= scene.textures.size() || size_t(slot.texcoord) >= scene.texcoords.size())
        throw InternalError("material " + std::to_string(i) + "'s " + texture_slot_name(k) +
                            " names a texture or TEXCOORD set the scene does not have");
      if (texture_slot_is_normal_map(k) && !has_tangents) continue;
      PmrTextureMap& map = m.maps[k];
      map.texture = entry[size_t(slot_kind(in, k))][size_t(slot.texture)];
      map.texcoord = uint32_t(slot.texcoord);
      texture_transform_matrix(slot, map.uv_transform);
    }
  }
  // the ground catcher's mark is the scene's (host/scene/ground_catcher.h); the rest is found here
  for (PmrMaterial& m : t.materials) m.flags = material_flags(m) | (m.flags & PMR_MATERIAL_SHADOW_CATCHER);
  return t;
}

}  // namespace pmr
