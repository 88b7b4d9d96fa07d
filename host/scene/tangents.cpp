// Generated tangents for meshes that have a normal texture but no TANGENT attribute (DESIGN 4b: glTF
// recommends MikkTSpace). Debian has no MikkTSpace library; this is its method in essence, in double
// precision:
//   - per triangle, the direction of increasing u, dP/du = (dv31 * e21 - dv21 * e31) / area, from
//     the UVs with v pointing up (MikkTSpace sees OpenGL's convention; glTF's v points down), and
//     the sign of that UV area: +1 where the UVs keep the triangle's orientation, -1 where mirrored;
//   - per corner, that direction projected onto the plane of the corner's vertex normal, normalized,
//     weighted by the corner's angle (also measured in that plane);
//   - summed over every corner whose vertex has the same position, normal and UV bit for bit and whose
//     triangle has the same UV orientation (MikkTSpace welds such vertices even when the index
//     buffer does not), then made orthogonal to the normal and normalized.
// What differs from MikkTSpace: a glTF vertex holds one tangent, so a vertex whose corners have both
// UV orientations takes the majority's (MikkTSpace would need the exporter to split it), and
// degenerate triangles only contribute nothing (MikkTSpace gives their corners a neighbour's tangent).
#include <array>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "scene/motion.h"

namespace pmr {

namespace {

struct WeldKey {
  std::array<uint32_t, 8> bits;  // position, normal, uv as float bit patterns
  bool preserving;
  bool operator==(const WeldKey& o) const { return bits == o.bits && preserving == o.preserving; }
};

struct WeldHash {
  size_t operator()(const WeldKey& k) const {
    uint64_t h = k.preserving ? 0x9e3779b97f4a7c15ull : 0x243f6a8885a308d3ull;
    for (uint32_t b : k.bits) h = (h ^ b) * 0x100000001b3ull;
    return size_t(h ^ (h >> 29));
  }
};

uint32_t float_bits(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 welds with +0, as MikkTSpace's comparison of values does
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

glm::dvec3 unit_or_zero(const glm::dvec3& v) {
  const double len = glm::length(v);
  return len > 0.0 && std::isfinite(len) ? v / len : glm::dvec3(0.0);
}

// Some unit vector orthogonal to n (n unit or zero).
glm::dvec3 any_orthogonal(const glm::dvec3& n) {
  const glm::dvec3 axis = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 t = unit_or_zero(axis - n * glm::dot(n, axis));
  return t == glm::dvec3(0.0) ? glm::dvec3(1, 0, 0) : t;
}

}  // namespace

std::vector<float> generate_tangents(const std::vector<float>& pos, const std::vector<float>& nrm,
                                     const std::vector<float>& uv, const std::vector<uint32_t>& tris) {
  const size_t vertices = pos.size() / 3;
  auto P = [&](uint32_t v) { return glm::dvec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]); };
  auto UV = [&](uint32_t v) {
    return uv.size() >= 2 * (size_t(v) + 1) ? glm::dvec2(uv[2 * v], 1.0 - double(uv[2 * v + 1])) : glm::dvec2(0.0);
  };
  // Vertex normals: the file's, else the area-weighted sum of the face normals around the vertex.
  std::vector<glm::dvec3> normal(vertices, glm::dvec3(0.0));
  if (nrm.size() == 3 * vertices) {
    for (size_t v = 0; v < vertices; ++v)
      normal[v] = unit_or_zero(glm::dvec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
  } else {
    for (size_t t = 0; t + 2 < tris.size(); t += 3) {
      const glm::dvec3 f = glm::cross(P(tris[t + 1]) - P(tris[t]), P(tris[t + 2]) - P(tris[t]));
      for (int k = 0; k < 3; ++k) normal[tris[t + size_t(k)]] += f;
    }
    for (glm::dvec3& n : normal) n = unit_or_zero(n);
  }
  auto key = [&](uint32_t v, bool preserving) {
    WeldKey k{};
    for (int c = 0; c < 3; ++c) k.bits[size_t(c)] = float_bits(pos[3 * v + size_t(c)]);
    for (int c = 0; c < 3; ++c) k.bits[size_t(3 + c)] = float_bits(float(normal[v][c]));
    if (uv.size() >= 2 * (size_t(v) + 1)) k.bits[6] = float_bits(uv[2 * v]), k.bits[7] = float_bits(uv[2 * v + 1]);
    k.preserving = preserving;
    return k;
  };
  std::unordered_map<WeldKey, glm::dvec3, WeldHash> sum;
  std::vector<int> votes(vertices, 0);  // UV orientation of the vertex's corners: + preserving, - mirrored
  for (size_t t = 0; t + 2 < tris.size(); t += 3) {
    const uint32_t c[3] = {tris[t], tris[t + 1], tris[t + 2]};
    const glm::dvec3 p0 = P(c[0]), e21 = P(c[1]) - p0, e31 = P(c[2]) - p0;
    const glm::dvec2 uv0 = UV(c[0]), d21 = UV(c[1]) - uv0, d31 = UV(c[2]) - uv0;
    const double area = d21.x * d31.y - d21.y * d31.x;
    const bool preserving = area > 0.0;
    const glm::dvec3 os = d31.y * e21 - d21.y * e31;  // dP/du times the signed area
    const double len = glm::length(os);
    const bool usable = area != 0.0 && len > 0.0 && std::isfinite(len) && std::isfinite(area);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = c[k];
      if (!usable) continue;  // (no orientation either: it does not vote)
      votes[v] += preserving ? 1 : -1;
      const glm::dvec3 n = normal[v];
      const glm::dvec3 dir = unit_or_zero((preserving ? 1.0 : -1.0) * os / len);
      const glm::dvec3 in_plane = unit_or_zero(dir - n * glm::dot(n, dir));
      const glm::dvec3 here = P(v);
      glm::dvec3 a = P(c[(k + 1) % 3]) - here, b = P(c[(k + 2) % 3]) - here;
      a = unit_or_zero(a - n * glm::dot(n, a));
      b = unit_or_zero(b - n * glm::dot(n, b));
      const double angle = std::acos(std::max(-1.0, std::min(1.0, glm::dot(a, b))));
      sum[key(v, preserving)] += in_plane * angle;
    }
  }
  std::vector<float> out(4 * vertices);
  for (size_t v = 0; v < vertices; ++v) {
    const glm::dvec3 n = normal[v];
    const bool preserving = votes[v] >= 0;
    glm::dvec3 t(0.0);
    for (bool o : {preserving, !preserving}) {  // the other orientation's sum only if the vertex has none
      const auto it = sum.find(key(uint32_t(v), o));
      if (it != sum.end()) t = unit_or_zero(it->second - n * glm::dot(n, it->second));
      if (t != glm::dvec3(0.0)) break;
    }
    if (t == glm::dvec3(0.0)) t = any_orthogonal(n);
    for (int c = 0; c < 3; ++c) out[4 * v + size_t(c)] = float(t[c]);
    out[4 * v + 3] = preserving ? 1.0f : -1.0f;
  }
  return out;
}

}  // namespace pmr
