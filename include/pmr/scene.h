// A glTF scene flattened for rendering: every mesh instance baked into world space.
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/input_files.h"
#include "pmr/shared.h"

namespace pmr {

// An image decoded once for every material slot that samples it with the same wrap modes. The bytes
// are as stored in the image: colour slots (base colour, emissive) decode them from sRGB, data slots
// (metallic-roughness, normal, occlusion) read them as linear values (SceneTextureSlot::srgb).
struct SceneTexture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes as stored in the image, row 0 = top of image
  int wrap_s = PMR_WRAP_REPEAT, wrap_t = PMR_WRAP_REPEAT;
  uint32_t slots = 0;  // bit (1 << SceneTextureSlotKind) for each kind of slot that samples it
};

// The texture slots of a glTF metallic-roughness material (DESIGN section 4b), in this order.
enum SceneTextureSlotKind : int {
  kSlotBaseColor = 0,              // RGBA, sRGB
  kSlotMetallicRoughness = 1,      // B metallic, G roughness, linear
  kSlotNormal = 2,                 // RGB tangent-space normal, linear
  kSlotOcclusion = 3,              // R occlusion, linear
  kSlotEmissive = 4,               // RGB, sRGB
  kSlotTransmission = 5,           // R transmission (KHR_materials_transmission), linear
  kSlotThickness = 6,              // G thickness (KHR_materials_volume), linear
  kSlotClearcoat = 7,              // R clear coat intensity (KHR_materials_clearcoat), linear
  kSlotClearcoatRoughness = 8,     // G clear coat roughness, linear
  kSlotClearcoatNormal = 9,        // RGB the clear coat's tangent-space normal, linear
  kSlotSpecular = 10,              // A specular weight (KHR_materials_specular), linear
  kSlotSpecularColor = 11,         // RGB specular colour, sRGB
  kSlotAnisotropy = 12,            // RG direction, B strength (KHR_materials_anisotropy), linear
  kSlotIridescence = 13,           // R iridescence factor (KHR_materials_iridescence), linear
  kSlotIridescenceThickness = 14,  // G thin-film thickness, linear
  kSlotSheenColor = 15,            // RGB sheen colour (KHR_materials_sheen), sRGB
  kSlotSheenRoughness = 16,        // A sheen roughness, linear
  kTextureSlots = 17
};
const char* texture_slot_name(int slot);  // "baseColorTexture", ... (the glTF property names)
// The material extension whose object holds slot `slot`'s textureInfo; nullptr for the core slots.
const char* texture_slot_extension(int slot);
// Whether the slot holds a tangent-space normal map (normalTexture, clearcoatNormalTexture).
bool texture_slot_is_normal_map(int slot);
// Whether the slot's texels are sRGB-encoded colours (base colour, emissive, specular and sheen colour).
bool texture_slot_is_srgb(int slot);

// One textureInfo of a material. texcoord is the TEXCOORD_n set sampled (the KHR_texture_transform
// texCoord override already applied); the transform maps that set's stored (untransformed) values:
// u' = sx cos(r) u + sy sin(r) v + ox, v' = -sx sin(r) u + sy cos(r) v + oy.
struct SceneTextureSlot {
  int texture = -1;        // index into Scene::textures; -1 = none (absent, or its image is unusable)
  int texcoord = 0;        // index into Scene::texcoords; -1: no drawn primitive samples it (load_scene)
  int texcoord_set = 0;    // the file's TEXCOORD_n (what pmr info names)
  bool srgb = false;       // true for base colour and emissive
  bool transform = false;  // KHR_texture_transform present (else the identity)
  float offset[2] = {0.0f, 0.0f};
  float rotation = 0.0f;  // radians
  float scale[2] = {1.0f, 1.0f};
};

