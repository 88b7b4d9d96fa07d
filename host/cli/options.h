// Command-line options of `pmr render` (and their defaults: the paper-8k preset).
#pragma once
#include <string>
#include <vector>

#include "pipeline/pipeline_config.h"
#include "sequence/frame_names.h"
#include "sequence/sequence_job.h"

namespace pmr {

// --exposure EV, --environment-intensity X and --environment-rotation DEG, checked (shared by render
// and bench).
double parse_exposure(const std::string& text);
int parse_samples(const std::string& text);                    // --samples: 1, 4, 8 or 16
std::vector<int> parse_samples_list(const std::string& text);  // a comma list of them (bench, quality)
double parse_environment_intensity(const std::string& text);
double parse_environment_rotation(const std::string& text);
// --environment studio|uniform|FILE (EnvironmentSource::parse).
EnvironmentSource parse_environment(const std::string& text);
// Checks --environment and --environment-rotation against the shading model: an environment given on
// the command line lights --shading pbr only (an error with lambert); a rotation of the uniform
// environment, or with lambert, is a warning, added to `warnings`.
void check_environment_options(const EnvironmentSource& source, bool given, bool rotation_given, Shading shading,
                               std::vector<std::string>& warnings);

// The job the command line describes, and what the command line alone needs to know about how it
// was said.
struct RenderOptions {
  SequenceJob job;                  // defaults: the preset paper-8k's
  std::string compression = "zip";  // --compression, checked with the job (render_command.cpp)
  bool offset_given = false;        // else offset = -L / (2N), which centres every subpixel in its view
  bool help = false;
  bool preset_help = false;        // --preset help
  bool method_given = false;       // --method was on the command line
  bool environment_given = false;  // --environment was on the command line
  bool environment_rotation_given = false;
  bool zoom_given = false;     // --zoom was on the command line (rig.zoom)
  bool orbit_given = false;    // --orbit was on the command line (rig.orbit_*)
  bool framing_given = false;  // --framing was on the command line (else box, sphere for turntables)
  std::string background_depth;  // --background-depth as given ("": the focal plane)
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
