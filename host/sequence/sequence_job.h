// A sequence job (one frame is a sequence of one) from loading to the summary: what to render, with
// which rig, display and pipeline, into which files. The command line fills it in (cli/); the frame
// loop knows nothing of the command line.
#pragma once
#include <string>
#include <vector>

#include "output/background.h"
#include "output/view_transform.h"
#include "pipeline/pipeline_config.h"
#include "pmr/display_presets.h"
#include "pmr/input_files.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "sequence/frame_files.h"
#include "sequence/sequence_spec.h"
#include "shading/environment.h"

namespace pmr {

struct SequenceJob {
  // inputs
  std::string scene;              // the glTF or GLB file
  InputLimits input_limits;       // budgets and folder confinement (docs/SECURITY.md)
  std::string variant;            // --variant: a material variant's name or index ("" = default materials)
  EnvironmentSource environment;  // pbr: the studio (default), the uniform one or an image
  double environment_rotation_deg = 0.0;
  // cameras, display, pipeline
  RigConfig rig;
  std::string camera;  // --camera: a glTF camera's index or name (find_camera); "" = rig.camera
  Display display;
  DisplaySource display_source;  // what the display came from: a preset or a calibration file (sidecar)
  PipelineConfig pipeline;
  // products: which files per frame (FrameProducts), the quilt layout ("" = chosen), compression
  FrameProducts products;
  std::string quilt_layout;
  ExrCompression compression = ExrCompression::Zip;
  // frames: a --frames list or "all" (the animation's key range, or one turn of a turntable)
  std::string frames = "0";
  SequenceChoice sequence;  // --animation, --fps, --turntable
  std::string shard;        // "K/N" or "auto"; "" = every frame
  long shard_count = 0, shard_first = 0;
  bool resume = false, overwrite = false;
  bool quiet = false, verbose = false;
  bool print_outputs = false;         // --print-outputs: list each frame's files (JSON lines) and render nothing
  std::vector<std::string> warnings;  // printed before the work starts (e.g. from the options)
  Background background;              // behind every output (output/background.h)
  // the PNG previews' view transform (--ocio ...; output/view_transform.h): opened before the scene is
  // read, when there are previews or an option names part of a config
  ViewTransformOptions view_transform;
  bool view_transform_given = false;  // an option of it was on the command line
  bool quilt_preview_opaque = false;  // the quilt PNG over opaque black when no background is given
};

// Runs the job; returns the process exit code (0, or 128 + signal when interrupted). Throws pmr::Error
// with one line on bad input or a failed write.
int run_sequence(const SequenceJob& job);

}  // namespace pmr
