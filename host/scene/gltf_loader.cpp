// load_scene: a glTF 2.0 file flattened into world-space triangles (DESIGN sections 1 and 4).
//
// Order of work: read_source() checks the file and its JSON before tinygltf parses it (so that Draco,
// unknown required extensions, truncated GLBs and missing buffers get clear messages), tinygltf parses,
// validate_model() checks every reference the walk follows, then the default scene is walked and each
// mesh instance is emitted with its node's world matrix. Only images some implemented material slot
// samples are decoded (base colour, metallic-roughness, normal, occlusion, emissive).
#include <algorithm>
#include <array>
#include <cmath>
#include <new>
#include <cstring>
#include <limits>
#include <map>

#include "output/checksum.h"
#include "pmr/error.h"
#include "pmr/memory_budget.h"
#include "pmr/printable.h"
#include "pmr/scene.h"
#include "scene/gltf_internal.h"
#include "scene/gltf_loader_state.h"

namespace pmr {
namespace {

using namespace gltf;

// ---- tinygltf callbacks ------------------------------------------------------------------------------

struct FsContext {
  std::string prefix;                                               // base_dir with a trailing '/'
  std::map<std::string, SourceFile::External>* external = nullptr;  // read_source's reads: all tinygltf gets
  const std::set<std::string>* skip = nullptr;                      // files only unused images name: not read
  std::map<std::string, std::string> read;  // path relative to base_dir -> checksum of the bytes read
};

// tinygltf looks for external files in base_dir and then in the working directory. It gets exactly the
// files read_source() read and checked (inside the scene's folder, regular, within the budget), and
// the files of unused images as empty (tinygltf then warns "File is empty", which the loader ignores,
// and the image stays undecoded as it would anyway): nothing else, so it never opens a file itself.
bool fs_exists(const std::string& path, void* user) {
  const auto* ctx = static_cast<const FsContext*>(user);
  return ctx->external->count(path) > 0 || ctx->skip->count(path) > 0;
}

std::string fs_expand(const std::string& path, void*) { return path; }

// Every file read is checksummed from the bytes read (the sidecar lists them). The bytes move to
// tinygltf on the last use of a file that several buffers or images name.
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto* ctx = static_cast<FsContext*>(user);
  out->clear();
  auto it = ctx->external->find(path);
  if (it == ctx->external->end()) {
    if (!ctx->skip->count(path) && err) *err += "not read: " + path + "\n";
    return ctx->skip->count(path) > 0;
  }
  SourceFile::External& e = it->second;
  const std::string relative = path.substr(std::min(path.size(), ctx->prefix.size()));
  if (!ctx->read.count(relative)) ctx->read[relative] = checksum_hex(e.bytes.data(), e.bytes.size());
  if (--e.uses > 0) *out = e.bytes;
  else out->swap(e.bytes);
  return true;
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is disabled\n";
  return false;
}

// Decodes (texture_decode.cpp) but never fails the load: an undecodable image is a warning and an
// untextured material, and an image over the texture-pixels budget an error once tinygltf returns.
// Also checks what tinygltf does not: a GLB image's bufferView must lie inside its buffer before its
// bytes are read.
bool load_image(tinygltf::Image* image, int index, std::string*, std::string*, int, int, const unsigned char* bytes,
                int size, void* user) {
  auto* ctx = static_cast<ImageContext*>(user);
  if (!ctx->wanted->count(index) || !ctx->over_limit.empty()) return true;  // never sampled: skip the decode
  if (image->bufferView >= 0) {
    const tinygltf::Model& m = *ctx->model;
    bool inside = size_t(image->bufferView) < m.bufferViews.size();
    if (inside) {
      const tinygltf::BufferView& bv = m.bufferViews[size_t(image->bufferView)];
      uint64_t end = 0;
      inside = size_t(bv.buffer) < m.buffers.size() && !__builtin_add_overflow(bv.byteOffset, bv.byteLength, &end) &&
               end <= m.buffers[size_t(bv.buffer)].data.size() && bv.byteLength <= uint64_t(INT32_MAX);
    }
    if (!inside) {
      ctx->failures[index] = "its bufferView " + std::to_string(image->bufferView) + " lies outside the buffer";
      return true;
    }
  }
  if (size <= 0 || !bytes) {
    ctx->failures[index] = "the image data is empty";
    return true;
  }
  bool over = false;
  const std::string why = decode_image(*image, bytes, size, ctx->max_pixels, ctx->memory_left, over);
  if (why.empty()) ctx->memory_left -= std::min<uint64_t>(ctx->memory_left, image->image.size());
  if (over) {
    const std::string name = image->uri.empty() || image->uri.rfind("data:", 0) == 0 ? image->name : image->uri;
    ctx->over_limit = "image " + std::to_string(index) + (name.empty() ? "" : " '" + one_line(name) + "'") + ": " + why;
  } else if (!why.empty()) {
    ctx->failures[index] = one_line(why);
  }
  if (!why.empty()) {
    image->image.clear();
    image->width = image->height = 0;
  }
  return true;
}

// `files_read` receives the files read besides the scene file (relative path -> checksum).
void load_model(const std::string& path, SourceFile& src, tinygltf::Model& model, ImageContext& images,
                std::map<std::string, std::string>& files_read) {
  FsContext fs;
  fs.prefix = src.base_dir.back() == '/' ? src.base_dir : src.base_dir + "/";
  fs.external = &src.external;
  fs.skip = &src.unused_image_files;
  images.model = &model;
  images.wanted = &src.sampled_images;
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&fs_exists, &fs_expand, &fs_read, &fs_write, &fs});
  loader.SetImageLoader(&load_image, &images);
  std::string err, warn;
  bool ok = false;
  try {
    // The bytes were already read and checked by read_source(); parse them from memory.
    if (src.glb)
      ok = loader.LoadBinaryFromMemory(&model, &err, &warn, src.bytes.data(), unsigned(src.bytes.size()), src.base_dir);
    else
      ok = loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(src.bytes.data()),
                                      unsigned(src.bytes.size()), src.base_dir);
  } catch (const std::bad_alloc&) {  // not the file's fault: say so, not "not a valid glTF file"
    fail(path, "out of host memory while parsing it (" + std::to_string(src.bytes.size()) + " bytes)");
  } catch (const std::exception& e) {  // nlohmann type errors on odd JSON
    fail(path, "not a valid glTF file: " + one_line(e.what()));
  }
  if (!ok) {
    const std::string msg = one_line(err.empty() ? warn : err);
    fail(path, "not a valid glTF file: " + (msg.empty() ? std::string("tinygltf gave no reason") : msg));
  }
  if (!images.over_limit.empty()) fail(path, images.over_limit);
  files_read = std::move(fs.read);
}

