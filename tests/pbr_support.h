// Helpers of the --shading pbr tests against the double-precision reference (tests/reference): the
// model's inputs at a voxel, the default light and uniform environment as the reference states them,
// the 1% + 1e-3 bound per channel, and scenes of flat layers.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "reference/pbr_reference.h"
#include "test_util.h"

namespace pmr::test {

// The model's inputs at source barycentrics b of triangle `tri` seen from view `view`, computed from the
// scene's material inputs (tests/reference/material_reference.h), for the reference.
ref::SurfacePoint surface_at(const Scene& s, const Rig& rig, uint32_t tri, const glm::dvec3& b, bool back, int view);

// The model's bound on one voxel of a render: 1% relative plus 1e-3 absolute per colour channel.
// Counts the channels outside it (reporting the first five) and the largest error as a fraction of it.
struct BoundCheck {
  size_t bad = 0;
  double worst = 0.0;
  void voxel(const Rendered& out, size_t v, const glm::dvec3& want, const std::string& what = "voxel");
};

// The defaults: one directional light toward the rig's light direction with E = 0.8 pi, a uniform
// environment of radiance 0.2 (I = P = 0.2) and the split-sum table the kernels are given.
std::vector<ref::PunctualLight> default_light(const Rig& rig);
ref::EnvironmentTerms uniform_environment(double radiance);

// Scenes of flat layers: a rectangle [x0, x1] x [y0, y1] at depth z facing +Z (the camera) as two
// triangles; a material appended (its index returned); an unlit material of colour c (alpha 1).
void quad(Scene& s, float x0, float y0, float x1, float y1, float z, uint32_t material);
uint32_t add_material(Scene& s, const PmrMaterial& m);
PmrMaterial unlit(glm::vec3 c);

}  // namespace pmr::test
