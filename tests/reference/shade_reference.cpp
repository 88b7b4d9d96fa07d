#include "reference/shade_reference.h"

#include <cmath>

namespace pmr::ref {

namespace {

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

int wrap(int c, int n, int mode) {
  if (mode == PMR_WRAP_CLAMP) return c < 0 ? 0 : (c >= n ? n - 1 : c);
  if (mode == PMR_WRAP_MIRROR) {
    int r = ((c % (2 * n)) + 2 * n) % (2 * n);
    return r < n ? r : 2 * n - 1 - r;
  }
  return ((c % n) + n) % n;
}

glm::dvec4 texel(const SceneTexture& t, int x, int y, bool srgb) {
  const uint8_t* p = &t.rgba[(size_t(y) * t.width + x) * 4];
  const glm::dvec4 c(p[0] / 255.0, p[1] / 255.0, p[2] / 255.0, p[3] / 255.0);
  return srgb ? glm::dvec4(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w) : c;
}

}  // namespace

glm::dvec4 sample_texture(const SceneTexture& tex, const glm::dvec2& uv, bool srgb) {
  const double fx = uv.x * tex.width - 0.5, fy = uv.y * tex.height - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const double ax = fx - x0, ay = fy - y0;
  const int xa = wrap(x0, tex.width, tex.wrap_s), xb = wrap(x0 + 1, tex.width, tex.wrap_s);
  const int ya = wrap(y0, tex.height, tex.wrap_t), yb = wrap(y0 + 1, tex.height, tex.wrap_t);
  const glm::dvec4 top = glm::mix(texel(tex, xa, ya, srgb), texel(tex, xb, ya, srgb), ax);
  const glm::dvec4 bottom = glm::mix(texel(tex, xa, yb, srgb), texel(tex, xb, yb, srgb), ax);
  return glm::mix(top, bottom, ay);
}

glm::dvec2 transformed_uv(const SceneTextureSlot& slot, const glm::dvec2& uv) {
  if (!slot.transform) return uv;
  const double c = std::cos(double(slot.rotation)), s = std::sin(double(slot.rotation));
  const double sx = slot.scale[0], sy = slot.scale[1];
  return {sx * c * uv.x + sy * s * uv.y + slot.offset[0], -sx * s * uv.x + sy * c * uv.y + slot.offset[1]};
}

bool sample_slot(const Scene& scene, const PmrTriangle& t, const glm::dvec3& b, const SceneTextureSlot& slot,
                 glm::dvec4& out) {
  if (slot.texture < 0) return false;
  glm::dvec2 uv(0.0);
  for (int k = 0; k < 3; ++k) uv += b[k] * glm::dvec2(scene.texcoords[size_t(slot.texcoord)][t.v[k]]);
  out = sample_texture(scene.textures[size_t(slot.texture)], transformed_uv(slot, uv), slot.srgb);
  return true;
}

glm::dvec3 source_barycentrics(const PmrMta& m, int px, int py, int view) {
  return source_barycentrics_at(m, int64_t(px) * PMR_X_ONE + PMR_X_ONE / 2, int64_t(py) * PMR_Y_ONE + PMR_Y_ONE / 2,
                                view);
}

glm::dvec3 source_barycentrics_at(const PmrMta& m, int64_t sample_x, int64_t sample_y, int view) {
  double x[3], y[3];
  for (int k = 0; k < 3; ++k) {
    x[k] = (double(m.x0[k]) + double(view) * m.dx[k]) / PMR_X_ONE;
    y[k] = double(m.y[k]) / PMR_Y_ONE;
  }
  const double X = double(sample_x) / PMR_X_ONE, Y = double(sample_y) / PMR_Y_ONE;
  // screen-space barycentrics of the MTA from signed sub-areas
  double l[3];
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const int a = ea[k], b = eb[k];
    l[k] = ((y[b] - y[a]) * (X - x[a]) - (x[b] - x[a]) * (Y - y[a])) * m.inv_w[k];
    sum += l[k];
  }
  glm::dvec3 src(0.0);
  for (int k = 0; k < 3; ++k) {
    const double lk = l[k] / sum;
    src.y += lk * m.bary[k][0];
    src.z += lk * m.bary[k][1];
  }
  src.x = 1.0 - src.y - src.z;
  return src;
}

glm::dvec4 base_color(const Scene& scene, uint32_t tri, const glm::dvec3& b) {
  const PmrTriangle& t = scene.triangles[tri];
  const PmrMaterial& mat = scene.materials[t.material];
  glm::dvec4 c(mat.base_color[0], mat.base_color[1], mat.base_color[2], mat.base_color[3]);
  glm::dvec4 vc(0.0);
  for (int k = 0; k < 3; ++k) {
    const PmrVertexAttr& a = scene.attributes[t.v[k]];
    vc += b[k] * glm::dvec4(a.color[0], a.color[1], a.color[2], a.color[3]);
  }
  c *= vc;
  glm::dvec4 texture;
  if (t.material < scene.material_inputs.size() &&
      sample_slot(scene, t, b, scene.material_inputs[t.material].slots[kSlotBaseColor], texture))
    c *= texture;
  return c;
}

glm::dvec4 shade(const Scene& scene, uint32_t tri, const glm::dvec3& b, bool back, const glm::dvec3& light) {
  const PmrTriangle& t = scene.triangles[tri];
  glm::dvec3 n(t.face_normal[0], t.face_normal[1], t.face_normal[2]);
  if (t.has_normals) {
    glm::dvec3 s(0.0);
    for (int k = 0; k < 3; ++k) {
      const PmrVertexAttr& a = scene.attributes[t.v[k]];
      s += b[k] * glm::dvec3(a.normal[0], a.normal[1], a.normal[2]);
    }
    if (glm::length(s) > 0) n = glm::normalize(s);
  }
  if (back) n = -n;
  const double lambert = 0.2 + 0.8 * std::max(0.0, glm::dot(n, light));
  const glm::dvec4 c = base_color(scene, tri, b);
  return {c.x * lambert, c.y * lambert, c.z * lambert, 1.0};
}

}  // namespace pmr::ref