// Animation keys are decoded per sampler, so samplers sharing one accessor each count in full: the
// sum is checked before any is read.
void check_animation_budget(const tinygltf::Model& model, const InputLimits& limits, const std::string& path) {
  uint64_t bytes = 0;
  for (const tinygltf::Animation& a : model.animations)
    for (const tinygltf::AnimationSampler& smp : a.samplers)
      for (const int accessor : {smp.input, smp.output})
        if (__builtin_add_overflow(bytes, decoded_bytes(model, accessor), &bytes)) bytes = UINT64_MAX;
  if (bytes > limits.animation_data)
    fail(path, "the animations' samplers decode to " + std::to_string(bytes) +
                   " bytes of keys (every sampler "
                   "counted), more than the animation-data limit of " +
                   std::to_string(limits.animation_data) + " (raise it with --limit animation-data=N)");
  check_memory(bytes, "decoding the animations' keys");
}

// ---- scene walk and primitives ---------------------------------------------------------------------------

struct Instance {
  int mesh;
  int node;
};

// The glTF camera a node places: the first node placing a camera gives its entry (same index) its pose
// and name; every further node placing it gets an entry of its own, after the file's cameras, so that
// each camera node can drive the rig (Blender exports camera objects sharing their data this way).
void place_camera(Loader& L, const tinygltf::Node& node, int index, const glm::dmat4& world) {
  SceneCamera* cam = &L.scene.cameras[size_t(node.camera)];
  if (cam->placed) {
    const SceneCamera shared = *cam;
    L.scene.cameras.push_back(shared);
    L.motion->camera_node.push_back(-1);
    cam = &L.scene.cameras.back();
    cam->shared_with = node.camera;
  }
  cam->placed = true;
  cam->world_from_camera = world;
  cam->node_name = node.name;
  L.motion->camera_node[size_t(cam - L.scene.cameras.data())] = index;
}

// Pre-order walk, children in their listed order: the instances in the order they are emitted, and
// the cameras' nodes (place_camera, in this order).
std::vector<Instance> walk(Loader& L, const std::vector<int>& roots) {
  std::vector<Instance> instances;
  std::vector<int> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const int index = stack.back();
    stack.pop_back();
    const tinygltf::Node& node = L.model.nodes[size_t(index)];
    const glm::dmat4& world = L.rest_world[size_t(index)];
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(world[c][r]))
          fail(L.file, "node " + std::to_string(index) + " has a world matrix that overflows");
    if (node.mesh >= 0) instances.push_back({node.mesh, index});
    for (const int light : (*L.node_light)[size_t(index)]) {
      if (light < 0) continue;
      SceneLight l = (*L.light_defs)[size_t(light)];
      l.node = index;
      l.node_name = node.name;
      if (!place_light(l, world))
        L.warn("node " + std::to_string(index) +
               " places a light with a degenerate matrix (zero scale?): shining along -Z");
      L.scene.lights.push_back(l);
      L.motion->light_node.push_back(index);
    }
    if (node.camera >= 0) place_camera(L, node, index, world);
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back(*c);
  }
  return instances;
}

