// The glTF 2.0 schema's ranges for indices, offsets, lengths, counts and strides, and the structure of
// animations and skins, checked on the raw JSON before tinygltf sees it: tinygltf coerces some
// schema-invalid numbers instead of refusing them (a negative byteOffset was read as a valid one and
// the file rendered). Upper bounds of the references the renderer follows are checked after tinygltf
// (gltf_validate.cpp); animations and skins are checked here completely, since nothing else reads them
// yet and a file must be refused before any frame renders.
#include <string>

#include "scene/gltf_internal.h"

namespace pmr::gltf {
namespace {

using json = nlohmann::json;

class SchemaCheck {
 public:
  SchemaCheck(const std::string& path, const json& doc) : path_(path), doc_(doc) {}

  // Every element of the top-level array `name` (if present), with its display name ("accessor 3").
  template <class F>
  void each(const char* name, const char* singular, F f) const {
    const json* a = member(doc_, name);
    if (!a) return;
    if (!a->is_array()) fail(path_, std::string(name) + " is not an array");
    for (size_t i = 0; i < a->size(); ++i) f((*a)[i], std::string(singular) + " " + std::to_string(i));
  }

  // An optional integer property >= lo (and < hi when hi >= 0). Returns it, or -1 when absent.
  int64_t integer(const json& obj, const char* key, const std::string& where, int64_t lo, int64_t hi = -1,
                  const char* what = nullptr) const {
    const json* v = member(obj, key);
    if (!v) return -1;
    const std::string name = where + " " + key;
    if (!v->is_number_integer()) fail(path_, name + " is not an integer");
    if (v->is_number_unsigned()) {
      const uint64_t u = v->get<uint64_t>();
      if (lo > 0 && u < uint64_t(lo)) below(name, std::to_string(u), lo);
      if (hi >= 0 && u >= uint64_t(hi)) out_of_range(name, std::to_string(u), hi, what);
      return u > uint64_t(INT64_MAX) ? INT64_MAX : int64_t(u);
    }
    const int64_t s = v->get<int64_t>();
    if (s < lo) below(name, std::to_string(s), lo);
    if (hi >= 0 && s >= hi) out_of_range(name, std::to_string(s), hi, what);
    return s;
  }

  int64_t required_integer(const json& obj, const char* key, const std::string& where, int64_t lo, int64_t hi = -1,
                           const char* what = nullptr) const {
    if (!member(obj, key)) fail(path_, where + " has no " + key);
    return integer(obj, key, where, lo, hi, what);
  }

  // An optional array of integers >= 0 (each < hi when hi >= 0), at least min_items long.
  void indices(const json& obj, const char* key, const std::string& where, int64_t hi, const char* what,
               size_t min_items = 0) const {
    const json* a = member(obj, key);
    if (!a) return;
    if (!a->is_array()) fail(path_, where + " " + key + " is not an array");
    if (a->size() < min_items) fail(path_, where + " " + key + " is empty");
    for (size_t i = 0; i < a->size(); ++i) {
      json one = {{key, (*a)[i]}};
      integer(one, key, where, 0, hi, what);
    }
  }

  // An optional string property that must be one of `allowed`.
  std::string one_of(const json& obj, const char* key, const std::string& where,
                     std::initializer_list<const char*> allowed, const char* fallback) const {
    const json* v = member(obj, key);
    if (!v) return fallback;
    const std::string name = where + " " + key;
    if (!v->is_string()) fail(path_, name + " is not a string");
    const std::string s = v->get<std::string>();
    std::string list;
    for (const char* a : allowed) {
      if (s == a) return s;
      list += std::string(list.empty() ? "" : ", ") + a;
    }
    fail(path_, name + " is '" + one_line(s) + "'; the glTF schema allows " + list);
  }

  int64_t count(const char* name) const {
    const json* a = member(doc_, name);
    return a && a->is_array() ? int64_t(a->size()) : 0;
  }

  const json& doc() const { return doc_; }
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void below(const std::string& name, const std::string& value, int64_t lo) const {
    fail(path_, name + " is " + value + ", which the glTF schema does not allow (minimum " + std::to_string(lo) + ")");
  }

  [[noreturn]] void out_of_range(const std::string& name, const std::string& value, int64_t hi, const char* what) const {
    fail(path_, name + " refers to " + (what ? what : "element") + " " + value + ", but the file has " +
                    std::to_string(hi));
  }

