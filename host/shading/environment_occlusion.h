// The environment's occlusion (DESIGN section 4d): with shadows on, the light an environment sends to a
// surface point is scaled by the fraction of it that arrives past the scene. The estimator
// (docs/SHADING.md, "The environment's occlusion"):
// - kOcclusionDirections directions toward the environment, spread evenly over the sphere (a Fibonacci
//   sphere about +Y), each with an orthographic shadow map over the scene, rendered once per frame and
//   read by every view like a sun's;
// - each direction weighs the environment's radiance about it: the luminance of the prefiltered
//   environment P(d, kOcclusionWeightRoughness), whose GGX lobe is about as wide as the patch of the
//   sphere a direction stands for (1 for the uniform environment);
// - the diffuse term's visibility is the mean of the directions' visibilities weighted by radiance x
//   cosine at the receiver (directions below its horizon are not read), the specular term's weighted by
//   radiance x cosine x a lobe about the reflected direction (cl/lights.h, environment_visibility_lanes).
// The lights taken out of the environment (the studio's boxes, an image's suns) have their own maps:
// a point in a sun's shadow keeps its sky light.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "shading/environment.h"

namespace pmr {

constexpr int kOcclusionDirections = 64;
constexpr double kOcclusionWeightRoughness = 0.6;

struct OcclusionDirection {
  glm::dvec3 toward;  // unit, world space: toward the environment
  double weight;      // the environment's luminance about it, > 0
};

// The directions of the environment `env` (null: the uniform environment, at `uniform_intensity`),
// those of zero weight left out; none for an environment turned off (intensity 0).
std::vector<OcclusionDirection> occlusion_directions(const Environment* env, double uniform_intensity);

}  // namespace pmr
