// The glTF 2.0 schema's ranges for indices, offsets, lengths, counts and strides, and the structure of
// animations and skins, checked on the raw JSON before tinygltf sees it: tinygltf coerces some
// schema-invalid numbers instead of refusing them (a negative byteOffset was read as a valid one and
// the file rendered). Upper bounds of the references the renderer follows are checked after tinygltf
// (gltf_validate.cpp); animations and skins are checked here completely, since nothing else reads them
// yet and a file must be refused before any frame renders.
#include <string>
#include <vector>

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
    return v ? value(*v, where + " " + key, lo, hi, what) : -1;
  }

  // An integer JSON value >= lo (and < hi when hi >= 0), `name` naming it in messages.
  int64_t value(const json& v, const std::string& name, int64_t lo, int64_t hi = -1, const char* what = nullptr) const {
    if (!v.is_number_integer()) fail(path_, name + " is not an integer");
    if (v.is_number_unsigned()) {
      const uint64_t u = v.get<uint64_t>();
      if (lo > 0 && u < uint64_t(lo)) below(name, std::to_string(u), lo);
      if (hi >= 0 && u >= uint64_t(hi)) out_of_range(name, std::to_string(u), hi, what);
      return u > uint64_t(INT64_MAX) ? INT64_MAX : int64_t(u);
    }
    const int64_t s = v.get<int64_t>();
    if (s < lo) below(name, std::to_string(s), lo);
    if (hi >= 0 && s >= hi) out_of_range(name, std::to_string(s), hi, what);
    return s;
  }

  // An optional reference (an integer >= 0) to an element of an array of `count`, checked as the
  // 64-bit value written: tinygltf stores indices as int, so 2^32 would wrap to element 0 and 2^31 to a
  // negative index. `owner` names the referring element as the later checks do ("node 0 children").
  void reference(const json& obj, const char* key, const std::string& owner, const char* kind, int64_t count) const {
    if (const json* v = member(obj, key)) reference_value(*v, owner + " " + key, owner, kind, count);
  }
  // `name` names the value itself in the messages of value() ("node 0 children").
  void reference_value(const json& v, const std::string& name, const std::string& owner, const char* kind,
                       int64_t count) const {
    if (value(v, name, 0) >= count)
      fail(path_, owner + " refers to " + kind + " " + v.dump() + ", which does not exist (the file has " +
                      std::to_string(count) + ")");
  }
  // An optional array of references, as reference().
  void references(const json& obj, const char* key, const std::string& owner, const char* kind, int64_t count) const {
    const json* a = member(obj, key);
    if (!a) return;
    if (!a->is_array()) fail(path_, owner + " " + key + " is not an array");
    for (const json& v : *a) reference_value(v, owner + " " + key, owner, kind, count);
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
    for (const json& v : *a) value(v, where + " " + key, 0, hi, what);
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

  [[noreturn]] void out_of_range(const std::string& name, const std::string& value, int64_t hi,
                                 const char* what) const {
    fail(path_,
         name + " refers to " + (what ? what : "element") + " " + value + ", but the file has " + std::to_string(hi));
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
    c.reference(*info, "index", where + " " + name, "texture", c.count("textures"));
    c.integer(*info, "texCoord", where + " " + name, 0, int64_t(INT32_MAX) + 1, "TEXCOORD set");
  };
  for (const char* n : direct) check(member(material, n), n);
  if (pbr)
    for (const char* n : in_pbr) check(member(*pbr, n), n);
}

// An accessor's count, type and componentType as written (count -1, type "" when absent or invalid;
// their own checks report that).
struct AccessorShape {
  int64_t count = -1;
  std::string type;
  int64_t component = -1;
};

AccessorShape accessor_shape(const SchemaCheck& c, int64_t index) {
  AccessorShape a;
  const json* all = member(c.doc(), "accessors");
  if (!all || !all->is_array() || index < 0 || index >= int64_t(all->size())) return a;
  const json& acc = (*all)[size_t(index)];
  if (const json* n = member(acc, "count"); n && n->is_number_unsigned() && n->get<uint64_t>() <= uint64_t(INT64_MAX))
    a.count = int64_t(n->get<uint64_t>());
  if (const json* t = member(acc, "type"); t && t->is_string()) a.type = t->get<std::string>();
  if (const json* k = member(acc, "componentType"); k && k->is_number_integer()) a.component = k->get<int64_t>();
  return a;
}

