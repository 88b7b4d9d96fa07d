// The options of `pmr bench` (one table makes the parser and --help: cli/option_table.h); those it
// shares with `pmr render` go through render's parser.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "pipeline/pipeline_config.h"
#include "pmr/input_files.h"
#include "pmr/rig.h"
#include "sequence/sequence_spec.h"
#include "shading/environment.h"

namespace pmr {

struct BenchOptions {
  std::string scene;
  std::string generator;                // "synthetic" or "objects": procedural scenes instead of SCENE
  std::vector<size_t> triangle_counts;  // one generated scene per count (the triangle sweep)
  std::string save_scene;               // write the generated scene as .glb and exit
  std::vector<int> views = {1, 2, 4, 8, 16, 32, 48, 64, 96};
  std::vector<Method> methods = {Method::Pmr, Method::Multipass, Method::Duplicate};
  std::vector<Sampling> samplings = {Sampling::View};  // subpixel applies to pmr only
  bool samplings_given = false;    // else the preset's default sampling (view for methods other than pmr)
  std::vector<int> samples = {4};  // samples per pixel, as pmr render's --samples (and its default)
  TextureFilter texture_filter = TextureFilter::Trilinear;  // --texture-filter, as pmr render's
  Shading shading = Shading::Pbr;
  bool shadows = true;                // pbr: --shadows, as pmr render's
  bool environment_occlusion = true;  // pbr: --environment-occlusion, as pmr render's
  double exposure_ev = 0.0, environment_intensity = 1.0;
  bool views_given = false;
  int frames = 5;
  std::string csv;
  std::string keep = "view";
  int view_w = 1024, view_h = 512;  // per-view raster at N = 96 (keep total) or always (keep view)
  RigConfig rig;                    // cone, field of view (views and sizes come from the options above)
  bool offset_given = false;        // --offset, or a Looking Glass preset's calibrated offset
  Display display;
  int tile[3] = {16, 2, 16};
  bool check = true;
  bool queue_stats = false;  // --queue-stats: histograms of the last frame's work (cli/queue_stats.h)
  bool help = false;
  // Timed frames are frames 0..K-1 of this sequence (animation and turntable as for pmr render).
  SequenceChoice sequence;
  // --environment E and --environment-rotation DEG (pbr), made once for every point
  EnvironmentSource environment_source;
  bool environment_given = false;
  double environment_rotation_deg = 0.0;
  bool environment_rotation_given = false;
  std::shared_ptr<const Environment> environment;
  InputLimits limits;                    // --limit, --allow-outside-scene-folder (docs/SECURITY.md)
  std::vector<std::string> render_args;  // the options pmr render reads for bench, in the order given
};

// Parses the arguments after `bench`. Throws pmr::Error with one line on bad input.
BenchOptions parse_bench_options(const std::vector<std::string>& args);
std::string bench_help();

}  // namespace pmr
