#include "environment_maps.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <cmath>

namespace pmr::test {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

glm::dvec3 direction_of(double u, double v) {
  const double th = kPi * v, ph = 2.0 * kPi * (u - 0.5);
  return {std::sin(th) * std::sin(ph), std::cos(th), -std::sin(th) * std::cos(ph)};
}

EnvironmentImage make_map(int w, int h, const std::function<glm::dvec3(glm::dvec3)>& f) {
  EnvironmentImage m;
  m.width = w, m.height = h;
  m.rgb.resize(size_t(w) * size_t(h) * 3);
  for (int i = 0; i < h; ++i)
    for (int j = 0; j < w; ++j) {
      const glm::dvec3 v = f(direction_of((j + 0.5) / w, (i + 0.5) / h));
      for (int c = 0; c < 3; ++c) m.rgb[(size_t(i) * size_t(w) + size_t(j)) * 3 + size_t(c)] = float(v[c]);
    }
  return m;
}

glm::dvec3 sun_direction() { return glm::normalize(direction_of(0.6, 0.3)); }

glm::dvec3 sun_sky(glm::dvec3 d) {
  static const glm::dvec3 sun = sun_direction();
  if (glm::dot(d, sun) > std::cos(3.0 * kPi / 180)) return {2000.0, 1800.0, 1500.0};
  if (d.y < 0) return glm::dvec3(0.12, 0.1, 0.08) * (1 + 0.5 * d.x);
  return glm::dvec3(0.4, 0.6, 1.0) * (0.5 + 1.5 * d.y) + glm::dvec3(0.2, 0.1, 0.0) * (1 - d.y);
}

void write_exr(const std::string& path, const EnvironmentImage& m) {
  Imf::Header h(m.width, m.height);
  h.channels().insert("R", Imf::Channel(Imf::FLOAT));
  h.channels().insert("G", Imf::Channel(Imf::FLOAT));
  h.channels().insert("B", Imf::Channel(Imf::FLOAT));
  Imf::OutputFile f(path.c_str(), h);
  Imf::FrameBuffer fb;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(m.rgb.data() + c), 12, 12 * size_t(m.width)));
  f.setFrameBuffer(fb);
  f.writePixels(m.height);
}

}  // namespace pmr::test
