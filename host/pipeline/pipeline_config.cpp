// The run-wide choices of a pipeline (pipeline_config.h): method, sampling and shading names.
#include "pipeline/pipeline_config.h"

#include <cmath>

#include "pmr/error.h"

namespace pmr {

Method parse_method(const std::string& name) {
  if (name == "pmr") return Method::Pmr;
  if (name == "multipass") return Method::Multipass;
  if (name == "duplicate") return Method::Duplicate;
  throw Error("unknown method '" + name + "' (expected pmr, multipass or duplicate)");
}

const char* to_string(Method m) {
  switch (m) {
    case Method::Multipass:
      return "multipass";
    case Method::Duplicate:
      return "duplicate";
    default:
      return "pmr";
  }
}

Sampling parse_sampling(const std::string& name) {
  if (name == "view") return Sampling::View;
  if (name == "subpixel") return Sampling::Subpixel;
  throw Error("unknown sampling '" + name + "' (expected view or subpixel)");
}

const char* to_string(Sampling s) { return s == Sampling::Subpixel ? "subpixel" : "view"; }

Shading parse_shading(const std::string& name) {
  if (name == "lambert") return Shading::Lambert;
  if (name == "pbr") return Shading::Pbr;
  throw Error("unknown shading '" + name + "' (expected lambert or pbr)");
}

const char* to_string(Shading s) { return s == Shading::Pbr ? "pbr" : "lambert"; }

bool parse_on_off(const std::string& name, const std::string& option) {
  if (name == "on") return true;
  if (name == "off") return false;
  throw Error("unknown " + option + " '" + name + "' (expected on or off)");
}

bool parse_shadows(const std::string& name) { return parse_on_off(name, "--shadows"); }

TextureFilter parse_texture_filter(const std::string& name) {
  if (name == "bilinear") return TextureFilter::Bilinear;
  if (name == "trilinear") return TextureFilter::Trilinear;
  throw Error("unknown texture filter '" + name + "' (expected bilinear or trilinear)");
}

const char* to_string(TextureFilter f) { return f == TextureFilter::Trilinear ? "trilinear" : "bilinear"; }

void set_sample_pattern(int samples, double scale_x, double scale_y, PmrParams& P) {
  static const int one[] = PMR_SAMPLE_PATTERN_1, four[] = PMR_SAMPLE_PATTERN_4, eight[] = PMR_SAMPLE_PATTERN_8,
                   sixteen[] = PMR_SAMPLE_PATTERN_16;
  const int* pattern = samples == 1    ? one
                       : samples == 4  ? four
                       : samples == 8  ? eight
                       : samples == 16 ? sixteen
                                       : nullptr;
  if (!pattern) throw Error("invalid --samples " + std::to_string(samples) + ": use 1, 4, 8 or 16");
  P.samples = uint32_t(samples);
  for (int s = 0; s < PMR_MAX_SAMPLES; ++s) {  // 1/16 pixel to 16.16 / 24.8, rounded to the grid
    P.sample_x[s] = s < samples ? int32_t(std::lround(pattern[2 * s] * scale_x * (PMR_X_ONE / 16))) : 0;
    P.sample_y[s] = s < samples ? int32_t(std::lround(pattern[2 * s + 1] * scale_y * (PMR_Y_ONE / 16))) : 0;
  }
}

void check_subpixel_sampling(Method method, const Display& display) {
  if (method != Method::Pmr) throw Error("--sampling subpixel renders with --method pmr");
  if (display.bilinear || display.blend_views)
    throw Error(
        "--sampling subpixel computes every subpixel at its own sample: --bilinear and --blend-views "
        "apply to --sampling view only");
}

}  // namespace pmr
