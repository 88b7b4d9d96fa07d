// Procedural environment images for the tests (tests/test_environment.cpp, tests/test_pbr.cpp, the
// command-line tests): the mapping inverted, maps made from a function of the direction, a sun and sky,
// and an OpenEXR writer.
#pragma once
#include <functional>
#include <string>

#include <glm/glm.hpp>

#include "shading/environment.h"

namespace pmr::test {

// The unit direction that image position (u, v) shows (host/shading/environment.h, inverted).
glm::dvec3 direction_of(double u, double v);
// A w x h map whose texel centers hold f(direction).
EnvironmentImage make_map(int w, int h, const std::function<glm::dvec3(glm::dvec3)>& f);
// The sun of sun_sky: at image position (0.6, 0.3), up and to the right of -Z.
glm::dvec3 sun_direction();
// A sky gradient, darker ground, and a sun disc of radius 3 degrees about 1000 times brighter.
glm::dvec3 sun_sky(glm::dvec3 d);
// R, G, B float channels.
void write_exr(const std::string& path, const EnvironmentImage& m);

}  // namespace pmr::test
