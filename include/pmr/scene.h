// A glTF scene flattened for rendering: every mesh instance baked into world space.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/shared.h"

namespace pmr {

struct SceneTexture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes, sRGB-encoded colour, row 0 = top of image
  int wrap_s = PMR_WRAP_REPEAT, wrap_t = PMR_WRAP_REPEAT;
};

// A glTF camera, placed by the first node (in scene traversal order) that uses it. Cameras that no
// node of the rendered scene uses, or whose perspective parameters are invalid, keep placed = false.
struct SceneCamera {
  std::string name;
  glm::dmat4 world_from_camera{1.0};  // the node's world matrix (camera looks along its -Z)
  double yfov = 0.0;                  // radians
  double znear = 0.0;
  double zfar = 0.0;                  // 0 = infinite
  double aspect = 0.0;                // 0 = not given
  bool perspective = true;            // orthographic cameras are listed but cannot drive the rig
  bool placed = false;                // true: a node of the scene places it (world_from_camera valid)
};

struct SceneMotion;  // node hierarchy, clips, skins, moving instances (host/scene/motion.h)

// A glTF animation as the CLI lists and selects it.
struct SceneAnimation {
  std::string name;               // as in the file ("" when unnamed)
  double start = 0.0, end = 0.0;  // first and last key time, seconds
  size_t channels = 0;
};

// What the file holds beyond the flattened arrays, for `pmr info SCENE`.
struct SceneStructure {
  size_t nodes = 0, meshes = 0, mesh_instances = 0, primitives = 0;
  std::vector<size_t> skin_joints;                    // per skin: its joint count
  std::vector<std::pair<int, size_t>> morph_meshes;   // (mesh index, morph target count) per mesh with targets
  std::string generator;                              // asset.generator
};

// A file the loader read besides the scene file itself (an external buffer or a decoded image), with
// the checksum (output/checksum.h) of its bytes as read.
struct SceneInputFile {
  std::string path;      // relative to the scene file's folder, as the URI names it (percent-decoded)
  std::string checksum;  // XXH3-64, 16 hex digits
};

struct Scene {
  std::vector<glm::vec3> positions;       // world space, one per vertex
  std::vector<PmrVertexAttr> attributes;  // one per vertex (normal in world space)
  std::vector<PmrTriangle> triangles;     // CCW front (winding already fixed for mirrored nodes)
  std::vector<PmrMaterial> materials;     // at least one: index 0 may be the glTF default material
                                          // (load_scene: 0 is the default, glTF material i is i + 1)
  std::vector<SceneTexture> textures;     // referenced by PmrMaterial::texture
  std::vector<SceneCamera> cameras;       // one per glTF camera, same order (see SceneCamera::placed)
  std::vector<std::string> warnings;      // non-fatal problems, one line each
  // The arrays above hold the rest pose: no animation applied, default morph weights, skins bound to
  // their skeleton's rest transforms. pose_scene() places a frame.
  std::vector<SceneAnimation> animations;
  std::shared_ptr<const SceneMotion> motion;
  SceneStructure structure;  // null when no animation can move anything
  // What the render read (docs/SEQUENCES.md, "What a sidecar records"): the checksum of the scene file
  // (a .glb's whole file, a .gltf's JSON) and of every other file read, sorted by path. data: URIs and
  // images no material samples as base colour are not files read. Hashed from the loader's own bytes.
  std::string source_checksum;
  std::vector<SceneInputFile> input_files;
};

constexpr int kNoAnimation = -1, kAllAnimations = -2;

// One frame's pose (DESIGN section 7).
struct PoseRequest {
  double time = 0.0;                // seconds
  int animation = kNoAnimation;     // index into Scene::animations, kNoAnimation or kAllAnimations
  bool turntable = false;           // turn the geometry by turntable_deg about +Y through pivot
  double turntable_deg = 0.0;       // counter-clockwise seen from above (right-hand rule about +Y)
  glm::dvec3 pivot{0.0};
};

// Writes the posed geometry (positions, attributes, triangles) and cameras of `rest` into `out`.
// `out` starts as anything: its arrays are sized and filled from `rest` on first use and rewritten
// where the pose differs, so a pose depends only on the request, never on earlier frames. Materials
// and textures of `out` are left alone. Returns true when some geometry differs from the rest pose's
// arrays (so the renderer must upload it).
bool pose_scene(const Scene& rest, const PoseRequest& request, Scene& out);

// True if the request can move any vertex or camera (an animation that targets something, or a
// turntable). A static request's frames are the rest scene.
bool pose_moves(const Scene& rest, const PoseRequest& request);

// The turntable angle of frame f for DEG:FRAMES, in [0, 360), exact for whole multiples of 360.
double turntable_angle(long frame, double degrees, long frames);

// Loads a .gltf or .glb file (detected by content, not by extension) and validates it completely
// before returning. Throws pmr::Error with one clear line on anything that cannot be rendered.
Scene load_scene(const std::string& path);

// World-space axis-aligned bounds of all vertices referenced by triangles. Returns false (lo, hi
// untouched) when there are none.
bool scene_bounds(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi);

}  // namespace pmr

namespace pmr {
// The glTF default material: white, opaque, single-sided (used when a primitive has none).
PmrMaterial default_material();

// A procedural scene of about `triangles` triangles (1k to 1M): UV spheres of ~200 triangles with
// random sizes and colours spread through a 4 x 2 x 3 box, so they cover the whole depth range in
// front of and behind the focal plane. Deterministic for a given seed. For performance sweeps.
Scene make_synthetic_scene(size_t triangles, uint32_t seed = 1);

// A procedural scene built like a detailed CAD assembly: about `triangles` triangles over 100 closed
// objects (fewer below 10,000 triangles), tori and superquadrics (rounded boxes to ellipsoids) with
// smooth normals, random rotations, anisotropic sizes and colours, each its own double-sided material,
// spread through the same 4 x 2 x 3 box. At 1M triangles most triangles cover under a pixel of a
// 1024 x 512 view. Deterministic for a given seed. For performance sweeps.
Scene make_objects_scene(size_t triangles, uint32_t seed = 1);

// Writes a scene without textures as a binary glTF (.glb): one mesh per material with POSITION,
// NORMAL and COLOR_0, uint32 indices, the materials' base colour, alpha mode and sidedness. Loading
// the file gives the same positions, triangles and materials (load_scene adds its default material
// at index 0). Written atomically; throws pmr::Error on failure or on a scene with textures.
void save_glb(const Scene& scene, const std::string& path);
}  // namespace pmr
