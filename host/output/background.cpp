#include "output/background.h"

#include <half.h>

#include <array>
#include <cmath>
#include <cstdio>
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

BackdropDepth parse_backdrop_depth(const std::string& text) {
  if (text == "focal") return {};
  if (text == "inf") return {BackdropDepth::Kind::Infinity, 0.0};
  char* end = nullptr;
  const double z = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(z) || z <= 0.0)
    throw Error("invalid --background-depth '" + text +
                "': expected focal, inf or a depth > 0 in scene units from the center camera");
  return {BackdropDepth::Kind::Distance, z};
}

std::string to_string(const BackdropDepth& depth) {
  if (depth.kind == BackdropDepth::Kind::Focal) return "focal";
  if (depth.kind == BackdropDepth::Kind::Infinity) return "inf";
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", depth.distance);
  return text;
}

Background parse_background(const std::string& text) {
  if (text == "environment") {
    Background bg;
    bg.environment = true;
    return bg;
  }
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const double d = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(d) || d < 0.0 || d > 65504.0)
      throw Error("invalid --background '" + text +
                  "': expected environment, R,G,B or R,G,B,A, linear values >= 0 (e.g. 0,0,0,1 for opaque black)");
    v.push_back(d);
  }
  if (v.size() != 3 && v.size() != 4)
    throw Error("invalid --background '" + text +
                "': expected environment, R,G,B or R,G,B,A (e.g. 0,0,0,1 for opaque black)");
  Background bg;
  bg.r = v[0], bg.g = v[1], bg.b = v[2], bg.a = v.size() == 4 ? v[3] : 1.0;
  if (bg.a > 1.0) throw Error("invalid --background '" + text + "': alpha is at most 1");
  return bg;
}

namespace {

// The environment's layer of `pixels` pixels (an internal error when the frame did not make it).
const uint16_t* backdrop_layer(const Background& bg, bool display, size_t pixels) {
  const BackdropLayers* l = bg.layers.get();
  const std::vector<uint16_t>* layer = l ? (display ? &l->display : &l->volume) : nullptr;
  if (!layer || layer->size() != pixels * 4) throw InternalError("the environment background's layers do not fit");
  return layer->data();
}

// The colour behind every pixel, premultiplied RGBA.
std::array<float, 4> premultiplied(const Background& bg) {
  return {float(bg.r * bg.a), float(bg.g * bg.a), float(bg.b * bg.a), float(bg.a)};
}

}  // namespace

void composite_rgba(uint16_t* px, size_t pixels, const Background& bg) {
  if (bg.transparent()) return;
  const uint16_t* layer = bg.environment ? backdrop_layer(bg, false, pixels) : nullptr;
  const std::array<float, 4> colour = premultiplied(bg);
  for (size_t i = 0; i < pixels; ++i, px += 4) {
    const float keep = 1.0f - from_half(px[3]);
    if (keep == 0.0f) continue;  // covered: unchanged
    for (int c = 0; c < 4; ++c) {
      const float under = layer ? from_half(layer[4 * i + size_t(c)]) : colour[size_t(c)];
      px[c] = to_half(from_half(px[c]) + keep * under);
    }
  }
}

void composite_encoded(uint16_t* px, uint16_t* sub, size_t pixels, const Background& bg) {
  if (bg.transparent()) return;
  const uint16_t* layer = bg.environment ? backdrop_layer(bg, true, pixels) : nullptr;
  const std::array<float, 4> colour = premultiplied(bg);
  for (size_t i = 0; i < pixels; ++i, px += 4, sub += 3) {
    float mean = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const float a = from_half(sub[k]), keep = 1.0f - a;
      const float under = layer ? from_half(layer[4 * i + size_t(k)]) : colour[size_t(k)];
      const float under_alpha = layer ? 1.0f : colour[3];
      px[k] = to_half(from_half(px[k]) + keep * under);
      const float out = a + keep * under_alpha;
      sub[k] = to_half(out);
      mean += out;
    }
    px[3] = to_half(mean / 3.0f);
  }
}

}  // namespace pmr
