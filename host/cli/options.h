// Command-line options of `pmr render` (and their defaults: the paper-8k preset).
#pragma once
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "pmr/rig.h"

namespace pmr {

struct RenderOptions {
  std::string scene;            // empty = the bundled default scene
  std::string out_dir = "out";
  RigConfig rig;
  Display display;
  bool offset_given = false;    // else offset = -L / (2N), which centres every subpixel in its view
  PipelineConfig pipeline;
  bool write_encoded = true;
  bool write_views = false;
  std::string compression = "zip";
  int frame = 0;
  bool verbose = false;
  bool help = false;
};

// Parses the arguments after `render`. Throws pmr::Error with one line on bad input.
RenderOptions parse_render_options(const std::vector<std::string>& args);
// Fills in derived defaults (the encoder offset) once all options are known.
void finalize_render_options(RenderOptions& options);
std::string render_help();
std::string main_help();

}  // namespace pmr
