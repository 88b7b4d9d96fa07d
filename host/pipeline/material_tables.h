// The scene's materials as the kernels read them: PmrMaterial with its texture maps filled from the
// loader's material inputs, the texture table and its texels, and the TEXCOORD sets the maps sample.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "pmr/shared.h"

namespace pmr {

struct MaterialTables {
  std::vector<PmrMaterial> materials;  // Scene::materials, the maps and pbr fields from Scene::material_inputs
  // Scene::textures in order, then (with mips) further entries of those sampled through more than one
  // kind of chain (colour, data, normal: MipKind), whose chains differ (cl/material_maps.h reads map.texture)
  std::vector<PmrTexture> textures;
  std::vector<uint8_t> texels;       // RGBA8 as stored, each texture's levels back to back (PmrTexture)
  std::vector<glm::vec2> texcoords;  // TEXCOORD set k of vertex v at k * vertices + v (at least one entry)
};

// Throws pmr::Error when the scene's material inputs do not fit its arrays (a map's texture or
// TEXCOORD set missing: the loader never produces that), or the textures with their mips exceed 4 G
// texels or the memory budget. A normal map is dropped (drawn with the interpolated normal) when the
// scene has no tangents. `mips`: every texture gets its mip chain (--texture-filter trilinear), else
// level 0 alone.
MaterialTables make_material_tables(const Scene& scene, bool mips);

// KHR_texture_transform of a slot as the 2x3 matrix of PmrTextureMap::uv_transform.
void texture_transform_matrix(const SceneTextureSlot& slot, float out[6]);

}  // namespace pmr