// A glTF material's texture slots (both models read the base colour slot) and everything else of it the
// physically based model reads (DESIGN 4b), beside the PmrMaterial factors the Lambert model reads (base
// colour factor, alpha mode and cutoff, sidedness stay there).
struct SceneMaterialInputs {
  std::string name;                         // as in the file ("" when unnamed or the default material)
  float metallic = 1.0f, roughness = 1.0f;  // metallicFactor, roughnessFactor (validated to [0, 1])
  float normal_scale = 1.0f;                // normalTexture.scale
  float occlusion_strength = 1.0f;          // occlusionTexture.strength (validated to [0, 1])
  float emissive[3] = {0.0f, 0.0f, 0.0f};   // emissiveFactor (linear)
  float emissive_strength = 1.0f;           // KHR_materials_emissive_strength (1 without it)
  bool unlit = false;                       // KHR_materials_unlit
  float ior = 1.5f;                         // KHR_materials_ior: 0 or >= 1 (its F0: PmrMaterial::f0_dielectric)
  // DESIGN 4c step 2 (pbr)
  bool has_transmission = false, has_volume = false;  // the material has the extension
  float transmission = 0.0f;                          // KHR_materials_transmission transmissionFactor
  float thickness = 0.0f;                             // KHR_materials_volume thicknessFactor (0: thin)
  float attenuation_distance = std::numeric_limits<float>::infinity();  // KHR_materials_volume (none)
  float attenuation_color[3] = {1.0f, 1.0f, 1.0f};                      // KHR_materials_volume (linear)
  // KHR_materials_clearcoat (pbr): a second specular lobe over the material, with its own roughness
  // and normal map
  bool has_clearcoat = false;
  float clearcoat = 0.0f, clearcoat_roughness = 0.0f;  // the factors (validated to [0, 1])
  float clearcoat_normal_scale = 1.0f;                 // clearcoatNormalTexture.scale
  // KHR_materials_specular (pbr): the dielectric's Fresnel weight and colour
  bool has_specular = false;
  float specular = 1.0f;                         // specularFactor (validated to [0, 1])
  float specular_color[3] = {1.0f, 1.0f, 1.0f};  // specularColorFactor (linear, >= 0)
  // KHR_materials_anisotropy (pbr): GGX stretched along a direction of the tangent frame
  bool has_anisotropy = false;
  float anisotropy_strength = 0.0f;  // anisotropyStrength (validated to [0, 1])
  float anisotropy_rotation = 0.0f;  // anisotropyRotation, radians counter-clockwise from the tangent
  // KHR_materials_iridescence (pbr): a thin film whose interference tints the Fresnel term
  bool has_iridescence = false;
  float iridescence = 0.0f;                           // iridescenceFactor (validated to [0, 1])
  float iridescence_ior = 1.3f;                       // iridescenceIor (>= 1)
  float iridescence_thickness[2] = {100.0f, 400.0f};  // iridescenceThicknessMinimum, ...Maximum (nm, >= 0)
  // KHR_materials_sheen (pbr): a layer of fibres over the material (the Charlie lobe)
  bool has_sheen = false;
  float sheen_color[3] = {0.0f, 0.0f, 0.0f};          // sheenColorFactor (linear, validated to [0, 1])
  float sheen_roughness = 0.0f;                       // sheenRoughnessFactor (validated to [0, 1])
  std::array<SceneTextureSlot, kTextureSlots> slots;  // indexed by SceneTextureSlotKind
  std::vector<std::string> unimplemented;  // material extensions present but not drawn (warned once per scene)
};

// A KHR_lights_punctual light placed by one node of the rendered scene (a light used by two nodes is
// two SceneLights). position and direction are world space; pose_scene moves them with the node's
// animation and the turntable.
// KHR_lights_punctual's three kinds, and EXT_lights_area's rect and disk (DESIGN section 4d).
enum class SceneLightType { Directional, Point, Spot, Rect, Disk };
struct SceneLight {
  std::string name;       // the light's name in the file
  int light = 0;          // index into the file's KHR_lights_punctual lights (area lights: EXT_lights_area's)
  int node = 0;           // the node that places it
  std::string node_name;  // that node's name in the file
  SceneLightType type = SceneLightType::Directional;
  float color[3] = {1.0f, 1.0f, 1.0f};  // linear
  float intensity = 1.0f;               // directional: lux; point and spot: candela; rect and disk: nits (cd/m^2)
  float range = 0.0f;                   // 0 = not given (no window); point and spot only
  float inner_cone = 0.0f, outer_cone = 0.7853981634f;  // spot: radians, 0 <= inner < outer <= pi / 2
  glm::dvec3 position{0.0};                             // the node's origin
  glm::dvec3 direction{0.0, 0.0, -1.0};                 // unit, the node's -Z: where the light shines
  // Its size (DESIGN section 4d), which shapes its shadows only: a point or spot light's radius (the
  // light's extras.pmr_radius, metres: a sphere, Blender's light radius) and a directional light's
  // apparent diameter (extras.pmr_angle, radians: Blender's sun angle). 0: point-like.
  float radius = 0.0f, angle = 0.0f;
  // An area light (EXT_lights_area, one-sided, emitting along `direction`): its `size` and `aspect` as
  // the file gives them, and as placed by its node (place_light): the unit axes of its plane (the
  // node's X and Y, `right` x `up` = -direction) and its world width (along right) and height (along
  // up): width = s size aspect, height = s size (a disk: its diameter s size), s the largest of the
  // node's world scales.
  float size = 1.0f, aspect = 1.0f;
  glm::dvec3 right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
  double width = 1.0, height = 1.0;
  // A distant area light (a patch of directions at infinity taken out of the environment, such as the
  // studio's soft boxes; DESIGN 4d): its shape lies on the plane tangent to the unit sphere at
  // `position`, the unit direction toward its centre (direction = -position), and is seen from every
  // point alike. Shadowed as a directional light of that size. light = node = -1.
  bool distant = false;
};

