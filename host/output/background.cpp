#include "output/background.h"

#include <half.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "pmr/error.h"

namespace pmr {

namespace {

float from_half(uint16_t bits) {
  half h;
  h.setBits(bits);
  return float(h);
}

uint16_t to_half(float v) { return half(v).bits(); }

}  // namespace

Background parse_background(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const double d = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(d) || d < 0.0 || d > 65504.0)
      throw Error("invalid --background '" + text +
                  "': expected R,G,B or R,G,B,A, linear values >= 0 (e.g. 0,0,0,1 for opaque black)");
    v.push_back(d);
  }
  if (v.size() != 3 && v.size() != 4)
    throw Error("invalid --background '" + text + "': expected R,G,B or R,G,B,A (e.g. 0,0,0,1 for opaque black)");
  Background bg{v[0], v[1], v[2], v.size() == 4 ? v[3] : 1.0};
  if (bg.a > 1.0) throw Error("invalid --background '" + text + "': alpha is at most 1");
  return bg;
}

void composite_rgba(uint16_t* px, size_t pixels, const Background& bg) {
  if (bg.transparent()) return;
  const float b[4] = {float(bg.r * bg.a), float(bg.g * bg.a), float(bg.b * bg.a), float(bg.a)};
  for (size_t i = 0; i < pixels; ++i, px += 4) {
    const float keep = 1.0f - from_half(px[3]);
    if (keep == 0.0f) continue;  // covered: unchanged
    for (int c = 0; c < 4; ++c) px[c] = to_half(from_half(px[c]) + keep * b[c]);
  }
}

void composite_encoded(uint16_t* px, uint16_t* sub, size_t pixels, const Background& bg) {
  if (bg.transparent()) return;
  const float b[3] = {float(bg.r * bg.a), float(bg.g * bg.a), float(bg.b * bg.a)};
  for (size_t i = 0; i < pixels; ++i, px += 4, sub += 3) {
    float mean = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const float a = from_half(sub[k]), keep = 1.0f - a;
      px[k] = to_half(from_half(px[k]) + keep * b[k]);
      const float out = a + keep * float(bg.a);
      sub[k] = to_half(out);
      mean += out;
    }
    px[3] = to_half(mean / 3.0f);
  }
}

}  // namespace pmr
