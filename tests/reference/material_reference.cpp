#include "reference/material_reference.h"

#include <cmath>

#include "reference/shade_reference.h"

namespace pmr::ref {

namespace {

// The tangent frame about unit normal n at barycentrics b: the interpolated tangent made orthogonal to n
// and normalized, the bitangent sign(w) cross(n, t). False without a usable tangent.
bool tangent_frame(const Scene& scene, const PmrTriangle& t, const glm::dvec3& b, const glm::dvec3& n,
                   glm::dvec3& tangent, glm::dvec3& bitangent) {
  if (scene.tangents.empty()) return false;
  glm::dvec4 tw(0.0);
  for (int k = 0; k < 3; ++k) tw += b[k] * glm::dvec4(scene.tangents[t.v[k]]);
  tangent = glm::dvec3(tw) - n * glm::dot(n, glm::dvec3(tw));
  if (glm::length(tangent) <= 1e-9) return false;
  tangent = glm::normalize(tangent);
  bitangent = (tw.w < 0.0 ? -1.0 : 1.0) * glm::cross(n, tangent);
  return true;
}

// Normal map `slot` (scale `scale`) applied to unit normal n: m = (2 s - 1) (scale, scale, 1) in the
// tangent frame. n itself without the map, a tangent or a usable result.
glm::dvec3 mapped_normal(const Scene& scene, const PmrTriangle& t, const glm::dvec3& b, const SceneTextureSlot& slot,
                         double scale, const glm::dvec3& n) {
  glm::dvec4 s;
  glm::dvec3 tangent, bitangent;
  if (!sample_slot(scene, t, b, slot, s) || !tangent_frame(scene, t, b, n, tangent, bitangent)) return n;
  const glm::dvec3 m = (2.0 * glm::dvec3(s) - 1.0) * glm::dvec3(scale, scale, 1.0);
  const glm::dvec3 mapped = tangent * m.x + bitangent * m.y + n * m.z;
  return glm::length(mapped) > 0.0 ? glm::normalize(mapped) : n;
}

// KHR_materials_anisotropy's strength and unit direction at barycentrics b about the interpolated normal
// n: the rotation applied to the texture's 2 RG - 1 (else (1, 0)) in the tangent frame; strength 0
// without a tangent.
void anisotropy_at(const Scene& scene, const PmrTriangle& t, const glm::dvec3& b, const SceneMaterialInputs& in,
                   const glm::dvec3& n, SurfacePoint& sp) {
  glm::dvec4 s;
  glm::dvec2 d(1.0, 0.0);
  sp.anisotropy = in.anisotropy_strength;
  if (sample_slot(scene, t, b, in.slots[kSlotAnisotropy], s)) d = 2.0 * glm::dvec2(s) - 1.0, sp.anisotropy *= s.z;
  const double c = std::cos(double(in.anisotropy_rotation)), sn = std::sin(double(in.anisotropy_rotation));
  glm::dvec3 tangent, bitangent;
  const glm::dvec3 dir = tangent_frame(scene, t, b, n, tangent, bitangent)
                             ? tangent * (c * d.x - sn * d.y) + bitangent * (sn * d.x + c * d.y)
                             : glm::dvec3(0.0);
  if (glm::length(dir) > 0.0) sp.anisotropy_t = glm::normalize(dir);
  else sp.anisotropy = 0.0;
}

}  // namespace

void material_at(const Scene& scene, uint32_t tri, const glm::dvec3& b, bool back, SurfacePoint& sp) {
  const PmrTriangle& t = scene.triangles[tri];
  const PmrMaterial& mat = scene.materials[t.material];
  sp.base = glm::dvec3(base_color(scene, tri, b));
  glm::dvec3 n(t.face_normal[0], t.face_normal[1], t.face_normal[2]);
  if (t.has_normals) {
    glm::dvec3 sum(0.0);
    for (int k = 0; k < 3; ++k) {
      const float* nk = scene.attributes[t.v[k]].normal;
      sum += b[k] * glm::dvec3(nk[0], nk[1], nk[2]);
    }
    if (glm::length(sum) > 0.0) n = glm::normalize(sum);
  }
  sp.metallic = mat.metallic, sp.roughness = mat.roughness;
  sp.emissive = glm::dvec3(mat.emissive[0], mat.emissive[1], mat.emissive[2]);
  sp.unlit = mat.unlit != 0;
  sp.ior = mat.ior, sp.transmission = mat.transmission;
  sp.ao = 1.0;
  sp.clearcoat = mat.clearcoat, sp.clearcoat_roughness = mat.clearcoat_roughness;
  sp.specular = mat.specular;
  sp.specular_color = glm::dvec3(mat.specular_color[0], mat.specular_color[1], mat.specular_color[2]);
  glm::dvec3 coat_n = n;  // no coat normal map: the coat follows the interpolated normal
  if (t.material < scene.material_inputs.size()) {
    const SceneMaterialInputs& in = scene.material_inputs[t.material];
    sp.metallic = in.metallic, sp.roughness = in.roughness, sp.unlit = in.unlit, sp.ior = in.ior;
    sp.transmission = in.transmission;
    sp.emissive = glm::dvec3(in.emissive[0], in.emissive[1], in.emissive[2]) * double(in.emissive_strength);
    glm::dvec4 s;
    if (sample_slot(scene, t, b, in.slots[kSlotMetallicRoughness], s)) sp.metallic *= s.z, sp.roughness *= s.y;
    if (sample_slot(scene, t, b, in.slots[kSlotOcclusion], s)) sp.ao = 1.0 + in.occlusion_strength * (s.x - 1.0);
    if (sample_slot(scene, t, b, in.slots[kSlotEmissive], s)) sp.emissive *= glm::dvec3(s);
    if (sample_slot(scene, t, b, in.slots[kSlotTransmission], s)) sp.transmission *= s.x;
    const glm::dvec3 geometric = n;
    if (in.anisotropy_strength > 0.0f) anisotropy_at(scene, t, b, in, geometric, sp);
    sp.iridescence = in.iridescence, sp.iridescence_ior = in.iridescence_ior;
    sp.iridescence_thickness = in.iridescence_thickness[1];
    if (sample_slot(scene, t, b, in.slots[kSlotIridescence], s)) sp.iridescence *= s.x;
    if (sample_slot(scene, t, b, in.slots[kSlotIridescenceThickness], s))
      sp.iridescence_thickness =
          glm::mix(double(in.iridescence_thickness[0]), double(in.iridescence_thickness[1]), s.y);
    n = mapped_normal(scene, t, b, in.slots[kSlotNormal], in.normal_scale, geometric);
    sp.specular = in.specular;
    sp.specular_color = glm::dvec3(in.specular_color[0], in.specular_color[1], in.specular_color[2]);
    if (sample_slot(scene, t, b, in.slots[kSlotSpecular], s)) sp.specular *= s.w;
    if (sample_slot(scene, t, b, in.slots[kSlotSpecularColor], s)) sp.specular_color *= glm::dvec3(s);
    sp.sheen_color = glm::dvec3(in.sheen_color[0], in.sheen_color[1], in.sheen_color[2]);
    sp.sheen_roughness = in.sheen_roughness;
    if (sample_slot(scene, t, b, in.slots[kSlotSheenColor], s)) sp.sheen_color *= glm::dvec3(s);
    if (sample_slot(scene, t, b, in.slots[kSlotSheenRoughness], s)) sp.sheen_roughness *= s.w;
    sp.clearcoat = in.clearcoat, sp.clearcoat_roughness = in.clearcoat_roughness;
    if (in.clearcoat > 0.0f) {
      if (sample_slot(scene, t, b, in.slots[kSlotClearcoat], s)) sp.clearcoat *= s.x;
      if (sample_slot(scene, t, b, in.slots[kSlotClearcoatRoughness], s)) sp.clearcoat_roughness *= s.y;
      coat_n = mapped_normal(scene, t, b, in.slots[kSlotClearcoatNormal], in.clearcoat_normal_scale, geometric);
    }
  }
  sp.n = back ? -n : n;
  sp.clearcoat_n = back ? -coat_n : coat_n;
}

}  // namespace pmr::ref
