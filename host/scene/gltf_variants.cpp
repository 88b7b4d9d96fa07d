// KHR_materials_variants on the raw JSON, before tinygltf (gltf_internal.h).
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "scene/gltf_internal.h"

namespace pmr::gltf {

using json = nlohmann::json;

namespace {

// The names of the file's variants (root extension); each must be an object with a string name.
std::vector<std::string> variant_names(const std::string& path, const json& doc) {
  const json* ext = member(doc, "extensions");
  const json* khr = ext ? member(*ext, "KHR_materials_variants") : nullptr;
  if (!khr) return {};
  const json* list = member(*khr, "variants");
  if (!list || !list->is_array()) fail(path, "KHR_materials_variants: variants is not an array");
  std::vector<std::string> names;
  for (size_t i = 0; i < list->size(); ++i) {
    const json* name = member((*list)[i], "name");
    if (!name || !name->is_string()) fail(path, "KHR_materials_variants variant " + std::to_string(i) + " has no name");
    names.push_back(name->get<std::string>());
  }
  return names;
}

// The variant `choice` names: the one variant of that name, or "#K" its index.
int chosen_variant(const std::string& path, const std::vector<std::string>& names, const std::string& choice) {
  const std::string shown = "--variant '" + one_line(choice) + "'";
  if (names.empty()) fail(path, shown + ": the file has no material variants (KHR_materials_variants)");
  const auto count = std::count(names.begin(), names.end(), choice);
  if (count > 1)
    fail(path, shown + " is ambiguous: " + std::to_string(count) + " variants have that name (give its index, #K)");
  const auto it = std::find(names.begin(), names.end(), choice);
  if (it != names.end()) return int(it - names.begin());
  const IndexChoice index = parse_index_choice(choice, names.size(), "variant(s)");
  if (!index.is_index) fail(path, shown + ": no variant has that name" + unnamed_choice_hint(choice, "pmr info"));
  if (!index.problem.empty()) fail(path, shown + ": " + index.problem);
  return index.index;
}

// The material `variant` maps primitive `p` to (-1: none of its mappings names it), every mapping
// checked: a material of the file, variants of the file, each variant in one mapping at most.
int mapped_material(const std::string& path, const json& p, const std::string& where, size_t variants, size_t materials,
                    int variant) {
  const json* ext = member(p, "extensions");
  const json* khr = ext ? member(*ext, "KHR_materials_variants") : nullptr;
  if (!khr) return -1;
  const json* mappings = member(*khr, "mappings");
  if (!mappings || !mappings->is_array()) fail(path, where + " KHR_materials_variants: mappings is not an array");
  int found = -1;
  std::set<int64_t> seen;  // this primitive's mapped variants (not one flag per variant of the file: a
                           // hostile file with many of both would cost their product)
  for (size_t m = 0; m < mappings->size(); ++m) {
    const std::string at = where + " KHR_materials_variants mapping " + std::to_string(m);
    const json* material = member((*mappings)[m], "material");
    const json* list = member((*mappings)[m], "variants");
    if (!material || !material->is_number_integer() || material->get<int64_t>() < 0 ||
        material->get<int64_t>() >= int64_t(materials))
      fail(path, at + " does not name a material of the file (it has " + std::to_string(materials) + ")");
    if (!list || !list->is_array()) fail(path, at + ": variants is not an array");
    for (const json& v : *list) {
      if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() >= int64_t(variants))
        fail(path, at + " names a variant the file does not have (it has " + std::to_string(variants) + ")");
      if (!seen.insert(v.get<int64_t>()).second)
        fail(path, at + " maps variant " + std::to_string(v.get<int64_t>()) + " a second time");
      if (v.get<int64_t>() == variant) found = int(material->get<int64_t>());
    }
  }
  return found;
}

}  // namespace

bool apply_material_variant(const std::string& path, json& doc, const std::string& choice, SourceFile& src) {
  src.variants = variant_names(path, doc);
  src.variant = choice.empty() ? -1 : chosen_variant(path, src.variants, choice);
  const json* materials = member(doc, "materials");
  const size_t material_count = materials && materials->is_array() ? materials->size() : 0;
  bool changed = false;
  json* meshes = doc.contains("meshes") && doc["meshes"].is_array() ? &doc["meshes"] : nullptr;
  for (size_t m = 0; meshes && m < meshes->size(); ++m) {
    json* prims =
        (*meshes)[m].is_object() && (*meshes)[m].contains("primitives") ? &(*meshes)[m]["primitives"] : nullptr;
    for (size_t k = 0; prims && prims->is_array() && k < prims->size(); ++k) {
      const std::string where = "mesh " + std::to_string(m) + " primitive " + std::to_string(k);
      const int material = mapped_material(path, (*prims)[k], where, src.variants.size(), material_count, src.variant);
      if (material >= 0) (*prims)[k]["material"] = material, changed = true;
    }
  }
  return changed;
}

}  // namespace pmr::gltf
