// What makes a loaded scene move (DESIGN section 7): the node hierarchy with its rest transforms, the
// animation clips, skins, and the instances whose vertices follow them. Built by the glTF loader, used
// by pose_scene (pose.cpp). The same deform() places vertices at load time (rest pose, default morph
// weights, bind pose of the rest skeleton) and per frame, so a frame at the rest pose is the loaded
// scene bit for bit.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "scene/animation.h"

namespace pmr {

struct MotionNode {
  int parent = -1;
  bool has_matrix = false;  // a matrix node is never animated (the spec forbids it)
  glm::dmat4 matrix{1.0};
  glm::dvec3 translation{0.0}, scale{1.0};
  glm::dvec4 rotation{0.0, 0.0, 0.0, 1.0};  // unit quaternion (x, y, z, w)
  std::vector<float> weights;               // default morph weights (the node's, else its mesh's)
};

enum class ChannelPath { Translation, Rotation, Scale, Weights };

struct MotionChannel {
  int node = 0;
  ChannelPath path = ChannelPath::Translation;
  int sampler = 0;
};

struct MotionClip {
  std::string name;
  double start = 0.0, end = 0.0;  // first and last key time over all samplers, seconds
  std::vector<AnimationSampler> samplers;
  std::vector<MotionChannel> channels;
};

struct MotionSkin {
  std::vector<int> joints;               // node indices
  std::vector<glm::dmat4> inverse_bind;  // one per joint (identity when the file gives none)
};

// One mesh primitive in its mesh's space, with what deforms it. Shared by all instances of the mesh.
struct DeformSource {
  size_t vertices = 0;
  std::vector<float> pos, nrm;                             // 3 per vertex; nrm empty when absent
  std::vector<std::vector<float>> target_pos, target_nrm;  // per morph target, 3 per vertex or empty
  std::vector<float> tan;                                  // 4 per vertex (xyz, w handedness) or empty
  std::vector<std::vector<float>> target_tan;              // per morph target, 3 per vertex or empty
  int influences = 0;                                      // joint influences per vertex: 0, 4 or 8
  std::vector<uint16_t> joints;                            // influences per vertex (skin joint slots)
  std::vector<float> weights;                              // influences per vertex
};

// An instance whose vertices move with some animation: its ranges in the scene's arrays.
struct Deformable {
  int node = 0;
  int skin = -1;  // skinned: the node's own transform is not applied (glTF spec, "Skins")
  std::shared_ptr<const DeformSource> source;
  uint32_t vertex_begin = 0;
  uint32_t triangle_begin = 0, triangle_end = 0;
  bool rest_mirrored = false;  // winding of its triangles as loaded was reversed for a mirroring node
};

struct SceneMotion {
  std::vector<MotionNode> nodes;
  std::vector<int> order;  // every node, parents before children
  std::vector<MotionClip> clips;
  std::vector<MotionSkin> skins;
  std::vector<Deformable> deformables;
  std::vector<int> camera_node;  // per scene camera: the node that places it, -1 if none
  std::vector<int> light_node;   // per Scene::lights entry: the node that places it
};

// Node transform from its TRS (unit quaternion), T * R * S.
glm::dmat4 trs_matrix(const glm::dvec3& t, const glm::dvec4& q, const glm::dvec3& s);
// World matrices of all nodes from their local matrices (world = parent world * local).
std::vector<glm::dmat4> world_matrices(const SceneMotion& m, const std::vector<glm::dmat4>& local);
// Local matrices of all nodes at rest.
std::vector<glm::dmat4> rest_local_matrices(const SceneMotion& m);

// The joint matrices of a skin: world(joint) * inverseBind, one per joint.
std::vector<glm::dmat4> joint_matrices(const MotionSkin& skin, const std::vector<glm::dmat4>& world);

// Runs fn(begin, end) over [0, n) split into contiguous chunks on up to hardware_concurrency threads
// (serially below `grain` items per thread).
void parallel_for(size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn);

// Places src's vertices: morph targets with `morph_weights` (may be empty), then the skin's joint
// matrices if `joints` is not null, else the rigid `world`. Writes positions and unit normals (normal
// left zero when absent or degenerate, so shading falls back to the face normal). Vertices whose
// position is not finite are flagged in bad_position (if given) and set to the origin. With
// `tangents` (and src.tan) also the tangents: xyz morphed by the TANGENT targets, then by the blended
// joint matrix's or the world matrix's upper 3x3, normalized (zero when degenerate); w = the sign of
// src's w times the sign of that matrix's determinant (Scene::tangents).
void deform(const DeformSource& src, const std::vector<float>& morph_weights, const glm::dmat4* joints,
            const glm::dmat4& world, glm::vec3* positions, PmrVertexAttr* attributes, uint8_t* bad_position = nullptr,
            uint8_t* bad_normal = nullptr, glm::vec4* tangents = nullptr);
// The same for vertices [begin, end) only (the output pointers still address vertex 0).
void deform_range(const DeformSource& src, const std::vector<float>& morph_weights, const glm::dmat4* joints,
                  const glm::dmat4& world, size_t begin, size_t end, glm::vec3* positions, PmrVertexAttr* attributes,
                  uint8_t* bad_position, uint8_t* bad_normal, glm::vec4* tangents = nullptr);

// Tangents for a mesh without TANGENT, in its own space (DESIGN 4b; MikkTSpace in essence): per
// triangle the direction of increasing u from the UV derivatives, per corner projected onto the
// vertex normal's plane and weighted by the corner's angle, summed over the corners that share a
// position, normal and UV and the same UV orientation (MikkTSpace's welding), normalized. w is +1
// where the triangles' UVs (with v pointing up, as MikkTSpace sees them) keep their orientation, -1
// where they mirror it. pos and nrm hold 3 floats per vertex (nrm may be empty: face normals are
// used), uv 2 per vertex (glTF's convention, v down), tris 3 indices per triangle. Returns 4 floats
// per vertex; a vertex no triangle gives a direction gets some unit vector orthogonal to its normal.
std::vector<float> generate_tangents(const std::vector<float>& pos, const std::vector<float>& nrm,
                                     const std::vector<float>& uv, const std::vector<uint32_t>& tris);

// Unit normal of a triangle, +Z when it has no area.
glm::vec3 face_normal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

}  // namespace pmr