// The light type's name as glTF spells it ("directional", "point", "spot", "rect", "disk").
const char* light_type_name(SceneLightType type);

// Whether a light is an area light (rect or disk), and whether its shadows are soft (it has a size:
// an area, a radius or an angle).
bool is_area_light(const SceneLight& light);
bool has_size(const SceneLight& light);

// Places `light` by its node's world matrix: the origin, the -Z direction (a degenerate matrix keeps the
// one it had: returns false), and for an area light its axes and world size.
bool place_light(SceneLight& light, const glm::dmat4& world);

// A glTF camera, placed by the first node (in scene traversal order) that uses it. Cameras that no
// node of the rendered scene uses, or whose perspective parameters are invalid, keep placed = false.
struct SceneCamera {
  std::string name;
  std::string node_name;              // the name of the node that places it
  int shared_with = -1;               // a further node placing glTF camera `shared_with` (entries after the file's)
  glm::dmat4 world_from_camera{1.0};  // the node's world matrix (camera looks along its -Z)
  double yfov = 0.0;                  // radians
  double znear = 0.0;
  double zfar = 0.0;        // 0 = infinite
  double aspect = 0.0;      // 0 = not given
  bool perspective = true;  // orthographic cameras are listed but cannot drive the rig
  bool placed = false;      // true: a node of the scene places it (world_from_camera valid)
  std::string invalid;      // why its perspective parameters cannot drive the rig (empty: they can)
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
  std::vector<size_t> skin_joints;                   // per skin: its joint count
  std::vector<std::pair<int, size_t>> morph_meshes;  // (mesh index, morph target count) per mesh with targets
  std::string generator;                             // asset.generator
  size_t generated_tangent_primitives = 0;           // primitives with a normal texture and no TANGENT
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
  std::vector<SceneTexture> textures;     // referenced by SceneTextureSlot::texture
  // Texture slots and physically based inputs (DESIGN 4b). material_inputs is parallel to materials
  // (same index), or empty (generated scenes: every material has the defaults, no textures). texcoords holds, for every
  // vertex, each TEXCOORD set that some drawn primitive's material samples, in increasing set number
  // (SceneTextureSlot::texcoord indexes it, texcoord_set names the file's set), as stored in the file
  // (no KHR_texture_transform applied: each slot has its own); (0, 0) for vertices of meshes without
  // it, whose materials do not sample it. tangents is empty or one per vertex: world-space unit xyz, and w = the file's
  // handedness times sign(det) of the matrix that placed the vertex (the node's world matrix or the
  // blended joint matrix), so the world bitangent is w * cross(n, t); xyz = 0 where the vertex has
  // no tangent (its material has no normal texture). Tangents are the file's, or generated for
  // meshes with a normal texture and no TANGENT. pose_scene updates tangents and lights; texcoords,
  // like materials, are read from the rest scene.
  std::vector<SceneMaterialInputs> material_inputs;
  std::vector<std::vector<glm::vec2>> texcoords;
  std::vector<glm::vec4> tangents;
  std::vector<SceneLight> lights;  // KHR_lights_punctual, in scene traversal order
  // One per glTF camera, same order (see SceneCamera::placed), then one per further node that places a
  // camera already placed (SceneCamera::shared_with)
  std::vector<SceneCamera> cameras;
  // KHR_materials_variants: the file's variants, and the one the materials were loaded for (-1: none,
  // the primitives' default materials)
  std::vector<std::string> variants;
  int variant = -1;
  std::vector<std::string> warnings;  // non-fatal problems, one line each
  // The arrays above hold the rest pose: no animation applied, default morph weights, skins bound to
  // their skeleton's rest transforms. pose_scene() places a frame.
  std::vector<SceneAnimation> animations;
  std::shared_ptr<const SceneMotion> motion;
  SceneStructure structure;  // null when no animation can move anything
  // What the render read (docs/SEQUENCES.md, "What a sidecar records"): the checksum of the scene file
  // (a .glb's whole file, a .gltf's JSON) and of every other file read, sorted by path. data: URIs and
  // images no material slot samples (base colour, metallic-roughness, normal, occlusion, emissive)
  // are not files read. Hashed from the loader's own bytes.
  std::string source_checksum;
  std::vector<SceneInputFile> input_files;
};

constexpr int kNoAnimation = -1, kAllAnimations = -2;

// One frame's pose (DESIGN section 7).
struct PoseRequest {
  double time = 0.0;             // seconds
  int animation = kNoAnimation;  // index into Scene::animations, kNoAnimation or kAllAnimations
  bool turntable = false;        // turn the geometry by turntable_deg about +Y through pivot
  double turntable_deg = 0.0;    // counter-clockwise seen from above (right-hand rule about +Y)
  glm::dvec3 pivot{0.0};
};

