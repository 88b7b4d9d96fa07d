// The per-frame JSON sidecar (DESIGN section 6): everything needed to reproduce or check a frame, its
// comparison with another sidecar (--resume, the folder guard, pmr verify) and where a frame came from.
#pragma once
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "output/background.h"
#include "output/view_transform.h"
#include "pipeline/pipeline_config.h"
#include "pmr/display_presets.h"
#include "pmr/input_files.h"
#include "pmr/output.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "sequence/sequence_spec.h"
#include "shading/environment.h"

namespace pmr {

// A file the frame wrote, as its sidecar records it: name, size and checksum (output/checksum.h), so
// that --resume and `pmr verify` can check the frame without decoding it.
struct OutputChecksum {
  std::string file;
  uint64_t bytes = 0;
  std::string checksum;
};

// The render settings that decide a frame's pixels, as the sidecar records them: plain values, so that
// what writes and compares sidecars does not depend on the pipeline's own configuration (which also
// holds the prefiltered environment, callbacks and budgets). render_settings (sequence/sequence_job.h)
// takes them from a PipelineConfig.
struct RenderSettings {
  Method method = Method::Pmr;
  Sampling sampling = Sampling::View;
  int samples = 1;  // per pixel
  TextureFilter texture_filter = TextureFilter::Bilinear;
  Shading shading = Shading::Pbr;
  double exposure_ev = 0.0;
  double environment_intensity = 1.0;  // pbr
  bool shadows = false;                // pbr: --shadows (recorded only when on: an older sidecar is off)
  bool environment_occlusion = false;  // pbr, shadows on: --environment-occlusion
  bool ground_shadow = false;          // pbr, shadows on: --ground shadow (recorded only when on)
  bool clear_glass = false;            // pbr, a transparent background (PipelineConfig::clear_glass)
  ShadowSizes shadow_sizes;
  int tile_x = 16, tile_y = 2, tile_v = 16;
};

// What the sidecar records besides the rig and the display: the job's configuration, whole, as the
// job holds it; what the run read and framed; and the frame's own values.
struct SidecarInfo {
  // the job's configuration
  std::string scene;                          // the scene file as given (empty = the bundled default scene)
  RigConfig rig_config;                       // its glTF camera (the rig itself is recorded as resolved)
  std::string camera_name;                    // that camera's node name ("" = none)
  std::optional<std::string> variant;         // the material variant drawn (none: the default materials)
  int variant_index = -1;                     // its index in the file
  RenderSettings render;                      // method, sampling, shading and exposure, tile
  DisplaySource display_source;               // the display's source and its calibration's values
  SequenceSpec sequence;                      // fps, animation, turntable
  std::optional<ExrCompression> compression;  // of the images (none: not recorded)
  // the PNG previews' view transform, recorded when previews pass through another than Standard
  std::optional<ViewTransformRecord> view_transform;
  Background background;     // transparent: not recorded
  InputLimits input_limits;  // allow_outside_scene_folder: recorded only when given
  // pbr: the environment (--environment: the studio, the uniform one or an image file as given), an
  // image's checksum, the rotation (its intensity is render.environment_intensity)
  EnvironmentSource environment;
  std::string environment_checksum;
  double environment_rotation_deg = 0.0;
  // what the run read and framed
  bool has_bounds = false;  // world bounds of the scene the default framing used
  glm::dvec3 bounds_lo{0.0}, bounds_hi{0.0};
  glm::dvec3 pivot{0.0};              // the turntable axis passes through it (along +Y)
  std::vector<std::string> warnings;  // e.g. "near plane raised ..."
  // Checksums of what the render read (output/checksum.h; "" = not recorded): the scene file and every
  // other file the loader read (path relative to the scene's folder, checksum); the calibration file's
  // is its own. The program version is always recorded (pmr::program_version()).
  std::string scene_checksum;
  std::vector<std::pair<std::string, std::string>> scene_files;
  // the frame: its place in the sequence (DESIGN section 7), so any frame can be reproduced alone
  int frame = 0;
  double time = 0.0;               // seconds: frame / fps
  double turntable_angle = 0.0;    // this frame's angle, degrees
  std::vector<SceneLight> lights;  // pbr: the frame's lights as used (FrameRenderer::Frame::lights)
  // Files written for this frame, as (kind, file name) pairs, e.g. {"encoded", "frame_0000.exr"}.
  std::vector<std::pair<std::string, std::string>> outputs;
  std::vector<OutputChecksum> output_checksums;                // of the written outputs (the sidecar is written last)
  int quilt_columns = 0, quilt_rows = 0;                       // of the quilt output (0: none)
  int center_view = -1;                                        // the view of the center preview (-1: none)
  bool depth = false;                                          // Z channels in the views / quilt files
  float depth_empty = std::numeric_limits<float>::infinity();  // their Z where nothing was drawn
};

// The largest sidecar pmr reads back. Everything a sidecar lists from the scene is bounded (names cut,
// lights and warnings counted beyond the first few), and write_sidecar refuses to write a larger one.
constexpr uint64_t kMaxSidecarBytes = uint64_t(16) << 20;

// The sidecar's JSON text (pretty printed, doubles with round-trip precision).
std::string sidecar_json(const Rig& rig, const Display& display, const SidecarInfo& info);
// Compares the configuration that decides a frame's pixels (scene, method, tile, camera, display, rig,
// framing, fps, animation, turntable, shading and its lights; not the frame, its time or the outputs) of
// two sidecars' JSON texts. The lights' positions and directions follow the frame (animation, turntable):
// they are compared only between sidecars of the same frame. Returns "" when they agree, else the first differing key (or "unreadable" when `existing` does
// not parse).
// With ignore_scene_derived, the keys that follow from the scene file's content (scene_bounds, the
// turntable's pivot, the animation's name, the lights) are not compared: for a frame known to come from another
// scene (sidecar_provenance), only the configuration the user chose matters.
std::string sidecar_config_difference(const std::string& existing, const std::string& expected,
                                      bool ignore_scene_derived = false);
// The message for a difference `key` that sidecar_config_difference found: "KEY differs", and the first
// differing value under it, e.g. "shading differs: shading.exposure_ev 0 in the folder, 1 in this run"
// (labels: where `existing` and `expected` come from; values shortened and made printable).
std::string config_difference_text(const std::string& existing, const std::string& expected, const std::string& key,
                                   const std::string& existing_label, const std::string& expected_label);

// Where a sidecar's frame came from. Never throws: a damaged or old sidecar gives empty strings.
struct SidecarProvenance {
  // The scene's identity: the checksum algorithm, the scene file's and every other read file's
  // checksums as one canonical string; "" when the sidecar records none (written before pmr recorded
  // them, or damaged). Two frames with equal non-empty identities were rendered from the same bytes.
  std::string scene;
  std::string version;  // program_version, "" when absent
};
SidecarProvenance sidecar_provenance(const std::string& sidecar_text);

// Throws pmr::Error when a sidecar of `bytes` is larger than pmr reads back (kMaxSidecarBytes): a job
// is refused before its first frame renders (SequenceRun), so no frame is left that verify and
// --resume could not read.
void check_sidecar_size(uint64_t bytes);

// Writes the JSON sidecar (DESIGN section 6) atomically. Matrices are 16 numbers, column-major.
void write_sidecar(const std::string& path, const Rig& rig, const Display& display, const SidecarInfo& info);

}  // namespace pmr
