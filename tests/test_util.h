// Shared helpers for the tests: one OpenCL runtime for the whole test binary, small rigs, and
// procedural scenes with known properties.
#pragma once
#include <sys/types.h>

#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "runtime/cl_runtime.h"

namespace pmr {
// The tests' kernel probes (tests/probes), embedded into the test binary only; pass to
// ClRuntime::build_program.
const std::map<std::string, std::string>& test_kernel_sources();
}  // namespace pmr

namespace pmr::test {

const ClRuntime& runtime();

// A scene with one default material (opaque; double_sided as given) and no triangles.
Scene empty_scene(bool double_sided = false);
// Adds a triangle with world-space corners (counter-clockwise seen from +Z = front for the default
// rig, which looks down -Z).
void add_triangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material = 0);
// Gives `material` the base colour texture `texture` (sRGB) sampled on TEXCOORD set `set`, and returns
// the slot (for a transform). Material inputs are added for the materials that have none, with their
// PmrMaterial's pbr factors.
SceneTextureSlot& base_colour_texture(Scene& s, uint32_t material, int texture, int set = 0);
// TEXCOORD set `set` of vertex v; every set (up to `set`) is sized to the scene's vertices first, (0, 0)
// where not given. Call after the last vertex is added.
glm::vec2& texcoord(Scene& s, int set, size_t v);
// `n` random triangles inside the box [-1,1]^3, sizes from sub-pixel to a good part of the screen.
Scene random_scene(int n, uint32_t seed, bool double_sided, float max_size = 0.6f);

// The default rig (paper-8k display, framing the unit box [-1,1]^3) with a small view raster, with
// linear or angular camera spacing.
Rig small_rig(int views, int w, int h, bool angular = false);
// Both camera spacings, for the exactness tests that must hold for either.
constexpr bool kSpacings[] = {false, true};
inline const char* spacing_name(bool angular) { return angular ? "angular" : "linear"; }

// The value of a half's bits (the volumes, EXR channels and encoded images hold halves).
float half_value(uint16_t bits);
// A fixed rig (3 views of 64x32, a camera at (3, 2, 4) looking at (0, 0.5, 0)) for sidecar tests.
Rig sidecar_rig();

// Renders the scene with the given rig and tile size; returns the pipeline for read-back.
struct Rendered {
  std::vector<uint32_t> key, count;
  std::vector<float> depth;
  std::vector<uint16_t> volume;
  std::vector<PmrMta> mtas;
  StageTimes times;
};
Rendered render(const Scene& scene, const Rig& rig, int tx = 4, int ty = 4, int tv = 4,
                const Display* display = nullptr, std::vector<uint16_t>* encoded = nullptr);
// The same with a whole configuration (debug outputs are turned on: the keys are read back).
Rendered render_with(const Scene& scene, const Rig& rig, PipelineConfig pc, const Display* display = nullptr,
                     std::vector<uint16_t>* encoded = nullptr);
// One frame through a pipeline configured with `pc` and display `d`: the encoded image, which path the
// pipeline chose, and the view volume when it kept one.
struct EncodedRender {
  std::vector<uint16_t> image, volume;
  bool fused = false, has_volume = false;
};
EncodedRender render_encoded(const Scene& scene, const Rig& rig, const Display& d, const PipelineConfig& pc);
// A pipeline set up for `views` views of vw x vh (a one-triangle scene) and `display`, to drive the
// encoder directly with a volume of the test's own (Pipeline::encode_volume).
std::unique_ptr<Pipeline> encoder_pipeline(const Display& display, int views, int vw, int vh);

// A 64 x 40 display (lens pitch 7.3125, slant -0.15) into `d`, and a rig of 10 views of 3 x 64 by 40
// framing [-1, 1]^3: every subpixel's sample is a view pixel center, so subpixel sampling gives view
// sampling's image (but for depth ties).
Rig subpixel_display_rig(Display& d);
// Path of the shared glTF corpus (PMR_SOURCE_DIR/../shared/gltf), empty if absent.
std::string corpus_dir();
// The .gltf and .glb files under `dir`, recursively, sorted.
std::vector<std::string> corpus_files(const std::string& dir);

}  // namespace pmr::test

namespace pmr::test {
// World point on the focal plane (zero disparity) that projects to raster position (x, y) in every
// view of a rig made by small_rig (camera on +Z looking at the origin).
glm::vec3 focal_point(const Rig& rig, double x, double y);
// Parameters the kernels see for this rig and tile size.
PmrParams params_for(const Rig& rig, int tx = 4, int ty = 4, int tv = 4);
}  // namespace pmr::test

namespace pmr::test {
// The pmr binary run with `args` (stderr merged into output).
struct CliRun {
  int status;  // exit code, -1 if killed by a signal
  std::string output;
};
CliRun run(const std::string& args);
// The same with environment assignments for the process, e.g. "POCL_CACHE_DIR='/tmp/x'".
CliRun run_env(const std::string& env, const std::string& args);
// The same started through a wrapper command, e.g. "prlimit --as=1073741824" or "env X=1".
CliRun run_wrapped(const std::string& wrapper, const std::string& args);
// The pmr binary started in the background with `args` (its output to `log`); returns its pid.
pid_t start(const std::string& args, const std::string& log = "/dev/null");
// A fresh folder per test and process, so that two test runs on one machine cannot meet.
std::string temp_dir(const std::string& name);
bool exists(const std::string& path);
std::string read_file(const std::string& path);
size_t count_entries(const std::string& dir);           // including hidden ones
std::set<std::string> listing(const std::string& dir);  // the entries' names
// A double-sided 2x2 square in the z = 0 plane, centered on the origin (facing +z), saved as a .glb.
void save_square_glb(const std::string& path);
// The error is one line starting with "pmr: error:" (warnings may precede it), exit code `status`: 1
// for bad input or a runtime error, 2 for a usage error (expect_usage_error).
void expect_one_error_line(const CliRun& r, const std::string& fragment, int status = 1);
// A run-wide choice the sidecar records and --resume compares: a small frame rendered with `options`
// records `recorded` in its sidecar, --resume with the same options keeps it, and --resume without
// them is refused in one error line naming `key`.
void expect_resume_compares(const std::string& options, const std::string& recorded, const std::string& key);
inline void expect_usage_error(const CliRun& r, const std::string& fragment) { expect_one_error_line(r, fragment, 2); }
}  // namespace pmr::test

namespace pmr::test {
// The view index each display subpixel shows, from the encode kernel (a volume whose every channel
// holds its view's index, encoded by the pipeline): [i][j][k], display rows from the top.
std::vector<int> encoded_view_indices(const Display& display, int views, int view_w, int view_h);
// The same from the host tables alone (the kernels' formula, no device): for whole-panel checks.
std::vector<int> table_view_indices(const Display& display, int views);
}  // namespace pmr::test
