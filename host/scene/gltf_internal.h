// Private to host/scene: the glTF loader, split by concern.
//   gltf_validate.cpp   the file before tinygltf sees it (reading, GLB container, JSON pre-checks) and
//                       the structure after (reference ranges, bufferView bounds, node hierarchy)
//   gltf_schema.cpp     the schema's minimums and the animation / skin structure on the raw JSON
//   gltf_accessors.cpp  bounds-checked typed reads of accessors (stride, normalization, sparse)
//   gltf_loader.cpp     the tinygltf call, materials and textures, the scene walk, flattening
//
// tinygltf 2.7 parses but checks almost nothing: indices, offsets and counts are taken as written.
// Everything read from the model therefore goes through the checks here first, in 64-bit arithmetic,
// and every failure is a pmr::Error naming the file and the offending element.
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

// Debian ships tinygltf prebuilt (libtinygltf.so): the header only declares, nothing is implemented
// here, and the JSON library is the system nlohmann one.
#define TINYGLTF_NO_INCLUDE_JSON
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "pmr/input_files.h"
#include "scene/motion.h"

namespace pmr::gltf {

// Throws pmr::Error("<file>: <what>").
[[noreturn]] void fail(const std::string& file, const std::string& what);

// Text quoted from the file or a parser made fit for a one-line message: newlines become spaces,
// other control bytes (and with ascii_only, non-ASCII bytes) '?', cut to a few hundred characters.
std::string one_line(const std::string& text, bool ascii_only = false);

// ---- gltf_validate.cpp: before tinygltf ----------------------------------------------------------

// The file as read, after the checks tinygltf does not do (or does too late to give a clear message):
// GLB container layout, JSON syntax and nesting depth, asset.version, extensionsRequired, external
// buffer files. Throws pmr::Error on any of them.
struct SourceFile {
  std::vector<unsigned char> bytes;  // the whole file (a GLB is cut to the length its header gives)
  bool glb = false;                  // detected by the magic bytes, not by the extension
  std::string base_dir;              // directory relative URIs are resolved against
  std::set<int> sampled_images;      // images some material slot samples (base colour, metallic-
                                     // roughness, normal, occlusion, emissive): decoded and read
  std::string checksum;              // of `bytes` as read from disk (before a GLB is cut)
  // External files only unused images name (resolved like tinygltf does): never read
  std::set<std::string> unused_image_files;
  std::vector<std::string> ignored_extensions;  // in extensionsUsed, not implemented (the material
                                                // extensions of material_extension_fallback excepted)
  // KHR_lights_punctual and EXT_lights_area, validated: the file's lights (the punctual ones, then the
  // area lights; unplaced) and per node the lights it places: [0] a punctual one, [1] an area light
  // (indices into `lights`, -1 = none).
  std::vector<SceneLight> lights;
  std::vector<std::array<int, 2>> node_light;
  // The external files tinygltf will ask for (buffers, sampled images), read and checked here: inside
  // the scene's folder (unless allowed outside), regular, within the file-bytes budget. Keyed by the
  // path tinygltf asks for (resolve_uri); `uses` counts the buffers and images that name the file.
  struct External {
    std::vector<unsigned char> bytes;
    int uses = 0;
  };
  std::map<std::string, External> external;
  // Buffers some accessor the loader reads uses (needed_buffers); the others are never read. Those
  // with an external file are handed to tinygltf as one byte: their declared byteLength, per index.
  std::set<int> needed_buffers;
  std::map<int, uint64_t> unread_buffers;
  // KHR_materials_variants: the variants' names, and the one chosen (-1: the default materials)
  std::vector<std::string> variants;
  int variant = -1;
};
// `variant`: --variant, a material variant's name or index ("" = the default materials).
SourceFile read_source(const std::string& path, const InputLimits& limits, const std::string& variant = "");

// KHR_materials_variants (gltf_variants.cpp): the variants' names into src.variants and every
// primitive's mappings checked; with `choice` (a variant's name or index, "" = none) src.variant is set
// and each primitive that maps it takes its material in `doc`. Returns whether `doc` changed. Each
// problem is a one-line pmr::Error.
bool apply_material_variant(const std::string& path, nlohmann::json& doc, const std::string& choice, SourceFile& src);

// For a material extension the renderer does not implement but can draw without (its appearance
// changes, nothing else): what is drawn instead, e.g. "drawn opaque, without transmission". nullptr
// for any other extension.
const char* material_extension_fallback(const std::string& name);

// A member of a JSON object, nullptr when absent or when `object` is not an object.
const nlohmann::json* member(const nlohmann::json& object, const char* key);

// ---- gltf_schema.cpp: the schema's ranges on the raw JSON (called by read_source) -------------------

// Indices, offsets, lengths, counts and strides against the glTF 2.0 schema's minimums, and animations
// and skins completely (references, enums). Throws pmr::Error naming the file and the element.
void check_schema(const std::string& path, const nlohmann::json& doc);

// Percent-decodes a relative URI the way tinygltf does and joins it to base_dir.
std::string resolve_uri(const std::string& base_dir, const std::string& uri);
// The URI's file name as tinygltf decodes it ('+' a space, %XX a byte), relative to the scene's folder.
std::string decode_uri(const std::string& uri);

// ---- texture_decode.cpp -------------------------------------------------------------------------------

// Decodes a PNG or JPEG into `image` as tinygltf's own loader does (4 channels of 8 or 16 bits, rows
// top first) after reading its header: an image of more than `max_pixels` pixels, or whose decoded
// bytes exceed `memory_left` (what the memory budget leaves the decoded images), is not decoded and sets
// `over_limit`. Returns "" when decoded, else why not.
std::string decode_image(tinygltf::Image& image, const unsigned char* bytes, int size, uint64_t max_pixels,
                         uint64_t memory_left, bool& over_limit);

// ---- gltf_validate.cpp: after tinygltf ------------------------------------------------------------

// Checks every cross reference the loader follows (scene -> node -> mesh -> accessor / material ->
// texture -> image / sampler, node -> camera), that each bufferView lies inside its buffer, and that
// the nodes form a forest (no cycle, at most one parent). Returns each node's parent (-1 = root).
// Buffers in `unread_buffers` (SourceFile) are checked against their declared byteLength.
std::vector<int> validate_model(const tinygltf::Model& model, const std::map<int, uint64_t>& unread_buffers,
                                const std::string& file);

// Root nodes of the scene to render: the default scene (scene 0 when none is named) or, with no
// scenes at all, every node without a parent.
std::vector<int> scene_roots(const tinygltf::Model& model, const std::vector<int>& parent, const std::string& file);

// The node's rest transform (matrix, or T, R, S with R normalized), checked for size and finiteness.
// Morph weights are not filled in.
MotionNode node_transform(const tinygltf::Node& node, int index, const std::string& file);

// ---- gltf_motion.cpp ---------------------------------------------------------------------------------

// Nodes (rest transforms, default morph weights, parents before children), clips and skins. Camera
// nodes and deformable instances are filled in by the loader's walk.
std::shared_ptr<SceneMotion> read_motion(const tinygltf::Model& model, const std::vector<int>& parent,
                                         const std::string& file);
// Per node: whether some clip's translation, rotation or scale channel moves it or an ancestor.
std::vector<bool> moving_nodes(const SceneMotion& motion);

// ---- gltf_accessors.cpp ----------------------------------------------------------------------------

enum class Semantic {
  Position,
  Normal,
  Tangent,
  Texcoord,
  Color,
  Indices,
  KeyTimes,
  AnimationOutput,
  Joints,
  Weights,
  InverseBind,
  MorphDelta
};

// One vertex attribute, decoded to float (normalized integers mapped per the glTF spec), sparse
// substitutions applied. values.size() == count * components.
struct AttributeData {
  size_t count = 0;
  int components = 0;
  std::vector<float> values;
};

// `what` names the use for messages, e.g. "POSITION of mesh 0 primitive 1". Checks the type and
// component type against what the semantic allows (core glTF plus KHR_mesh_quantization).
AttributeData read_attribute(const tinygltf::Model& model, int accessor, Semantic semantic, const std::string& what,
                             const std::string& file);

// Runs the checks of read_attribute / read_indices (type, component type, bounds) without reading, so
// that counts can be trusted before anything is allocated from them.
void check_accessor(const tinygltf::Model& model, int accessor, Semantic semantic, const std::string& what,
                    const std::string& file);

// Bytes the accessor takes decoded (4 per component: float, or uint32 for indices), from its count
// alone; 0 for an index out of range.
uint64_t decoded_bytes(const tinygltf::Model& model, int accessor);

// A SCALAR u8 / u16 / u32 index accessor. Values are not range-checked here (the caller knows the
// vertex count).
std::vector<uint32_t> read_indices(const tinygltf::Model& model, int accessor, const std::string& what,
                                   const std::string& file);

}  // namespace pmr::gltf
