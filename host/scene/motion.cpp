// Node transforms and vertex deformation (morph targets, skins), shared by the loader's rest pose and
// the per-frame pose. Double precision throughout: a vertex costs ~100 flops, so 100k skinned vertices
// take a few milliseconds (measured in docs/SEQUENCES.md), and the rest pose matches the loader's
// historical double-precision transform bit for bit.
#include "scene/motion.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace pmr {

glm::dmat4 trs_matrix(const glm::dvec3& t, const glm::dvec4& q, const glm::dvec3& s) {
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  // Rotation matrix of the unit quaternion; glm matrices are indexed [column][row].
  glm::dmat3 r;
  r[0] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w)};
  r[1] = {2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w)};
  r[2] = {2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)};
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * s[c], 0.0);
  m[3] = glm::dvec4(t, 1.0);
  return m;
}

std::vector<glm::dmat4> rest_local_matrices(const SceneMotion& m) {
  std::vector<glm::dmat4> local(m.nodes.size());
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    const MotionNode& n = m.nodes[i];
    local[i] = n.has_matrix ? n.matrix : trs_matrix(n.translation, n.rotation, n.scale);
  }
  return local;
}

std::vector<glm::dmat4> world_matrices(const SceneMotion& m, const std::vector<glm::dmat4>& local) {
  std::vector<glm::dmat4> world(local.size());
  for (int i : m.order) {
    const int p = m.nodes[size_t(i)].parent;
    world[size_t(i)] = p < 0 ? local[size_t(i)] : world[size_t(p)] * local[size_t(i)];
  }
  return world;
}

std::vector<glm::dmat4> joint_matrices(const MotionSkin& skin, const std::vector<glm::dmat4>& world) {
  std::vector<glm::dmat4> out(skin.joints.size());
  for (size_t j = 0; j < skin.joints.size(); ++j) out[j] = world[size_t(skin.joints[j])] * skin.inverse_bind[j];
  return out;
}

glm::vec3 face_normal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::dvec3 n = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
  const double len = glm::length(n);
  if (!(len > 0.0) || !std::isfinite(len)) return {0.0f, 0.0f, 1.0f};  // zero area
  return glm::vec3(n / len);
}

namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Unit normal into a, or a zero normal (shading then uses the face normal) when degenerate.
bool store_normal(const glm::dvec3& n, PmrVertexAttr& a) {
  const double len = glm::length(n);
  if (len > 0.0 && std::isfinite(len)) {
    for (int c = 0; c < 3; ++c) a.normal[c] = float(n[c] / len);
    return true;
  }
  for (float& c : a.normal) c = 0.0f;
  return false;
}

}  // namespace

void parallel_for(size_t n, size_t grain, const std::function<void(size_t, size_t)>& fn) {
  const size_t hw = std::max(1u, std::thread::hardware_concurrency());
  const size_t threads = std::min<size_t>(std::min<size_t>(hw, 8), std::max<size_t>(1, n / std::max<size_t>(1, grain)));
  if (threads <= 1) {
    fn(0, n);
    return;
  }
  std::vector<std::thread> pool;
  const size_t chunk = (n + threads - 1) / threads;
  for (size_t t = 1; t < threads; ++t) {
    const size_t b = std::min(n, t * chunk), e = std::min(n, b + chunk);
    pool.emplace_back([&fn, b, e] { fn(b, e); });
  }
  fn(0, std::min(n, chunk));
  for (std::thread& t : pool) t.join();
}

void deform(const DeformSource& src, const std::vector<float>& morph_weights, const glm::dmat4* joints,
            const glm::dmat4& world, glm::vec3* positions, PmrVertexAttr* attributes, uint8_t* bad_position,
            uint8_t* bad_normal, glm::vec4* tangents) {
  // Vertices are independent: split them over the cores (a 100k-vertex skinned, morphed mesh).
  parallel_for(src.vertices, 16384, [&](size_t b, size_t e) {
    deform_range(src, morph_weights, joints, world, b, e, positions, attributes, bad_position, bad_normal, tangents);
  });
}

