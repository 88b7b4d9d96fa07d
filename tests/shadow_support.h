// Shared by the shadow tests (DESIGN section 4d): small scenes of quads, boxes and spheres, the frame's
// shadow maps as the pipeline renders them, and cl/lights.h's lookups run on them at given receivers
// (tests/probes/shadow_probe.cl).
#pragma once
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/scene.h"
#include "pmr/shared.h"
#include "shading/environment.h"

namespace pmr::test {

// A quad of two triangles with corners a, b, c, d (counter-clockwise seen from the front).
void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d);
// The box [lo, hi], its faces outward.
void add_box(Scene& s, glm::vec3 lo, glm::vec3 hi);
// A sphere of radius r about c, `rings` x 2 `rings` facets, outward.
void add_sphere(Scene& s, glm::vec3 c, float r, int rings);

// The frame's shadow maps of scene `s` (its lights) as the pipeline renders them, with shadows on: the
// lights' maps, then the environment's occlusion maps when the environment (`env`, null: the uniform
// one at `uniform_intensity`) is on. The default, a black uniform environment, gives the lights' alone.
struct ShadowMaps {
  std::vector<PmrShadowMap> maps;
  std::vector<float> depth;
};
ShadowMaps render_maps(const Scene& s, const std::shared_ptr<const Environment>& env = nullptr,
                       double uniform_intensity = 0.0);

// A receiver: a point on a surface and that surface's unit normal.
struct Receiver {
  glm::dvec3 p, n;
};

// cl/lights.h's shadow_visibility_lanes of `light`, whose maps are all of m's, at each receiver.
std::vector<float> probe(const ShadowMaps& m, const SceneLight& light, const std::vector<Receiver>& at);

// cl/lights.h's environment_visibility_lanes with m's last `directions` maps, at each receiver (its
// normal both the face's and the shading normal) for the reflected direction reflected[i] and the
// lobe's sharpness: per receiver the diffuse and the specular visibility.
std::vector<glm::vec2> probe_environment(const ShadowMaps& m, int directions, const std::vector<Receiver>& at,
                                         const std::vector<glm::dvec3>& reflected, float sharpness);

}  // namespace pmr::test