  const std::string& path_;
  const json& doc_;
};

void check_texture_info(const SchemaCheck& c, const json& material, const std::string& where) {
  const json* pbr = member(material, "pbrMetallicRoughness");
  const char* direct[] = {"normalTexture", "occlusionTexture", "emissiveTexture"};
  const char* in_pbr[] = {"baseColorTexture", "metallicRoughnessTexture"};
  auto check = [&](const json* info, const char* name) {
    if (!info) return;
    c.integer(*info, "index", where + " " + name, 0);
    c.integer(*info, "texCoord", where + " " + name, 0);
  };
  for (const char* n : direct) check(member(material, n), n);
  if (pbr)
    for (const char* n : in_pbr) check(member(*pbr, n), n);
}

void check_animations(const SchemaCheck& c) {
  const int64_t accessors = c.count("accessors"), nodes = c.count("nodes");
  c.each("animations", "animation", [&](const json& anim, const std::string& where) {
    const json* samplers = member(anim, "samplers");
    const json* channels = member(anim, "channels");
    if (!samplers || !samplers->is_array() || samplers->empty()) fail(c.path(), where + " has no samplers");
    if (!channels || !channels->is_array() || channels->empty()) fail(c.path(), where + " has no channels");
    for (size_t s = 0; s < samplers->size(); ++s) {
      const std::string w = where + " sampler " + std::to_string(s);
      c.required_integer((*samplers)[s], "input", w, 0, accessors, "accessor");
      c.required_integer((*samplers)[s], "output", w, 0, accessors, "accessor");
      c.one_of((*samplers)[s], "interpolation", w, {"LINEAR", "STEP", "CUBICSPLINE"}, "LINEAR");
    }
    for (size_t k = 0; k < channels->size(); ++k) {
      const std::string w = where + " channel " + std::to_string(k);
      const json& ch = (*channels)[k];
      c.required_integer(ch, "sampler", w, 0, int64_t(samplers->size()), "sampler");
      const json* target = member(ch, "target");
      if (!target || !target->is_object()) fail(c.path(), w + " has no target");
      c.integer(*target, "node", w + " target", 0, nodes, "node");
      if (!member(*target, "path")) fail(c.path(), w + " target has no path");
      c.one_of(*target, "path", w + " target", {"translation", "rotation", "scale", "weights"}, "");
    }
  });
}

void check_skins(const SchemaCheck& c) {
  const int64_t accessors = c.count("accessors"), nodes = c.count("nodes");
  c.each("skins", "skin", [&](const json& skin, const std::string& where) {
    c.integer(skin, "inverseBindMatrices", where, 0, accessors, "accessor");
    c.integer(skin, "skeleton", where, 0, nodes, "node");
    if (!member(skin, "joints")) fail(c.path(), where + " has no joints");
    c.indices(skin, "joints", where, nodes, "node", 1);
  });
}

}  // namespace

void check_schema(const std::string& path, const json& doc) {
  const SchemaCheck c(path, doc);
  c.integer(doc, "scene", "the file's", 0);
  c.each("accessors", "accessor", [&](const json& a, const std::string& where) {
    c.integer(a, "bufferView", where, 0);
    c.integer(a, "byteOffset", where, 0);
    c.integer(a, "count", where, 1);
    if (const json* sparse = member(a, "sparse")) {
      c.integer(*sparse, "count", where + " sparse", 1);
      for (const char* part : {"indices", "values"})
        if (const json* p = member(*sparse, part)) {
          c.integer(*p, "bufferView", where + " sparse " + part, 0);
          c.integer(*p, "byteOffset", where + " sparse " + part, 0);
        }
    }
  });
  c.each("buffers", "buffer", [&](const json& b, const std::string& where) { c.integer(b, "byteLength", where, 1); });
  c.each("bufferViews", "bufferView", [&](const json& v, const std::string& where) {
    c.integer(v, "buffer", where, 0);
    c.integer(v, "byteOffset", where, 0);
    c.integer(v, "byteLength", where, 1);
    const int64_t stride = c.integer(v, "byteStride", where, 4);
    if (stride > 252 || (stride > 0 && stride % 4 != 0))
      fail(path, where + " byteStride is " + std::to_string(stride) +
                     ", which the glTF schema does not allow (a multiple of 4 from 4 to 252)");
  });
  c.each("images", "image", [&](const json& i, const std::string& where) { c.integer(i, "bufferView", where, 0); });
  c.each("materials", "material", [&](const json& m, const std::string& where) { check_texture_info(c, m, where); });
  c.each("meshes", "mesh", [&](const json& mesh, const std::string& where) {
    const json* prims = member(mesh, "primitives");
    if (!prims || !prims->is_array()) return;  // tinygltf reports a mesh without primitives
    for (size_t p = 0; p < prims->size(); ++p) {
      const json& prim = (*prims)[p];
      const std::string w = where + " primitive " + std::to_string(p);
      c.integer(prim, "indices", w, 0);
      c.integer(prim, "material", w, 0);
      if (const json* attrs = member(prim, "attributes"))
        for (auto it = attrs->begin(); attrs->is_object() && it != attrs->end(); ++it) {
          const json one = {{it.key(), it.value()}};
          c.integer(one, it.key().c_str(), w + " attribute", 0);
        }
      if (const json* targets = member(prim, "targets"); targets && targets->is_array())
        for (size_t t = 0; t < targets->size(); ++t)
          for (auto it = (*targets)[t].begin(); (*targets)[t].is_object() && it != (*targets)[t].end(); ++it) {
            const json one = {{it.key(), it.value()}};
            c.integer(one, it.key().c_str(), w + " morph target " + std::to_string(t), 0);
          }
    }
  });
  c.each("nodes", "node", [&](const json& n, const std::string& where) {
    c.integer(n, "camera", where, 0);
    c.integer(n, "mesh", where, 0);
    c.integer(n, "skin", where, 0, c.count("skins"), "skin");
    c.indices(n, "children", where, -1, "node");
  });
  c.each("scenes", "scene", [&](const json& s, const std::string& where) { c.indices(s, "nodes", where, -1, "node"); });
  c.each("textures", "texture", [&](const json& t, const std::string& where) {
    c.integer(t, "sampler", where, 0);
    c.integer(t, "source", where, 0);
  });
  check_animations(c);
  check_skins(c);
}

}  // namespace pmr::gltf
