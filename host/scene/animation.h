// glTF animation sampling (DESIGN section 7, glTF 2.0 "Animations" and Appendix C): one sampler's
// keyframes evaluated at a time t. The scene's frame loop (issue 7) drives node TRS and morph weights
// with it; it is kept free of tinygltf so it can be tested on hand-computed values.
#pragma once
#include <string>
#include <vector>

namespace pmr {

enum class Interpolation { Step, Linear, CubicSpline };

// Parses a glTF interpolation name (LINEAR, STEP, CUBICSPLINE); throws pmr::Error on anything else.
Interpolation parse_interpolation(const std::string& name);

struct AnimationSampler {
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> times;   // strictly increasing, at least one key
  std::vector<float> values;  // keys x (3 for CubicSpline: in-tangent, value, out-tangent) x width
  int width = 3;              // floats per value: 3 (translation, scale), 4 (rotation), morph target count
  bool rotation = false;      // values are unit quaternions (x, y, z, w): slerp, renormalized
};

// The sampler's value at time t (seconds), `width` floats. Before the first key the first value, after
// the last key the last value. LINEAR rotations take the spherical interpolation on the shorter arc;
// CUBICSPLINE uses the Hermite basis with tangents multiplied by the key interval, and rotations are
// renormalized. Throws pmr::Error if the sampler is malformed (sizes that do not agree, no keys).
std::vector<float> sample(const AnimationSampler& s, double t);

}  // namespace pmr
