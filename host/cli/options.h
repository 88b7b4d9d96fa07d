// Command-line options of `pmr render` (and their defaults: the paper-8k preset).
#pragma once
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "pmr/input_files.h"
#include "pmr/display_presets.h"
#include "output/background.h"
#include "pmr/rig.h"
#include "sequence/frame_files.h"
#include "sequence/frame_names.h"

namespace pmr {

// --exposure EV, --environment-intensity X and --environment-rotation DEG, checked (shared by render
// and bench).
double parse_exposure(const std::string& text);
double parse_environment_intensity(const std::string& text);
double parse_environment_rotation(const std::string& text);
// Checks --environment and --environment-rotation against the shading model: an environment image
// lights --shading pbr only (an error with lambert); a rotation without an image is a warning, added
// to `warnings`.
void check_environment_options(const std::string& file, bool rotation_given, Shading shading,
                               std::vector<std::string>& warnings);

struct RenderOptions {
  std::string scene;       // empty = the bundled default scene
  FrameProducts products;  // --out, --name, --write, --preview
  RigConfig rig;
  Display display;
  std::string display_source = "preset paper-8k";  // what the display came from (sidecar)
  bool has_calibration = false;                    // --display-config: the file's values
  LookingGlassCalibration calibration;
  std::vector<std::string> option_warnings;  // e.g. calibration fields read but ignored
  bool offset_given = false;                 // else offset = -L / (2N), which centres every subpixel in its view
  PipelineConfig pipeline;
  std::string quilt;  // --quilt CxR; empty = chosen from the view count and size
  std::string compression = "zip";
  // Sequences (DESIGN section 7)
  std::string frames = "0";  // --frames LIST, or "all"
  double fps = 24.0;
  std::string animation;  // --animation NAME|INDEX|all; empty = the first animation
  bool turntable = false;
  double turntable_deg = 0.0;
  long turntable_frames = 0;
  bool resume = false, overwrite = false, quiet = false;
  std::string shard;  // --shard K/N or auto; empty = every frame
  long shard_count = 0, shard_first = 0;
  bool verbose = false;
  bool help = false;
  bool preset_help = false;   // --preset help
  bool method_given = false;  // --method was on the command line
  // pbr: --environment FILE (relative to the current folder; "" = the uniform default) and its
  // --environment-rotation (the intensity is pipeline.environment_intensity)
  std::string environment_file;
  double environment_rotation_deg = 0.0;
  bool environment_rotation_given = false;
  // --limit KEY=VALUE,... and --allow-outside-scene-folder (docs/SECURITY.md)
  InputLimits input_limits;
  bool zoom_given = false;            // --zoom was on the command line (rig.zoom)
  Background background;              // --background R,G,B[,A]; transparent black by default
  bool quilt_preview_opaque = false;  // the quilt PNG over opaque black (Looking Glass presets)
  // --sampling was on the command line; else pipeline.sampling is the preset's default, and subpixel
  // sampling gives way to view sampling (with a notice) where other options need the views
  bool sampling_given = false;
};

// Parses the arguments after `render`. Throws pmr::Error with one line on bad input.
RenderOptions parse_render_options(const std::vector<std::string>& args);
// Fills in derived defaults (the encoder offset) once all options are known.
void finalize_render_options(RenderOptions& options);
std::string render_help();
std::string main_help();

}  // namespace pmr