size_t walk_count(const Loader& L, const std::vector<int>& roots) {
  size_t n = 0;
  std::vector<int> stack(roots.begin(), roots.end());
  while (!stack.empty()) {
    const tinygltf::Node& node = L.model.nodes[size_t(stack.back())];
    stack.pop_back();
    n += node.mesh >= 0;
    stack.insert(stack.end(), node.children.begin(), node.children.end());
  }
  return n;
}

// One primitive decoded in its mesh's space, shared by all instances of the mesh.
struct Decoded {
  std::shared_ptr<DeformSource> geo;     // positions, normals, morph targets, joints and weights
  std::vector<float> col;                // COLOR_0, empty when absent
  // TEXCOORD_k as stored, by k: the sets its material samples, and TEXCOORD_0 for an anisotropic
  // material's tangents
  std::map<int, std::vector<float>> sets;
  std::vector<uint32_t> tris;            // 3 local vertex indices per triangle, as authored (CCW front)
  uint32_t material = 0;                 // Scene::materials index
};

const int* attribute(const tinygltf::Primitive& p, const std::string& name) {
  auto it = p.attributes.find(name);
  return it == p.attributes.end() ? nullptr : &it->second;
}

// decode_primitive's reads: every attribute, and every morph target's, must hold one value per POSITION
// vertex, as the deformer indexes them all by vertex.
struct PrimitiveAttributes {
  Loader& L;
  const tinygltf::Primitive& p;
  const std::string& where;
  size_t vertices;

  // Empty when absent.
  std::vector<float> read_from(const std::map<std::string, int>& attributes, const std::string& name, Semantic semantic,
                               const std::string& label) const {
    const auto it = attributes.find(name);
    if (it == attributes.end()) return {};
    const int a = it->second;
    AttributeData data = read_attribute(L.model, a, semantic, label, L.file);
    if (data.count != vertices)
      fail(L.file, "accessor " + std::to_string(a) + " (" + label + ") has " + std::to_string(data.count) +
                       " elements but POSITION has " + std::to_string(vertices));
    return std::move(data.values);
  }

  std::vector<float> read(const std::string& name, Semantic semantic) const {
    std::vector<float> values = read_from(p.attributes, name, semantic, name + " of " + where);
    if (values.empty()) return values;
    if (semantic == Semantic::Color && values.size() == vertices * 3) {  // RGB -> RGBA, alpha 1
      std::vector<float> rgba(vertices * 4, 1.0f);
      for (size_t v = 0; v < vertices; ++v) std::copy_n(&values[3 * v], 3, &rgba[4 * v]);
      return rgba;
    }
    return values;
  }

  std::vector<float> read_target(size_t k, const std::string& name) const {
    return read_from(p.targets[k], name, Semantic::MorphDelta,
                     name + " of " + where + " morph target " + std::to_string(k));
  }
};

// JOINTS_0 / WEIGHTS_0, then _1: four influences each, merged per vertex (non-finite or negative
// weights count as 0).
void read_skin_influences(const PrimitiveAttributes& attrs, DeformSource& geo) {
  for (int set = 0; set < 2; ++set) {
    const std::string n = std::to_string(set);
    std::vector<float> joints = attrs.read("JOINTS_" + n, Semantic::Joints),
                       weights = attrs.read("WEIGHTS_" + n, Semantic::Weights);
    if (joints.empty() || weights.empty()) break;
    const int k = geo.influences + 4;
    std::vector<uint16_t> j(geo.vertices * size_t(k));
    std::vector<float> w(geo.vertices * size_t(k));
    for (size_t v = 0; v < geo.vertices; ++v)
      for (int i = 0; i < k; ++i) {
        const bool old = i < geo.influences;
        j[v * size_t(k) + size_t(i)] = old ? geo.joints[v * size_t(geo.influences) + size_t(i)]
                                           : uint16_t(joints[4 * v + size_t(i - geo.influences)]);
        const float wv =
            old ? geo.weights[v * size_t(geo.influences) + size_t(i)] : weights[4 * v + size_t(i - geo.influences)];
        w[v * size_t(k) + size_t(i)] = std::isfinite(wv) && wv > 0.0f ? wv : 0.0f;
      }
    geo.joints = std::move(j), geo.weights = std::move(w), geo.influences = k;
  }
}

