#include "pipeline/material_tables.h"

#include <cmath>
#include <string>

#include "pmr/error.h"

namespace pmr {

// A material's map k is its texture slot k (make_material_tables copies them by index).
static_assert(PMR_MAP_BASE_COLOR == kSlotBaseColor && PMR_MAP_METALLIC_ROUGHNESS == kSlotMetallicRoughness &&
                  PMR_MAP_NORMAL == kSlotNormal && PMR_MAP_OCCLUSION == kSlotOcclusion &&
                  PMR_MAP_EMISSIVE == kSlotEmissive && PMR_MAPS == kTextureSlots,
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

MaterialTables make_material_tables(const Scene& scene) {
  MaterialTables t;
  const size_t vertices = scene.positions.size();
  size_t total_texels = 0;
  for (const SceneTexture& tex : scene.textures) {
    PmrTexture d{};
    d.offset = uint32_t(total_texels);
    d.width = tex.width, d.height = tex.height;
    d.wrap_s = tex.wrap_s, d.wrap_t = tex.wrap_t;
    if (tex.rgba.size() != size_t(tex.width) * size_t(tex.height) * 4)
      throw InternalError("a texture's texels do not match its size");
    total_texels += size_t(tex.width) * size_t(tex.height);
    if (total_texels >= (size_t(1) << 32)) throw Error("the scene's textures are too large (over 4 G texels)");
    t.textures.push_back(d);
  }
  t.texels.resize(total_texels * 4);
  for (size_t i = 0; i < scene.textures.size(); ++i)
    std::copy(scene.textures[i].rgba.begin(), scene.textures[i].rgba.end(),
              t.texels.begin() + size_t(t.textures[i].offset) * 4);

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
    // the factors as the loader checked them (a scene's PmrMaterial copies may be stale)
    m.metallic = in.metallic, m.roughness = in.roughness, m.unlit = in.unlit ? 1u : 0u;
    for (int c = 0; c < 3; ++c) m.emissive[c] = in.emissive[c] * in.emissive_strength;
    m.normal_scale = in.normal_scale, m.occlusion_strength = in.occlusion_strength;
    for (int k = 0; k < PMR_MAPS; ++k) {
      const SceneTextureSlot& slot = in.slots[size_t(k)];  // PMR_MAP_* is the slot's kind
      if (slot.texture < 0) continue;
      if (size_t(slot.texture) >= scene.textures.size() || slot.texcoord < 0 ||
          size_t(slot.texcoord) >= scene.texcoords.size())
        throw InternalError("material " + std::to_string(i) + "'s " + texture_slot_name(k) +
                            " names a texture or TEXCOORD set the scene does not have");
      if (k == PMR_MAP_NORMAL && !has_tangents) continue;
      PmrTextureMap& map = m.maps[k];
      map.texture = slot.texture;
      map.texcoord = uint32_t(slot.texcoord);
      texture_transform_matrix(slot, map.uv_transform);
    }
  }
  return t;
}

}  // namespace pmr
