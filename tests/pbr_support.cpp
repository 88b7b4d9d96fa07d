#include "pbr_support.h"

#include <gtest/gtest.h>

#include <Imath/half.h>

#include <glm/gtc/constants.hpp>

#include "reference/material_reference.h"
#include "shading/environment.h"

namespace pmr::test {

// The model's inputs at source barycentrics b of triangle `tri` seen from view `view`, computed here
// from the scene's material inputs (tests/reference/material_reference.h), for the reference.
ref::SurfacePoint surface_at(const Scene& s, const Rig& rig, uint32_t tri, const glm::dvec3& b, bool back, int view) {
  const PmrTriangle& t = s.triangles[tri];
  ref::SurfacePoint sp;
  ref::material_at(s, tri, b, back, sp);
  sp.p = glm::dvec3(0.0);
  for (int k = 0; k < 3; ++k) sp.p += b[k] * glm::dvec3(s.positions[t.v[k]]);
  sp.eye = glm::dvec3(glm::inverse(rig.view_matrix(view))[3]);
  return sp;
}

// The model's bound on one voxel of a render: 1% relative plus 1e-3 absolute per colour channel.
// Counts the channels outside it (reporting the first five) and the largest error as a fraction of it.
void BoundCheck::voxel(const Rendered& out, size_t v, const glm::dvec3& want, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    half got;
    got.setBits(out.volume[v * 4 + size_t(c)]);
    const double err = std::abs(double(float(got)) - want[c]), tol = 0.01 * std::abs(want[c]) + 1e-3;
    worst = std::max(worst, err / tol);
    if (err > tol && ++bad <= 5)
      ADD_FAILURE() << what << " " << v << " channel " << c << ": " << float(got) << " vs " << want[c];
  }
}

// The defaults: one directional light toward the rig's light direction with E = 0.8 pi, a uniform
// environment of radiance 0.2 (I = P = 0.2) and the split-sum table the kernels are given.
std::vector<ref::PunctualLight> default_light(const Rig& rig) {
  ref::PunctualLight l;
  l.type = ref::LightType::Directional;
  l.direction = -rig.light_world();
  l.color_intensity = glm::dvec3(0.8 * glm::pi<double>());
  return {l};
}

ref::EnvironmentTerms uniform_environment(double radiance) {
  ref::EnvironmentTerms env;
  env.irradiance = [=](const glm::dvec3&) { return glm::dvec3(radiance); };
  env.prefiltered = [=](const glm::dvec3&, double) { return glm::dvec3(radiance); };
  env.split_sum = [](double nv, double r) { return split_sum(nv, r); };
  return env;
}

void quad(Scene& s, float x0, float y0, float x1, float y1, float z, uint32_t material) {
  add_triangle(s, {x0, y0, z}, {x1, y0, z}, {x1, y1, z}, material);
  add_triangle(s, {x0, y0, z}, {x1, y1, z}, {x0, y1, z}, material);
}

uint32_t add_material(Scene& s, const PmrMaterial& m) {
  s.materials.push_back(m);
  return uint32_t(s.materials.size() - 1);
}

PmrMaterial unlit(glm::vec3 c) {
  PmrMaterial m = default_material();
  m.unlit = 1;
  m.base_color[0] = c.x, m.base_color[1] = c.y, m.base_color[2] = c.z;
  return m;
}

}  // namespace pmr::test