// Every set a texture slot of the material samples, untransformed (Scene::texcoords); each must exist.
// Returns the set the tangents follow (-1: none): the normal texture's, else the clear coat normal
// texture's, else the anisotropy texture's (the maps share the vertex's one tangent), else TEXCOORD_0
// for an anisotropic material when the primitive has it.
int read_texcoord_sets(const PrimitiveAttributes& attrs, int mesh, int index, Decoded& d) {
  Loader& L = attrs.L;
  const tinygltf::Primitive& p = attrs.p;
  if (p.material < 0) return -1;
  const std::array<int, kTextureSlots>& sets = L.slot_sets[size_t(p.material)];
  for (int slot = 0; slot < kTextureSlots; ++slot) {
    const int k = sets[size_t(slot)];
    if (k < 0 || d.sets.count(k)) continue;
    std::vector<float>& values = d.sets[k] = attrs.read("TEXCOORD_" + std::to_string(k), Semantic::Texcoord);
    if (values.empty()) {
      const std::string& mesh_name = L.model.meshes[size_t(mesh)].name;
      const std::string& mat_name = L.model.materials[size_t(p.material)].name;
      fail(L.file, "material " + std::to_string(p.material) +
                       (mat_name.empty() ? "" : " '" + one_line(mat_name, true) + "'") + " " + texture_slot_name(slot) +
                       " samples TEXCOORD_" + std::to_string(k) + ", which mesh " + std::to_string(mesh) +
                       (mesh_name.empty() ? "" : " '" + one_line(mesh_name, true) + "'") + " primitive " +
                       std::to_string(index) + " does not have");
    }
  }
  for (int slot : {kSlotNormal, kSlotClearcoatNormal, kSlotAnisotropy})
    if (sets[size_t(slot)] >= 0) return sets[size_t(slot)];
  if (L.scene.material_inputs[size_t(p.material) + 1].anisotropy_strength <= 0.0f) return -1;
  if (!d.sets.count(0)) d.sets[0] = attrs.read("TEXCOORD_0", Semantic::Texcoord);
  return d.sets[0].empty() ? -1 : 0;
}

// 3 vertex indices per triangle, strips and fans unrolled, each index checked against POSITION.
std::vector<uint32_t> triangle_list(Loader& L, const tinygltf::Primitive& p, int mode, const std::string& where,
                                    size_t vertices) {
  std::vector<uint32_t> indices;
  if (p.indices >= 0) {
    const std::string what = "indices of " + where;
    indices = read_indices(L.model, p.indices, what, L.file);
    for (uint32_t i : indices)
      if (i >= vertices)
        fail(L.file, "accessor " + std::to_string(p.indices) + " (" + what + ") reads index " + std::to_string(i) +
                         " but POSITION has " + std::to_string(vertices) + " vertices");
  }
  const size_t n = p.indices >= 0 ? indices.size() : vertices;
  auto at = [&](size_t k) { return p.indices >= 0 ? indices[k] : uint32_t(k); };
  const size_t triangles = mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : n >= 3 ? n - 2 : 0;  // < 2^27: check_totals
  std::vector<uint32_t> tris;
  tris.reserve(3 * triangles);
  for (size_t k = 0; k < triangles; ++k) {
    uint32_t t[3];
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      t[0] = at(3 * k), t[1] = at(3 * k + 1), t[2] = at(3 * k + 2);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {  // every other triangle is reversed to stay CCW
      t[0] = at(k), t[1] = at(k + 1 + k % 2), t[2] = at(k + 2 - k % 2);
    } else {  // fan around vertex 0, in the spec's order
      t[0] = at(k + 1), t[1] = at(k + 2), t[2] = at(0);
    }
    tris.insert(tris.end(), t, t + 3);
  }
  if (mode == TINYGLTF_MODE_TRIANGLES && n % 3 != 0) ++L.leftover_indices;
  return tris;
}

// Tangents for a normal texture: the file's (morphed by its TANGENT targets), else generated from the
// normal texture's UV set at the rest shape.
void read_tangents(const PrimitiveAttributes& attrs, Decoded& d, int normal_set) {
  DeformSource& geo = *d.geo;
  geo.tan = attrs.read("TANGENT", Semantic::Tangent);
  if (!geo.tan.empty()) {
    for (size_t k = 0; k < attrs.p.targets.size(); ++k) geo.target_tan.push_back(attrs.read_target(k, "TANGENT"));
  } else {
    geo.tan = generate_tangents(geo.pos, geo.nrm, d.sets.at(normal_set), d.tris);
    ++attrs.L.generated_tangents;
  }
}

Decoded decode_primitive(Loader& L, int mesh, int index) {
  const tinygltf::Primitive& p = L.model.meshes[size_t(mesh)].primitives[size_t(index)];
  const std::string where = "mesh " + std::to_string(mesh) + " primitive " + std::to_string(index);
  Decoded d;
  const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    ++L.point_line_primitives;
    return d;
  }
  const int* position = attribute(p, "POSITION");
  if (!position) {
    L.warn(where + " has no POSITION attribute; skipped");
    return d;
  }
  if (p.material >= 0) L.used_materials.insert(p.material);
  d.material = p.material >= 0 ? uint32_t(p.material + 1) : 0u;
  AttributeData pos = read_attribute(L.model, *position, Semantic::Position, "POSITION of " + where, L.file);
  d.geo = std::make_shared<DeformSource>();
  DeformSource& geo = *d.geo;
  geo.vertices = pos.count;
  geo.pos = std::move(pos.values);
  const PrimitiveAttributes attrs{L, p, where, geo.vertices};
  geo.nrm = attrs.read("NORMAL", Semantic::Normal);
  for (size_t k = 0; k < p.targets.size(); ++k) {
    geo.target_pos.push_back(attrs.read_target(k, "POSITION"));
    geo.target_nrm.push_back(attrs.read_target(k, "NORMAL"));
  }
  read_skin_influences(attrs, geo);
  const int normal_set = read_texcoord_sets(attrs, mesh, index, d);
  d.col = attrs.read("COLOR_0", Semantic::Color);
  d.tris = triangle_list(L, p, mode, where, geo.vertices);
  if (normal_set >= 0) read_tangents(attrs, d, normal_set);
  return d;
}