// Morph targets of node `node`'s mesh (that of its first primitive), -1 when it has no mesh.
int64_t node_morph_targets(const SchemaCheck& c, int64_t node) {
  const json* nodes = member(c.doc(), "nodes");
  const json* meshes = member(c.doc(), "meshes");
  if (!nodes || !meshes || !nodes->is_array() || !meshes->is_array() || node < 0 || node >= int64_t(nodes->size()))
    return -1;
  const json* mesh = member((*nodes)[size_t(node)], "mesh");
  if (!mesh || !mesh->is_number_unsigned() || mesh->get<uint64_t>() >= meshes->size()) return -1;
  const json* prims = member((*meshes)[mesh->get<size_t>()], "primitives");
  if (!prims || !prims->is_array() || prims->empty()) return -1;
  const json* targets = member((*prims)[0], "targets");
  return targets && targets->is_array() ? int64_t(targets->size()) : 0;
}

void check_animations(const SchemaCheck& c) {
  const int64_t accessors = c.count("accessors"), nodes = c.count("nodes");
  c.each("animations", "animation", [&](const json& anim, const std::string& where) {
    const json* samplers = member(anim, "samplers");
    const json* channels = member(anim, "channels");
    if (!samplers || !samplers->is_array() || samplers->empty()) fail(c.path(), where + " has no samplers");
    if (!channels || !channels->is_array() || channels->empty()) fail(c.path(), where + " has no channels");
    std::vector<std::string> interpolation;
    std::vector<int64_t> inputs, outputs;
    for (size_t s = 0; s < samplers->size(); ++s) {
      const std::string w = where + " sampler " + std::to_string(s);
      const int64_t input = c.required_integer((*samplers)[s], "input", w, 0, accessors, "accessor");
      inputs.push_back(input);
      outputs.push_back(c.required_integer((*samplers)[s], "output", w, 0, accessors, "accessor"));
      interpolation.push_back(
          c.one_of((*samplers)[s], "interpolation", w, {"LINEAR", "STEP", "CUBICSPLINE"}, "LINEAR"));
      const AccessorShape in = accessor_shape(c, input);
      if (in.type != "SCALAR" || in.component != 5126)
        fail(c.path(), w + " input (accessor " + std::to_string(input) + ") must hold float scalars (key times)");
    }
    for (size_t k = 0; k < channels->size(); ++k) {
      const std::string w = where + " channel " + std::to_string(k);
      const json& ch = (*channels)[k];
      const int64_t s = c.required_integer(ch, "sampler", w, 0, int64_t(samplers->size()), "sampler");
      const json* target = member(ch, "target");
      if (!target || !target->is_object()) fail(c.path(), w + " has no target");
      const int64_t node = c.integer(*target, "node", w + " target", 0, nodes, "node");
      if (!member(*target, "path")) fail(c.path(), w + " target has no path");
      const std::string path =
          c.one_of(*target, "path", w + " target", {"translation", "rotation", "scale", "weights"}, "");
      if (node < 0) continue;  // the animated object is defined by an extension: nothing here reads it
      // the output must fit the path: VEC3 for translation and scale, VEC4 for rotation, one scalar per
      // morph target for weights; key count x 3 for CUBICSPLINE (in-tangent, value, out-tangent)
      const AccessorShape in = accessor_shape(c, inputs[size_t(s)]);
      const int64_t output = outputs[size_t(s)];
      const AccessorShape out = accessor_shape(c, output);
      const char* want = path == "rotation" ? "VEC4" : path == "weights" ? "SCALAR" : "VEC3";
      if (out.type != want)
        fail(c.path(), w + " animates " + path + " but its sampler's output (accessor " + std::to_string(output) +
                           ") has type " + (out.type.empty() ? "?" : out.type) + ", " + want + " expected");
      int64_t per_key = interpolation[size_t(s)] == "CUBICSPLINE" ? 3 : 1;
      if (path == "weights") {
        const int64_t targets = node >= 0 ? node_morph_targets(c, node) : -1;
        if (targets <= 0) fail(c.path(), w + " animates weights of a node without morph targets");
        per_key *= targets;
      }
      if (in.count >= 0 && out.count >= 0 && out.count != in.count * per_key)
        fail(c.path(), w + ": sampler " + std::to_string(s) + " has " + std::to_string(in.count) + " key times but " +
                           std::to_string(out.count) + " output elements (" + std::to_string(in.count * per_key) +
                           " expected)");
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
  const int64_t accessors = c.count("accessors"), buffer_views = c.count("bufferViews"), nodes = c.count("nodes");
  if (c.count("scenes") > 0) {
    if (const json* v = member(doc, "scene"))
      c.reference_value(*v, "the file's scene", "the default scene", "scene", c.count("scenes"));
  } else if (const int64_t s = c.integer(doc, "scene", "the file's", 0); s > INT32_MAX) {
    fail(path, "scene " + member(doc, "scene")->dump() + " is the default but there are no scenes");
  }
  c.each("accessors", "accessor", [&](const json& a, const std::string& where) {
    c.reference(a, "bufferView", where, "bufferView", buffer_views);
    c.integer(a, "byteOffset", where, 0);
    c.integer(a, "count", where, 1);
    // tinygltf stores the component type as int: 2^32 + 5126 would read as FLOAT
    if (const json* t = member(a, "componentType"); t && !(t->is_number_integer() && t->get<int64_t>() >= 5120 &&
                                                           t->get<int64_t>() <= 5126 && t->get<int64_t>() != 5124))
      fail(path, where + " componentType is " + t->dump() + ", which is not a glTF component type");
    if (const json* sparse = member(a, "sparse")) {
      c.integer(*sparse, "count", where + " sparse", 1);
      for (const char* part : {"indices", "values"})
        if (const json* p = member(*sparse, part)) {
          c.reference(*p, "bufferView", where + " sparse " + part, "bufferView", buffer_views);
          c.integer(*p, "byteOffset", where + " sparse " + part, 0);
        }
    }
  });
  c.each("buffers", "buffer", [&](const json& b, const std::string& where) { c.integer(b, "byteLength", where, 1); });
  c.each("bufferViews", "bufferView", [&](const json& v, const std::string& where) {
    c.reference(v, "buffer", where, "buffer", c.count("buffers"));
    c.integer(v, "byteOffset", where, 0);
    c.integer(v, "byteLength", where, 1);
    const int64_t stride = c.integer(v, "byteStride", where, 4);
    if (stride > 252 || (stride > 0 && stride % 4 != 0))
      fail(path, where + " byteStride is " + std::to_string(stride) +
                     ", which the glTF schema does not allow (a multiple of 4 from 4 to 252)");
  });
  c.each("images", "image", [&](const json& i, const std::string& where) {
    c.reference(i, "bufferView", where, "bufferView", buffer_views);
  });
  c.each("materials", "material", [&](const json& m, const std::string& where) { check_texture_info(c, m, where); });
  c.each("meshes", "mesh", [&](const json& mesh, const std::string& where) {
    const json* prims = member(mesh, "primitives");
    if (!prims || !prims->is_array()) return;  // tinygltf reports a mesh without primitives
    for (size_t p = 0; p < prims->size(); ++p) {
      const json& prim = (*prims)[p];
      const std::string w = where + " primitive " + std::to_string(p);
      if (const json* v = member(prim, "indices"))
        c.reference_value(*v, w + " indices", w + " indices", "accessor", accessors);
      c.reference(prim, "material", w, "material", c.count("materials"));
      if (const json* mode = member(prim, "mode");
          mode && !(mode->is_number_integer() && mode->get<int64_t>() >= 0 && mode->get<int64_t>() <= 6))
        fail(path, w + " has mode " + mode->dump() + ", which is not a glTF primitive mode (0 to 6)");
      if (const json* attrs = member(prim, "attributes"))
        for (auto it = attrs->begin(); attrs->is_object() && it != attrs->end(); ++it)
          c.reference_value(it.value(), w + " attribute " + it.key(), w + " attribute " + it.key(), "accessor",
                            accessors);
      if (const json* targets = member(prim, "targets"); targets && targets->is_array())
        for (size_t t = 0; t < targets->size(); ++t)
          for (auto it = (*targets)[t].begin(); (*targets)[t].is_object() && it != (*targets)[t].end(); ++it)
            c.reference_value(it.value(), w + " morph target " + std::to_string(t) + " " + it.key(),
                              w + " morph target " + std::to_string(t) + " " + it.key(), "accessor", accessors);
    }
  });
  c.each("nodes", "node", [&](const json& n, const std::string& where) {
    c.reference(n, "camera", where, "camera", c.count("cameras"));
    c.reference(n, "mesh", where, "mesh", c.count("meshes"));
    c.integer(n, "skin", where, 0, c.count("skins"), "skin");
    if (const json* ch = member(n, "children")) {
      if (!ch->is_array()) fail(path, where + " children is not an array");
      for (const json& v : *ch) c.reference_value(v, where + " children", where + " children", "node", nodes);
    }
  });
  c.each("scenes", "scene",
         [&](const json& s, const std::string& where) { c.references(s, "nodes", where, "node", nodes); });
  c.each("textures", "texture", [&](const json& t, const std::string& where) {
    c.reference(t, "sampler", where, "sampler", c.count("samplers"));
    c.reference(t, "source", where, "image", c.count("images"));
  });
  check_animations(c);
  check_skins(c);
}

}  // namespace pmr::gltf
