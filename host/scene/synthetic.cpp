// Procedural scenes for triangle-count sweeps (`pmr bench --synthetic TRIS`, `--objects TRIS`).
#include <algorithm>
#include <cmath>
#include <random>

#include "pmr/error.h"
#include "pmr/scene.h"

namespace pmr {

Scene make_synthetic_scene(size_t triangles, uint32_t seed) {
  if (triangles < 1 || triangles > 50000000) throw Error("invalid --synthetic: expected 1 to 50000000 triangles");
  const int stacks = 8, slices = 14;  // 2 * slices * (stacks - 1) = 196 triangles a sphere
  const size_t per_sphere = size_t(2 * slices * (stacks - 1));
  const size_t spheres = std::max<size_t>(1, (triangles + per_sphere / 2) / per_sphere);
  Scene s;
  s.materials.push_back(default_material());
  s.materials[0].metallic = 0.0f, s.materials[0].roughness = 0.5f;  // painted plastic under --shading pbr
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // radius shrinks with the count so that the spheres keep a similar total screen coverage
  const float base_r = 0.35f / std::cbrt(float(spheres));
  for (size_t k = 0; k < spheres; ++k) {
    const glm::vec3 c(4.0f * u(rng) - 2.0f, 2.0f * u(rng) - 1.0f, 3.0f * u(rng) - 1.5f);
    const float r = base_r * (0.5f + u(rng));
    const float col[4] = {0.2f + 0.8f * u(rng), 0.2f + 0.8f * u(rng), 0.2f + 0.8f * u(rng), 1.0f};
    const uint32_t base = uint32_t(s.positions.size());
    for (int i = 0; i <= stacks; ++i) {
      const float th = float(M_PI) * float(i) / stacks;
      for (int j = 0; j < slices; ++j) {
        const float ph = 2.0f * float(M_PI) * float(j) / slices;
        const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        s.positions.push_back(c + r * n);
        PmrVertexAttr a{};
        a.scale = 1.0f;
        a.normal[0] = n.x, a.normal[1] = n.y, a.normal[2] = n.z;
        for (int q = 0; q < 4; ++q) a.color[q] = col[q];
        s.attributes.push_back(a);
      }
    }
    auto at = [&](int i, int j) { return base + uint32_t(i * slices + (j % slices)); };
    for (int i = 0; i < stacks; ++i)
      for (int j = 0; j < slices; ++j) {
        // counter-clockwise seen from outside
        const uint32_t q[4] = {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)};
        const uint32_t tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
        for (int t = 0; t < 2; ++t) {
          if ((i == 0 && t == 0) || (i == stacks - 1 && t == 1)) continue;  // degenerate at the poles
          PmrTriangle pt{};
          pt.v[0] = tri[t][0], pt.v[1] = tri[t][1], pt.v[2] = tri[t][2];
          const glm::vec3 e =
              glm::cross(s.positions[pt.v[1]] - s.positions[pt.v[0]], s.positions[pt.v[2]] - s.positions[pt.v[0]]);
          const glm::vec3 fn = glm::length(e) > 0 ? glm::normalize(e) : glm::vec3(0, 0, 1);
          pt.face_normal[0] = fn.x, pt.face_normal[1] = fn.y, pt.face_normal[2] = fn.z;
          pt.has_normals = 1;
          s.triangles.push_back(pt);
        }
      }
  }
  return s;
}

namespace {

// x^e keeping the sign of x (superquadric "signed power").
float signed_pow(float x, float e) { return std::copysign(std::pow(std::fabs(x), e), x); }

float snap(float x) { return std::fabs(x) < 1e-6f ? 0.0f : x; }

// A uniformly random rotation (Shoemake's quaternion method).
glm::mat3 random_rotation(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float a = u(rng), b = 2.0f * float(M_PI) * u(rng), c = 2.0f * float(M_PI) * u(rng);
  const float s1 = std::sqrt(1.0f - a), s2 = std::sqrt(a);
  const float x = s1 * std::sin(b), y = s1 * std::cos(b), z = s2 * std::sin(c), w = s2 * std::cos(c);
  return glm::mat3(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),   // column 0
                   2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),   // column 1
                   2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));  // column 2
}

// Appends the triangles of a closed (u, v) grid: u wraps around, v runs from ring 0 to ring rings - 1;
// `wrap_v` closes v as well (torus), otherwise rings 0 and rings - 1 are poles (every vertex of the
// ring at one point) and the triangles that would collapse there are left out. Each triangle is wound
// counter-clockwise around the outward vertex normal.
void add_grid(Scene& s, uint32_t base, int segments, int rings, bool wrap_v, uint32_t material) {
  auto at = [&](int i, int j) { return base + uint32_t((i % rings) * segments + (j % segments)); };
  const int bands = wrap_v ? rings : rings - 1;
  for (int i = 0; i < bands; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t q[4] = {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)};
      const uint32_t tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
      for (int t = 0; t < 2; ++t) {
        if (!wrap_v && ((i == 0 && t == 0) || (i == rings - 2 && t == 1))) continue;
        PmrTriangle pt{};
        pt.v[0] = tri[t][0], pt.v[1] = tri[t][1], pt.v[2] = tri[t][2];
        pt.material = material;
        const glm::vec3 p0 = s.positions[pt.v[0]], p1 = s.positions[pt.v[1]], p2 = s.positions[pt.v[2]];
        glm::vec3 e = glm::cross(p1 - p0, p2 - p0);
        glm::vec3 n(0.0f);
        for (uint32_t v : pt.v)
          n += glm::vec3(s.attributes[v].normal[0], s.attributes[v].normal[1], s.attributes[v].normal[2]);
        if (glm::dot(e, n) < 0.0f) std::swap(pt.v[1], pt.v[2]), e = -e;
        const glm::vec3 fn = glm::length(e) > 0 ? glm::normalize(e) : glm::vec3(0, 0, 1);
        pt.face_normal[0] = fn.x, pt.face_normal[1] = fn.y, pt.face_normal[2] = fn.z;
        pt.has_normals = 1;
        s.triangles.push_back(pt);
      }
    }
}

}  // namespace

