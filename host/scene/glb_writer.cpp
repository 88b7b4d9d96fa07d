// save_glb: a generated scene as a binary glTF, so that any build (an older one included) can render
// the very same triangles (`pmr bench --objects N --save-scene FILE.glb`, then `pmr bench FILE.glb`).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include <nlohmann/json.hpp>

#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/scene.h"

namespace pmr {
namespace {

using json = nlohmann::json;

constexpr uint32_t kGlbMagic = 0x46546C67, kChunkJson = 0x4E4F534A, kChunkBin = 0x004E4942;
constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// The BIN chunk and the JSON entries that describe it.
struct GlbBuilder {
  std::vector<uint8_t> bin;
  json views = json::array(), accessors = json::array();

  // Appends `count` elements of `components` values of T; returns the accessor index.
  template <class T>
  int add(const std::vector<T>& values, int components, const char* type, int component_type, int target,
          bool min_max) {
    const size_t offset = bin.size(), bytes = values.size() * sizeof(T);
    bin.resize(offset + ((bytes + 3) & ~size_t(3)), 0);
    std::memcpy(bin.data() + offset, values.data(), bytes);
    views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
    json a = {{"bufferView", views.size() - 1},
              {"componentType", component_type},
              {"count", values.size() / size_t(components)},
              {"type", type}};
    if (min_max) {  // required for POSITION
      std::vector<double> lo(size_t(components), std::numeric_limits<double>::infinity()),
          hi(size_t(components), -lo[0]);
      for (size_t i = 0; i < values.size(); ++i) {
        const size_t c = i % size_t(components);
        lo[c] = std::min(lo[c], double(values[i])), hi[c] = std::max(hi[c], double(values[i]));
      }
      a["min"] = lo, a["max"] = hi;
    }
    accessors.push_back(a);
    return int(accessors.size()) - 1;
  }
};

void put_u32(std::FILE* f, uint32_t v, bool& ok) { ok = ok && std::fwrite(&v, 4, 1, f) == 1; }

}  // namespace

void save_glb(const Scene& scene, const std::string& path) {
  if (!scene.textures.empty())
    throw Error("cannot save a scene with textures as .glb (only generated scenes are saved)");
  if (scene.triangles.empty()) throw Error("cannot save an empty scene");
  GlbBuilder b;
  json meshes = json::array(), nodes = json::array(), materials = json::array();
  std::vector<uint32_t> new_index(scene.positions.size(), std::numeric_limits<uint32_t>::max());
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const PmrMaterial& mat = scene.materials[m];
    json jm = {{"pbrMetallicRoughness",
                {{"baseColorFactor", {mat.base_color[0], mat.base_color[1], mat.base_color[2], mat.base_color[3]}},
                 {"metallicFactor", mat.metallic},
                 {"roughnessFactor", mat.roughness}}},
               {"doubleSided", mat.double_sided != 0}};
    if (mat.alpha_mode == PMR_ALPHA_MASK) jm["alphaMode"] = "MASK", jm["alphaCutoff"] = mat.alpha_cutoff;
    if (mat.alpha_mode == PMR_ALPHA_BLEND) jm["alphaMode"] = "BLEND";
    materials.push_back(jm);

    // this material's triangles, their vertices renumbered from 0
    std::vector<uint32_t> used, indices;
    bool normals = true, colours = false;
    for (const PmrTriangle& t : scene.triangles) {
      if (t.material != m) continue;
      normals = normals && t.has_normals;
      for (uint32_t v : t.v) {
        if (new_index[v] == std::numeric_limits<uint32_t>::max()) {
          new_index[v] = uint32_t(used.size());
          used.push_back(v);
        }
        indices.push_back(new_index[v]);
      }
    }
    if (indices.empty()) continue;
    std::vector<float> pos, nrm, col;
    for (uint32_t v : used) {
      new_index[v] = std::numeric_limits<uint32_t>::max();
      const glm::vec3& p = scene.positions[v];
      const PmrVertexAttr& a = scene.attributes[v];
      pos.insert(pos.end(), {p.x, p.y, p.z});
      nrm.insert(nrm.end(), a.normal, a.normal + 3);
      col.insert(col.end(), a.color, a.color + 4);
      for (float c : a.color) colours = colours || c != 1.0f;
    }
    json attributes = {{"POSITION", b.add(pos, 3, "VEC3", kFloat, kArrayBuffer, true)}};
    if (normals) attributes["NORMAL"] = b.add(nrm, 3, "VEC3", kFloat, kArrayBuffer, false);
    if (colours) attributes["COLOR_0"] = b.add(col, 4, "VEC4", kFloat, kArrayBuffer, false);
    const int ind = b.add(indices, 1, "SCALAR", kUnsignedInt, kElementArrayBuffer, false);
    meshes.push_back({{"primitives", {{{"attributes", attributes}, {"indices", ind}, {"material", m}, {"mode", 4}}}}});
    nodes.push_back({{"mesh", meshes.size() - 1}});
  }
  json scene_nodes = json::array();
  for (size_t i = 0; i < nodes.size(); ++i) scene_nodes.push_back(i);
  const json doc = {{"asset", {{"version", "2.0"}, {"generator", "pmr (procedural scene)"}}},
                    {"scene", 0},
                    {"scenes", {{{"nodes", scene_nodes}}}},
                    {"nodes", nodes},
                    {"meshes", meshes},
                    {"materials", materials},
                    {"buffers", {{{"byteLength", b.bin.size()}}}},
                    {"bufferViews", b.views},
                    {"accessors", b.accessors}};
  std::string text = doc.dump();
  text.resize((text.size() + 3) & ~size_t(3), ' ');
  const uint64_t total = 12 + 8 + text.size() + 8 + b.bin.size();
  if (total > std::numeric_limits<uint32_t>::max())
    throw Error("cannot save " + path + ": the scene exceeds the 4 GB .glb limit");

  AtomicFile file(path);
  std::FILE* f = std::fopen(file.temp_path().c_str(), "wb");
  if (!f) throw Error("cannot write " + path + ": " + std::strerror(errno));
  bool ok = true;
  put_u32(f, kGlbMagic, ok), put_u32(f, 2, ok), put_u32(f, uint32_t(total), ok);
  put_u32(f, uint32_t(text.size()), ok), put_u32(f, kChunkJson, ok);
  ok = ok && std::fwrite(text.data(), 1, text.size(), f) == text.size();
  put_u32(f, uint32_t(b.bin.size()), ok), put_u32(f, kChunkBin, ok);
  ok = ok && std::fwrite(b.bin.data(), 1, b.bin.size(), f) == b.bin.size();
  const int err = errno;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) throw Error("cannot write " + path + ": " + std::strerror(err));
  file.commit();
}

}  // namespace pmr
