// Display presets: the paper's panel and the Looking Glass panels with their maker's typical
// calibrations (Looking Glass Bridge's device templates, as LKG-Toolkit's HardCodedLKGDeviceTemplates
// carries them) and recommended quilts. A real panel's own visual.json (--display-config) is always
// better than a preset's typical calibration.
#include "pmr/display_presets.h"
#include "pmr/error.h"

namespace pmr {

namespace {

DisplayPreset looking_glass(const char* name, const char* description, int w, int h, double dpi, double pitch,
                            double slope, double center, double cone, int views, int tile_w, int tile_h,
                            const char* quilt) {
  LookingGlassCalibration c;
  c.screen_w = w, c.screen_h = h, c.dpi = dpi, c.pitch = pitch, c.slope = slope, c.center = center, c.view_cone = cone;
  DisplayPreset p;
  p.name = name;
  p.description = description;
  p.display = display_from_calibration(c);
  p.rig.views = views;
  p.rig.view_w = tile_w, p.rig.view_h = tile_h;
  p.rig.cone_deg = cone;
  p.quilt = quilt;
  return p;
}

std::vector<DisplayPreset> make_presets() {
  std::vector<DisplayPreset> all;
  DisplayPreset paper;
  paper.name = "paper-8k";
  paper.description =
      "the PMR paper's 8K lenticular panel: 7680x4320, 166x93 cm at 200 cm, 96 views of 1024x512, 80 deg";
  paper.quilt = "8x12";
  all.push_back(paper);
  // name, description, screen, DPI, pitch, slope, center, view cone, views, tile, quilt
  all.push_back(looking_glass("lg-portrait", "Looking Glass Portrait (LKG-P): 1536x2048, 7.9\", 48 views of 420x560",
                              1536, 2048, 324, 52, -7, 0.5, 40, 48, 420, 560, "8x6"));
  all.push_back(looking_glass("lg-go", "Looking Glass Go (LKG-E): 1440x2560, 6\", 66 views of 372x682", 1440, 2560, 491,
                              80.7, -6.3, -0.3, 54, 66, 372, 682, "11x6"));
  all.push_back(looking_glass("lg-16",
                              "Looking Glass 16\" Spatial, landscape (LKG-J; typical calibration without its "
                              "subpixel cells): 3840x2160, 49 views of 857x857",
                              3840, 2160, 283, 44.72, -6.9, 0.5, 50, 49, 857, 857, "7x7"));
  all.push_back(looking_glass("lg-16-portrait",
                              "Looking Glass 16\" Spatial, portrait (LKG-H; without its subpixel "
                              "cells): 2160x3840, 66 views of 545x1000",
                              2160, 3840, 283, 44.72, -7.45, 0.0, 50, 66, 545, 1000, "11x6"));
  all.push_back(looking_glass("lg-32",
                              "Looking Glass 32\" Spatial, landscape (LKG-L): 7680x4320, 49 views of 1170x1170", 7680,
                              4320, 280, 75, -7.2, -0.2, 50, 49, 1170, 1170, "7x7"));
  all.push_back(looking_glass("lg-32-portrait",
                              "Looking Glass 32\" Spatial, portrait (LKG-K): 4320x7680, 66 views of 744x1364", 4320,
                              7680, 280, 80.7, -6.3, -0.3, 54, 66, 744, 1364, "11x6"));
  all.push_back(looking_glass("lg-16-gen2", "Looking Glass 16\" Gen2 (LKG-A): 3840x2160, 45 views of 819x455", 3840,
                              2160, 283, 50, -7, 0.5, 40, 45, 819, 455, "5x9"));
  all.push_back(looking_glass("lg-32-gen2", "Looking Glass 32\" Gen2 (LKG-B): 7680x4320, 45 views of 1638x910", 7680,
                              4320, 280, 42, -6, 0.3, 40, 45, 1638, 910, "5x9"));
  // Subpixel sampling by default where it halves the error of view sampling for at most 1.5x its time,
  // both with the preset's angular spacing (measured: docs/SAMPLING.md, "Which default"). The panels
  // with more subpixels per view voxel (the 32" and Gen2 ones) cost 1.7-2.5x and keep view sampling.
  for (DisplayPreset& p : all)
    p.subpixel_sampling =
        p.name == "lg-portrait" || p.name == "lg-go" || p.name == "lg-16" || p.name == "lg-16-portrait";
  return all;
}

}  // namespace

const std::vector<DisplayPreset>& display_presets() {
  static const std::vector<DisplayPreset> presets = make_presets();
  return presets;
}

const DisplayPreset& find_display_preset(const std::string& name) {
  for (const DisplayPreset& p : display_presets())
    if (p.name == name) return p;
  std::string names;
  for (const DisplayPreset& p : display_presets()) names += (names.empty() ? "" : ", ") + p.name;
  throw Error("unknown --preset '" + name + "' (known: " + names + "; pmr render --preset help)");
}

std::string display_presets_help() {
  std::string s =
      "display presets (pmr render --preset NAME; a panel's own calibration: --display-config visual.json):\n";
  for (const DisplayPreset& p : display_presets())
    s += "  " + p.name + std::string(16 - p.name.size(), ' ') + p.description + "\n";
  return s;
}

}  // namespace pmr