// Appends one instance at its rest pose: morph targets with the node's default weights, then the skin at
// its skeleton's rest transforms or the node's world matrix; winding reversed under a mirroring matrix
// so that counter-clockwise stays the front face. Records the instance as deformable when a clip can
// move it.
void emit(Loader& L, const Decoded& d, const Instance& inst) {
  Scene& s = L.scene;
  const size_t ntri = d.tris.size() / 3;
  if (ntri == 0) return;  // (totals were checked by check_totals)
  const DeformSource& geo = *d.geo;
  int skin = L.model.nodes[size_t(inst.node)].skin;
  if (skin >= 0 && geo.influences == 0) {
    L.skins_without_joints.insert(inst.mesh);
    skin = -1;
  }
  if (skin >= 0) {
    const size_t joints = L.motion->skins[size_t(skin)].joints.size();
    for (uint16_t j : geo.joints)
      if (j >= joints)
        fail(L.file, "mesh " + std::to_string(inst.mesh) + " has a JOINTS value " + std::to_string(j) + " but skin " +
                         std::to_string(skin) + " has " + std::to_string(joints) + " joints");
  }
  const glm::dmat4& world = L.rest_world[size_t(inst.node)];
  const bool mirrored = skin < 0 && glm::determinant(glm::dmat3(world)) < 0.0;
  const uint32_t base = uint32_t(s.positions.size());
  const uint32_t first_triangle = uint32_t(s.triangles.size());
  s.positions.resize(base + geo.vertices);
  s.attributes.resize(base + geo.vertices);
  std::vector<uint8_t> bad_position(geo.vertices, 0), bad_normal(geo.vertices, 0);
  if (!geo.tan.empty() || !s.tangents.empty()) s.tangents.resize(s.positions.size(), glm::vec4(0.0f));
  deform(geo, L.motion->nodes[size_t(inst.node)].weights, skin >= 0 ? L.rest_joints[size_t(skin)].data() : nullptr,
         world, &s.positions[base], &s.attributes[base], bad_position.data(), bad_normal.data(),
         geo.tan.empty() ? nullptr : &s.tangents[base]);
  s.texcoords.resize(L.texcoord_index.size());
  for (std::vector<glm::vec2>& set : s.texcoords) set.resize(s.positions.size(), glm::vec2(0.0f));
  for (const auto& [k, values] : d.sets) {
    const auto index = L.texcoord_index.find(k);
    if (values.empty() || index == L.texcoord_index.end()) continue;  // read for tangents only
    std::vector<glm::vec2>& set = s.texcoords[size_t(index->second)];
    for (size_t v = 0; v < geo.vertices; ++v) {
      glm::vec2 t(values[2 * v], values[2 * v + 1]);
      if (!std::isfinite(t.x) || !std::isfinite(t.y)) t = glm::vec2(0.0f), ++L.nonfinite_attributes;
      set[base + v] = t;
    }
  }
  for (size_t v = 0; v < geo.vertices; ++v) {
    PmrVertexAttr& a = s.attributes[base + v];
    for (int c = 0; c < 4; ++c) {
      a.color[c] = d.col.empty() ? 1.0f : d.col[4 * v + size_t(c)];
      if (!std::isfinite(a.color[c])) a.color[c] = 1.0f, ++L.nonfinite_attributes;
    }
  }
  for (size_t t = 0; t < ntri; ++t) {
    uint32_t v[3] = {d.tris[3 * t], d.tris[3 * t + 1], d.tris[3 * t + 2]};
    if (mirrored) std::swap(v[1], v[2]);
    if (bad_position[v[0]] || bad_position[v[1]] || bad_position[v[2]]) {
      ++L.skipped_triangles;
      continue;
    }
    PmrTriangle tri{};
    for (int c = 0; c < 3; ++c) tri.v[c] = base + v[c];
    tri.material = d.material;
    const glm::vec3 n = face_normal(s.positions[tri.v[0]], s.positions[tri.v[1]], s.positions[tri.v[2]]);
    tri.face_normal[0] = n.x, tri.face_normal[1] = n.y, tri.face_normal[2] = n.z;
    tri.has_normals = !geo.nrm.empty() && !bad_normal[v[0]] && !bad_normal[v[1]] && !bad_normal[v[2]];
    s.triangles.push_back(tri);
  }
  bool moves = L.weights_animated[size_t(inst.node)] || (skin < 0 && L.moving[size_t(inst.node)]);
  if (skin >= 0)
    for (int j : L.motion->skins[size_t(skin)].joints) moves = moves || L.moving[size_t(j)];
  if (moves) {
    Deformable dm;
    dm.node = inst.node;
    dm.skin = skin;
    dm.source = d.geo;
    dm.vertex_begin = base;
    dm.triangle_begin = first_triangle;
    dm.triangle_end = uint32_t(s.triangles.size());
    dm.rest_mirrored = mirrored;
    L.motion->deformables.push_back(std::move(dm));
  }
}