Scene make_objects_scene(size_t triangles, uint32_t seed) {
  if (triangles < 1 || triangles > 50000000) throw Error("invalid --objects: expected 1 to 50000000 triangles");
  // 100 objects from 10,000 triangles up; fewer (100 triangles each) below, so that small counts stay
  // meshes rather than tetrahedra. Their radius shrinks with the count to keep the covered screen area.
  const size_t objects = std::clamp<size_t>(triangles / 100, 1, 100);
  const double per_object = double(triangles) / double(objects);
  const float base_r = 0.28f / std::sqrt(float(objects) / 100.0f);
  Scene s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (size_t k = 0; k < objects; ++k) {
    PmrMaterial m = default_material();
    m.metallic = 0.0f, m.roughness = 0.5f;  // painted plastic under --shading pbr
    m.base_color[0] = 0.15f + 0.85f * u(rng), m.base_color[1] = 0.15f + 0.85f * u(rng),
    m.base_color[2] = 0.15f + 0.85f * u(rng);
    m.double_sided = 1;
    const uint32_t material = uint32_t(s.materials.size());
    s.materials.push_back(m);
    const glm::vec3 centre(4.0f * u(rng) - 2.0f, 2.0f * u(rng) - 1.0f, 3.0f * u(rng) - 1.5f);
    const float r = base_r * (0.4f + 0.8f * u(rng));
    const glm::vec3 scale = r * glm::vec3(0.6f + 0.8f * u(rng), 0.6f + 0.8f * u(rng), 0.6f + 0.8f * u(rng));
    const glm::mat3 rot = random_rotation(rng);
    const bool torus = u(rng) < 0.4f;
    const float e1 = 0.25f + 0.75f * u(rng), e2 = 0.25f + 0.75f * u(rng);  // superquadric: box .. ellipsoid
    const float minor = 0.25f + 0.2f * u(rng);                             // torus tube / ring radius
    // 2 * segments * rings triangles (torus) or 2 * segments * (rings - 2) (poles), segments ~ 2 * rings
    const int rings = std::max(3, int(std::lround(std::sqrt(per_object / 4.0) + (torus ? 0.0 : 1.5))));
    const int bands = torus ? rings : rings - 2;
    const int segments = std::max(3, int(std::lround(per_object / (2.0 * bands))));
    const uint32_t base = uint32_t(s.positions.size());
    for (int i = 0; i < rings; ++i)
      for (int j = 0; j < segments; ++j) {
        const float ph = 2.0f * float(M_PI) * float(j) / float(segments);
        glm::vec3 p, n;
        if (torus) {
          const float th = 2.0f * float(M_PI) * float(i) / float(rings);
          const glm::vec3 ring(std::cos(ph), 0.0f, std::sin(ph));
          n = std::cos(th) * ring + glm::vec3(0.0f, std::sin(th), 0.0f);
          p = ring + minor * n;
        } else {
          const float th = float(M_PI) * float(i) / float(rings - 1);
          // exact zeros at the poles and quarter turns: a signed power would blow sin(pi) = -8.7e-8 up
          // to a visible hole at the pole
          const float st = snap(std::sin(th)), ct = snap(std::cos(th)), sp = snap(std::sin(ph)),
                      cp = snap(std::cos(ph));
          p = glm::vec3(signed_pow(st, e1) * signed_pow(cp, e2), signed_pow(ct, e1),
                        signed_pow(st, e1) * signed_pow(sp, e2));
          n = glm::vec3(signed_pow(st, 2 - e1) * signed_pow(cp, 2 - e2), signed_pow(ct, 2 - e1),
                        signed_pow(st, 2 - e1) * signed_pow(sp, 2 - e2));
        }
        // the normal of a scaled surface goes with the inverse scale
        n = rot * (n / scale);
        n = glm::length(n) > 0 ? glm::normalize(n) : glm::vec3(0, 1, 0);
        s.positions.push_back(centre + rot * (scale * p));
        PmrVertexAttr a{};
        a.scale = 1.0f;
        a.normal[0] = n.x, a.normal[1] = n.y, a.normal[2] = n.z;
        for (float& c : a.color) c = 1.0f;
        s.attributes.push_back(a);
      }
    add_grid(s, base, segments, rings, torus, material);
  }
  return s;
}

}  // namespace pmr