void deform_range(const DeformSource& src, const std::vector<float>& morph_weights, const glm::dmat4* joints,
                  const glm::dmat4& world, size_t begin, size_t end, glm::vec3* positions, PmrVertexAttr* attributes,
                  uint8_t* bad_position, uint8_t* bad_normal, glm::vec4* tangents) {
  const bool has_normals = !src.nrm.empty();
  const bool has_tangents = tangents && !src.tan.empty();
  const double world_sign = glm::determinant(glm::dmat3(world)) < 0.0 ? -1.0 : 1.0;
  // Morph targets with a zero weight are skipped (they add nothing), so a mesh at its base shape costs
  // nothing extra.
  std::vector<size_t> targets;
  for (size_t k = 0; k < morph_weights.size() && k < src.target_pos.size(); ++k)
    if (morph_weights[k] != 0.0f) targets.push_back(k);
  const bool skinned = joints && src.influences > 0;
  const glm::dmat3 m3(world);
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(m3));
  const double world_scale = std::cbrt(std::fabs(glm::determinant(m3)));
  for (size_t v = begin; v < end; ++v) {
    glm::dvec3 p(src.pos[3 * v], src.pos[3 * v + 1], src.pos[3 * v + 2]);
    glm::dvec3 n(0.0);
    if (has_normals) n = glm::dvec3(src.nrm[3 * v], src.nrm[3 * v + 1], src.nrm[3 * v + 2]);
    for (size_t k : targets) {
      const double w = morph_weights[k];
      if (!src.target_pos[k].empty())
        p += w * glm::dvec3(src.target_pos[k][3 * v], src.target_pos[k][3 * v + 1], src.target_pos[k][3 * v + 2]);
      if (has_normals && !src.target_nrm[k].empty())
        n += w * glm::dvec3(src.target_nrm[k][3 * v], src.target_nrm[k][3 * v + 1], src.target_nrm[k][3 * v + 2]);
    }
    glm::dvec3 t(0.0);
    if (has_tangents) {
      t = glm::dvec3(src.tan[4 * v], src.tan[4 * v + 1], src.tan[4 * v + 2]);
      for (size_t k : targets)
        if (k < src.target_tan.size() && !src.target_tan[k].empty())
          t += double(morph_weights[k]) *
               glm::dvec3(src.target_tan[k][3 * v], src.target_tan[k][3 * v + 1], src.target_tan[k][3 * v + 2]);
    }
    glm::dvec3 wp, wn, wt;
    double tangent_sign = world_sign;
    double weight_sum = 0.0;
    double scale = world_scale;
    glm::dmat4 skin(0.0);
    if (skinned) {
      for (int i = 0; i < src.influences; ++i) {
        const double w = src.weights[v * size_t(src.influences) + size_t(i)];
        if (w == 0.0) continue;
        skin += joints[src.joints[v * size_t(src.influences) + size_t(i)]] * w;
        weight_sum += w;
      }
    }
    if (weight_sum > 0.0) {
      // Exporters write weights that sum to 1 only approximately: normalize, as the spec expects them.
      skin *= 1.0 / weight_sum;
      wp = glm::dvec3(skin * glm::dvec4(p, 1.0));
      // Normals by the cofactor of the blended 3x3 (its inverse transpose up to the determinant's
      // scale), sign-corrected so that a mirroring blend does not turn them inside out.
      const glm::dvec3 a(skin[0]), b(skin[1]), c(skin[2]);
      const double det = glm::dot(a, glm::cross(b, c));
      wn = (glm::cross(b, c) * n.x + glm::cross(c, a) * n.y + glm::cross(a, b) * n.z) * (det < 0.0 ? -1.0 : 1.0);
      // Tangents are directions on the surface: they take the matrix itself, like edges do.
      wt = a * t.x + b * t.y + c * t.z;
      tangent_sign = det < 0.0 ? -1.0 : 1.0;
      scale = std::cbrt(std::fabs(det));
    } else {  // rigid (or a skinned vertex without weights: it keeps its node's transform)
      wp = glm::dvec3(world * glm::dvec4(p, 1.0));
      wn = normal_matrix * n;
      wt = m3 * t;
    }
    glm::vec3 pf(wp);
    const bool bad = !finite(pf);
    if (bad) pf = glm::vec3(0.0f);  // NaN in the data, or beyond float range
    if (bad_position) bad_position[v] = bad;
    positions[v] = pf;
    attributes[v].scale = std::isfinite(scale) ? float(scale) : 1.0f;
    const bool ok = has_normals && store_normal(wn, attributes[v]);
    if (!has_normals)
      for (float& c : attributes[v].normal) c = 0.0f;
    if (bad_normal) bad_normal[v] = !ok;
    if (has_tangents) {
      const double len = glm::length(wt);
      const double w = (src.tan[4 * v + 3] < 0.0f ? -1.0 : 1.0) * tangent_sign;
      tangents[v] = len > 0.0 && std::isfinite(len) ? glm::vec4(glm::vec3(wt / len), float(w))
                                                    : glm::vec4(0.0f, 0.0f, 0.0f, float(w));
    }
  }
}

}  // namespace pmr