// Triangles and vertices a primitive will produce, from its accessor counts alone (after checking
// that those accessors fit in their bufferViews, which bounds the counts by the file's data).
std::pair<uint64_t, uint64_t> primitive_size(const Loader& L, int mesh, int index) {
  const tinygltf::Primitive& p = L.model.meshes[size_t(mesh)].primitives[size_t(index)];
  const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  const int* position = attribute(p, "POSITION");
  if (!position || mode < TINYGLTF_MODE_TRIANGLES) return {0, 0};
  const std::string where = " of mesh " + std::to_string(mesh) + " primitive " + std::to_string(index);
  check_accessor(L.model, *position, Semantic::Position, "POSITION" + where, L.file);
  if (p.indices >= 0) check_accessor(L.model, p.indices, Semantic::Indices, "indices" + where, L.file);
  const uint64_t vertices = L.model.accessors[size_t(*position)].count;
  const uint64_t n = p.indices >= 0 ? L.model.accessors[size_t(p.indices)].count : vertices;
  const uint64_t triangles = mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : n >= 3 ? n - 2 : 0;
  return {triangles, triangles ? vertices : 0};
}

// Bytes decode_primitive allocates for a primitive of `triangles` triangles: every accessor it names
// decoded (attributes, each morph target's, indices) and its triangle list. Each morph target counts
// in full even when all of them name one accessor, as each is decoded into its own array.
uint64_t primitive_data_bytes(const Loader& L, int mesh, int index, uint64_t triangles) {
  if (triangles == 0) return 0;
  const tinygltf::Primitive& p = L.model.meshes[size_t(mesh)].primitives[size_t(index)];
  uint64_t bytes = 12 * triangles;
  auto add = [&](uint64_t b) {
    if (__builtin_add_overflow(bytes, b, &bytes)) bytes = UINT64_MAX;
  };
  for (const auto& [name, accessor] : p.attributes) add(decoded_bytes(L.model, accessor));
  for (const auto& target : p.targets)
    for (const auto& [name, accessor] : target) add(decoded_bytes(L.model, accessor));
  if (p.indices >= 0) add(decoded_bytes(L.model, p.indices));
  return bytes;
}

// The TEXCOORD sets the drawn primitives' materials sample, numbered in increasing set order
// (L.texcoord_index), and every material slot pointed at its set's number (-1: no drawn primitive
// samples it). Returns how many there are: each costs 8 bytes per vertex of the scene.
uint64_t assign_texcoord_sets(Loader& L, const std::vector<Instance>& instances) {
  std::set<int> meshes, sets;
  for (const Instance& inst : instances) meshes.insert(inst.mesh);
  for (int mesh : meshes)
    for (const tinygltf::Primitive& p : L.model.meshes[size_t(mesh)].primitives)
      if (p.material >= 0)
        for (int k : L.slot_sets[size_t(p.material)])
          if (k >= 0) sets.insert(k);
  for (int k : sets) L.texcoord_index.emplace(k, int(L.texcoord_index.size()));
  for (size_t m = 1; m < L.scene.material_inputs.size(); ++m)
    for (SceneTextureSlot& slot : L.scene.material_inputs[m].slots) {
      const auto index = L.texcoord_index.find(slot.texcoord_set);
      slot.texcoord = slot.texture >= 0 && index != L.texcoord_index.end() ? index->second : -1;
    }
  return sets.size();
}