// Writes the posed geometry (positions, attributes, triangles, tangents), cameras and lights of `rest`
// into `out`.
// `out` starts as anything: its arrays are sized and filled from `rest` on first use and rewritten
// where the pose differs, so a pose depends only on the request, never on earlier frames. Materials
// and textures of `out` are left alone. Returns true when some geometry differs from the rest pose's
// arrays (so the renderer must upload it).
bool pose_scene(const Scene& rest, const PoseRequest& request, Scene& out);

// Writes the posed cameras and lights of `rest` into `out`, the same as pose_scene places them, without
// posing any geometry (out's geometry is left alone): what a frame's sidecar records, for frames not
// rendered (--resume).
void pose_cameras_and_lights(const Scene& rest, const PoseRequest& request, Scene& out);

// True if the request can move any vertex or camera (an animation that targets something, or a
// turntable). A static request's frames are the rest scene.
bool pose_moves(const Scene& rest, const PoseRequest& request);

// The work of one pose_scene call for `animation` (kNoAnimation: the turntable only), in units of about
// one vertex's deformation by one shape (docs/SECURITY.md, "Posing"): every vertex once (copied or
// turned), each moving instance's vertices once more for the base shape and once per morph target it
// has, and its triangles once, every animated value sampled, and the transforms of nodes and skin joints, weighted by
// their measured cost relative to a vertex (kPoseNodeUnits, kPoseJointUnits). Checked before posing
// (FrameRenderer) so that a crafted file cannot make framing or frames run for hours.
inline constexpr uint64_t kPoseNodeUnits = 32, kPoseJointUnits = 8;
uint64_t pose_work(const Scene& rest, int animation);

// The turntable angle of frame f for DEG:FRAMES, in [0, 360), exact for whole multiples of 360.
double turntable_angle(long frame, double degrees, long frames);

// Loads a .gltf or .glb file (detected by content, not by extension) and validates it completely
// before returning. Throws pmr::Error with one clear line on anything that cannot be rendered.
Scene load_scene(const std::string& path);
// The same under the budgets and confinement of `limits` (docs/SECURITY.md): every file the scene
// names lies inside the scene's folder (unless limits.allow_outside_scene_folder), is a regular file
// within limits.file_bytes, and no texture image over limits.texture_pixels is decoded.
Scene load_scene(const std::string& path, const InputLimits& limits);
// The same with the material variant `variant` (KHR_materials_variants; its name or index, "" = the
// default materials): each primitive that maps it is drawn with its material.
Scene load_scene(const std::string& path, const InputLimits& limits, const std::string& variant);

// World-space axis-aligned bounds of all vertices referenced by triangles. Returns false (lo, hi
// untouched) when there are none.
bool scene_bounds(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi);

// --camera and --variant take a name first; "#K", when nothing has that name, selects the K-th (from 0),
// so that a camera or variant named "1" is never mistaken for an index.
struct IndexChoice {
  bool is_index = false;  // the choice is "#..."
  int index = -1;         // K, when it is an index of one of the `count` things
  std::string problem;    // why "#..." selects none ("" when it does)
};
IndexChoice parse_index_choice(const std::string& choice, size_t count, const std::string& things);
// The end of the message for a choice that names nothing: a hint when it is a bare number.
std::string unnamed_choice_hint(const std::string& choice, const std::string& lister);

// The glTF camera `--camera` names: the camera whose node has that name, else the one whose camera
// object has it, else "#K" its index. Throws pmr::Error when none or several match.
int find_camera(const Scene& scene, const std::string& name);

}  // namespace pmr

namespace pmr {
// The glTF default material: white, opaque, single-sided (used when a primitive has none).
PmrMaterial default_material();
// The reflectance at normal incidence of a dielectric of index of refraction `ior` in air,
// ((ior - 1) / (ior + 1))^2 (KHR_materials_ior): 0.04 for glTF's default 1.5; 1 for ior 0.
float dielectric_f0(double ior);
// Whether a triangle's material transmits (KHR_materials_transmission): pbr then draws glass, with
// the transmission source (DESIGN 4c step 2).
bool scene_transmissive(const Scene& scene);
// Whether a triangle's material is alphaMode BLEND and (with pbr shading) not transmissive: frames then
// composite BLEND layers (DESIGN 4c step 3), which the fused fine raster does not (they keep a volume).
bool scene_blended(const Scene& scene, bool pbr);
// The factors of `in` (as the loader checked them) into the device material `m`; maps are not touched.
void apply_material_inputs(const SceneMaterialInputs& in, PmrMaterial& m);

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
