// The glTF loader's state while it flattens a file (gltf_loader.cpp), shared with the material reader
// (gltf_materials.cpp).
#pragma once
#include <array>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/input_files.h"
#include "pmr/scene.h"
#include "scene/gltf_internal.h"

namespace pmr::gltf {

struct ImageContext {
  const tinygltf::Model* model = nullptr;  // the model tinygltf is filling (buffers come before images)
  const std::set<int>* wanted = nullptr;   // images to decode
  uint64_t max_pixels = 0;                 // the texture-pixels budget
  uint64_t memory_left = 0;                // the memory budget left for decoded images (less as they come)
  std::map<int, std::string> failures;     // image index -> why it could not be decoded
  std::string over_limit;                  // the first image over the budget: an error after parsing
};

struct Loader {
  Loader(const tinygltf::Model& m, const std::string& f, const ImageContext& i, Scene& s)
      : model(m), file(f), images(i), scene(s) {}

  const tinygltf::Model& model;
  const std::string& file;
  const ImageContext& images;
  Scene& scene;
  std::set<std::string> seen;
  std::vector<std::array<int, kTextureSlots>> slot_sets;  // per glTF material and slot: TEXCOORD set, -1 = no texture
  // glTF TEXCOORD set -> Scene::texcoords index, for the sets that drawn primitives' materials sample
  // (assign_texcoord_sets), so that a set number a file names costs nothing but its own vertices
  std::map<int, int> texcoord_index;
  std::map<int, int> scene_texture_of;                    // glTF texture -> Scene::textures index (-1: unusable)
  std::map<std::array<int, 3>, int> scene_texture_of_image;  // (image, wrap s, wrap t) -> Scene::textures
  const std::vector<SceneLight>* light_defs = nullptr;       // SourceFile::lights
  const std::vector<std::array<int, 2>>* node_light = nullptr;  // SourceFile::node_light
  std::set<int> used_materials;                              // glTF materials of emitted primitives
  size_t point_line_primitives = 0, skipped_triangles = 0, nonfinite_attributes = 0, leftover_indices = 0;
  size_t generated_tangents = 0;                     // primitives
  std::shared_ptr<SceneMotion> motion;               // always built; kept in the scene when a clip moves something
  std::vector<glm::dmat4> rest_world;                // per node
  std::vector<std::vector<glm::dmat4>> rest_joints;  // per skin: joint matrices at rest
  std::vector<bool> moving, weights_animated;        // per node
  std::set<int> skins_without_joints;                // meshes: skinned nodes whose mesh lacks JOINTS_0
  const InputLimits* limits = nullptr;               // the vertex-data budget

  void warn(const std::string& line) {
    if (seen.insert(line).second) scene.warnings.push_back(file + ": " + one_line(line));
  }
};

// Scene::materials and Scene::material_inputs from the file's materials (materials[0] is the default
// material; glTF material i is i + 1), the textures they sample, and L.slot_sets.
void build_materials(Loader& L);

}  // namespace pmr::gltf