// Sums the whole scene before anything is decoded: a small file instancing a big mesh many times must
// fail here, not after allocating gigabytes. The vertex cap is what the triangle cap can reference.
void check_totals(Loader& L, const std::vector<Instance>& instances) {
  struct Size {
    uint64_t triangles = 0, vertices = 0, data = 0;  // data: primitive_data_bytes
  };
  auto add = [](uint64_t& sum, uint64_t v) {
    if (__builtin_add_overflow(sum, v, &sum)) sum = UINT64_MAX;
  };
  std::map<int, Size> mesh_size;
  uint64_t triangles = 0, vertices = 0, data = 0;
  for (const Instance& inst : instances) {
    auto it = mesh_size.find(inst.mesh);
    if (it == mesh_size.end()) {
      Size sum;
      for (size_t p = 0; p < L.model.meshes[size_t(inst.mesh)].primitives.size(); ++p) {
        const auto [t, v] = primitive_size(L, inst.mesh, int(p));
        add(sum.triangles, t);
        add(sum.vertices, v);
        add(sum.data, primitive_data_bytes(L, inst.mesh, int(p), t));
      }
      it = mesh_size.emplace(inst.mesh, sum).first;
    }
    add(triangles, it->second.triangles);
    add(vertices, it->second.vertices);
    add(data, it->second.data);  // per instance: each is emitted from its own decoded copy's worth
  }
  if (data > L.limits->vertex_data)
    fail(L.file, "the scene's meshes decode to " + std::to_string(data) +
                     " bytes of vertex data (every instance and "
                     "morph target counted), more than the vertex-data limit of " +
                     std::to_string(L.limits->vertex_data) + " (raise it with --limit vertex-data=N)");
  // What the flattened scene holds per vertex and triangle (positions, attributes, the texture
  // coordinate sets drawn materials sample, tangents; triangles), on top of the decoded data.
  const uint64_t sets = assign_texcoord_sets(L, instances);
  const uint64_t per_vertex =
      sizeof(glm::vec3) + sizeof(PmrVertexAttr) + sets * sizeof(glm::vec2) + sizeof(glm::vec4);
  uint64_t scene_bytes = data, flattened = 0;
  if (vertices < (uint64_t(1) << 40) && !__builtin_mul_overflow(vertices, per_vertex, &flattened)) {
    add(scene_bytes, flattened);
    add(scene_bytes, triangles * sizeof(PmrTriangle));
  } else {
    scene_bytes = UINT64_MAX;
  }
  const uint64_t max_triangles = PMR_MAX_TRIANGLES - 1, max_vertices = 3 * max_triangles;
  if (triangles > max_triangles)
    fail(L.file, "the scene has " + std::to_string(triangles) + " triangles; the renderer supports at most " +
                     std::to_string(max_triangles));
  if (vertices > max_vertices)
    fail(L.file, "the scene has " + std::to_string(vertices) + " vertices; the renderer supports at most " +
                     std::to_string(max_vertices));
  check_memory(scene_bytes, "loading the scene's " + std::to_string(triangles) + " triangles");
  L.scene.triangles.reserve(size_t(triangles));
  L.scene.positions.reserve(size_t(vertices));
  L.scene.attributes.reserve(size_t(vertices));
}

void emit_instances(Loader& L, const std::vector<Instance>& instances) {
  check_totals(L, instances);
  // Decode each mesh once and keep it only while instances of it remain.
  std::map<int, size_t> remaining;
  for (const Instance& i : instances) ++remaining[i.mesh];
  std::map<int, std::vector<Decoded>> cache;
  for (const Instance& inst : instances) {
    auto it = cache.find(inst.mesh);
    if (it == cache.end()) {
      std::vector<Decoded> prims;
      const size_t count = L.model.meshes[size_t(inst.mesh)].primitives.size();
      for (size_t p = 0; p < count; ++p) prims.push_back(decode_primitive(L, inst.mesh, int(p)));
      const auto& mp = L.model.meshes[size_t(inst.mesh)].primitives;
      for (size_t p = 1; p < count; ++p)
        if (mp[p].targets.size() != mp[0].targets.size())
          fail(L.file, "mesh " + std::to_string(inst.mesh) + " primitive " + std::to_string(p) + " has " +
                           std::to_string(mp[p].targets.size()) + " morph targets but primitive 0 has " +
                           std::to_string(mp[0].targets.size()));
      it = cache.emplace(inst.mesh, std::move(prims)).first;
    }
    for (const Decoded& d : it->second) emit(L, d, inst);
    if (--remaining[inst.mesh] == 0) cache.erase(it);
  }
}

void build_cameras(Loader& L) {
  for (const tinygltf::Camera& c : L.model.cameras) {
    SceneCamera sc;
    sc.name = c.name;
    sc.perspective = c.type == "perspective";
    if (sc.perspective) {
      sc.yfov = c.perspective.yfov;
      sc.znear = c.perspective.znear;
      sc.zfar = c.perspective.zfar;
      sc.aspect = c.perspective.aspectRatio;
    }
    L.scene.cameras.push_back(sc);
  }
}

// Why a perspective camera's parameters cannot drive the rig, or empty.
std::string camera_problem(const SceneCamera& c) {
  const double pi = 3.14159265358979323846;
  if (!(std::isfinite(c.yfov) && c.yfov > 0 && c.yfov < pi)) return "its yfov must lie between 0 and pi radians";
  if (!(std::isfinite(c.znear) && c.znear > 0)) return "its znear must be positive";
  if (!(std::isfinite(c.zfar) && (c.zfar == 0 || c.zfar > c.znear))) return "its zfar must be 0 or beyond znear";
  if (!(std::isfinite(c.aspect) && c.aspect >= 0)) return "its aspectRatio must be 0 or positive";
  return std::string();
}

// A perspective camera with unusable parameters cannot drive the rig: it says why, with a warning.
void check_cameras(Loader& L) {
  for (size_t i = 0; i < L.scene.cameras.size(); ++i) {
    SceneCamera& c = L.scene.cameras[i];
    if (!c.placed || !c.perspective) continue;
    c.invalid = camera_problem(c);
    if (!c.invalid.empty())
      L.warn("camera " + std::to_string(i) + " has invalid perspective parameters (" + c.invalid + "); ignored");
  }
}

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& i : items) s += (s.empty() ? "" : ", ") + i;
  return s;
}

void summary_warnings(Loader& L, const SourceFile& src) {
  if (!src.ignored_extensions.empty())
    L.warn("extensions used but not implemented, ignored: " + join(src.ignored_extensions));
  for (int mesh : L.skins_without_joints)
    L.warn("mesh " + std::to_string(mesh) + " is skinned but has no JOINTS_0 / WEIGHTS_0: drawn unskinned");
  if (L.point_line_primitives)
    L.warn(std::to_string(L.point_line_primitives) + " point or line primitive(s) skipped: only triangles are drawn");
  if (L.leftover_indices)
    L.warn("TRIANGLES primitive(s) with a vertex count not divisible by 3: extra vertices ignored");
  if (L.skipped_triangles)
    L.warn(std::to_string(L.skipped_triangles) + " triangle(s) with non-finite vertex positions skipped");
  if (L.nonfinite_attributes) L.warn("non-finite texture coordinates or colours replaced by defaults");
  // One line per material extension the renderer does not implement, over the materials drawn.
  std::map<std::string, size_t> unimplemented;
  for (int m : L.used_materials)
    for (const std::string& ext : L.scene.material_inputs[size_t(m) + 1].unimplemented) ++unimplemented[ext];
  for (const auto& [ext, count] : unimplemented)
    L.warn(ext + " (" + std::to_string(count) + (count == 1 ? " material" : " materials") +
           "): " + material_extension_fallback(ext));
}

void describe_structure(Loader& L, const std::vector<int>& roots) {
  SceneStructure& d = L.scene.structure;
  d.nodes = L.model.nodes.size();
  d.meshes = L.model.meshes.size();
  d.mesh_instances = walk_count(L, roots);
  for (size_t m = 0; m < L.model.meshes.size(); ++m) {
    const auto& prims = L.model.meshes[m].primitives;
    d.primitives += prims.size();
    if (!prims.empty() && !prims[0].targets.empty()) d.morph_meshes.push_back({int(m), prims[0].targets.size()});
  }
  for (const tinygltf::Skin& skin : L.model.skins) d.skin_joints.push_back(skin.joints.size());
  d.generator = L.model.asset.generator;
  d.generated_tangent_primitives = L.generated_tangents;
}

}  // namespace

Scene load_scene(const std::string& path) { return load_scene(path, InputLimits()); }

Scene load_scene(const std::string& path, const InputLimits& limits) { return load_scene(path, limits, ""); }

Scene load_scene(const std::string& path, const InputLimits& limits, const std::string& variant) {
  SourceFile src = read_source(path, limits, variant);
  tinygltf::Model model;
  ImageContext images;
  images.max_pixels = limits.texture_pixels;
  images.memory_left = memory_budget() - std::min(memory_budget(), device_bytes_in_use());
  std::map<std::string, std::string> files_read;
  load_model(path, src, model, images, files_read);
  check_animation_budget(model, limits, path);
  const std::vector<int> parent = validate_model(model, src.unread_buffers, path);
  const std::vector<int> roots = scene_roots(model, parent, path);

  Scene scene;
  Loader L(model, path, images, scene);
  L.limits = &limits;
  L.light_defs = &src.lights;
  L.node_light = &src.node_light;
  L.motion = read_motion(model, parent, path);
  L.rest_world = world_matrices(*L.motion, rest_local_matrices(*L.motion));
  for (const MotionSkin& skin : L.motion->skins) L.rest_joints.push_back(joint_matrices(skin, L.rest_world));
  L.moving = moving_nodes(*L.motion);
  L.weights_animated.assign(model.nodes.size(), false);
  for (const MotionClip& clip : L.motion->clips)
    for (const MotionChannel& ch : clip.channels)
      if (ch.path == ChannelPath::Weights) L.weights_animated[size_t(ch.node)] = true;
  build_materials(L);
  build_cameras(L);
  emit_instances(L, walk(L, roots));
  check_cameras(L);
  if (!scene.tangents.empty()) scene.tangents.resize(scene.positions.size(), glm::vec4(0.0f));
  for (std::vector<glm::vec2>& set : scene.texcoords) set.resize(scene.positions.size(), glm::vec2(0.0f));
  summary_warnings(L, src);
  if (scene.triangles.empty()) L.warn("the scene has no triangles to render: every frame will be a transparent image");
  for (const MotionClip& clip : L.motion->clips)
    scene.animations.push_back({clip.name, clip.start, clip.end, clip.channels.size()});
  describe_structure(L, roots);
  if (!L.motion->clips.empty()) scene.motion = L.motion;
  scene.variants = src.variants;
  scene.variant = src.variant;
  scene.source_checksum = src.checksum;
  for (const auto& [file, sum] : files_read) scene.input_files.push_back({file, sum});
  return scene;
}

}  // namespace pmr
