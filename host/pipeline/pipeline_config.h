// The run-wide choices of a pipeline: how the views are rasterized (Method), where the display's
// subpixels take their colours from (Sampling), how winners are shaded (Shading), and the rest of a
// PipelineConfig. Apart from pipeline.h so that what records a configuration (the sidecar) needs no
// OpenCL.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "pipeline/shadow_sizes.h"
#include "pmr/input_files.h"
#include "pmr/rig.h"

namespace pmr {

class Environment;

// How the N views are rasterized. All three produce the same images (see tests/test_methods.cpp).
enum class Method {
  Pmr,        // multi-view triangles over (x, y, view): the paper's method
  Multipass,  // one conventional single-view pass per view, each with that view's own matrices
  Duplicate,  // every triangle duplicated once per view by setup, 2D tiles over the view atlas
};
Method parse_method(const std::string& name);  // "pmr", "multipass", "duplicate"
const char* to_string(Method m);

// Where the display's subpixels take their colours from.
enum class Sampling {
  View,      // the views rendered on their W x H grids, each subpixel reading its view's nearest pixel
  Subpixel,  // every subpixel rasterized at its own sample in its own view (cl/fine_subpixel.cl)
};
Sampling parse_sampling(const std::string& name);  // "view", "subpixel"
const char* to_string(Sampling s);
// The sample positions of S samples per pixel (DESIGN section 3b) into P, the pattern scaled by
// (scale_x, scale_y) view pixels per pattern pixel (with --sampling subpixel, a display pixel's footprint
// in the view) and rounded to the raster's fixed point; throws pmr::Error unless S is 1, 4, 8 or 16.
void set_sample_pattern(int samples, double scale_x, double scale_y, PmrParams& P);
inline void set_sample_pattern(int samples, PmrParams& P) { set_sample_pattern(samples, 1.0, 1.0, P); }
// Throws pmr::Error when --sampling subpixel cannot render with this method and display (PMR only;
// nearest, unblended sampling). Pipeline::configure checks it; the command line calls it before loading
// a scene.
void check_subpixel_sampling(Method method, const Display& display);

// How winners are shaded (docs/SHADING.md).
enum class Shading {
  Lambert,  // view-independent: base colour x (0.2 + 0.8 max(0, n.l)), one directional light
  Pbr,      // glTF metallic-roughness seen from each view's camera
};
Shading parse_shading(const std::string& name);                         // "lambert", "pbr"
bool parse_on_off(const std::string& name, const std::string& option);  // "on", "off"
bool parse_shadows(const std::string& name);                            // "on", "off"
const char* to_string(Shading s);

// How textures are filtered (DESIGN section 3b, --texture-filter).
enum class TextureFilter {
  Bilinear,   // level 0 alone, bilinear: the point-sampled renderer's textures, bit for bit
  Trilinear,  // mip chains, the level of detail from the analytic screen-space derivatives
};
TextureFilter parse_texture_filter(const std::string& name);  // "bilinear", "trilinear"
const char* to_string(TextureFilter f);

struct PipelineConfig {
  Method method = Method::Pmr;
  // PMR: the 3D tile (voxels over x, y, view) of one fine work-group. The single-view baselines use
  // 2D tiles: this tile if its V is 1, else 8x8x1 (measured best of 8x8, 16x4, 32x2, 16x8).
  // Default 16x2x16: best of the shapes measured with the fused path at N = 96 (pmr bench on
  // AnisotropyStrengthTest, TransmissionTest, --synthetic 100000; docs/PERFORMANCE.md).
  int tile_x = 16, tile_y = 2, tile_v = 16;
  bool debug_outputs = false;  // fine raster also writes per-voxel key, depth, count
  int samples = 1;             // samples per pixel (DESIGN section 3b): 1, 4, 8 or 16 (the command line defaults to 4)
  // The encoded-only job: fine raster writes the display image directly (cl/fine_encode.cl) and the
  // view volume is never allocated. Applies to PMR with a display, nearest sampling and no debug
  // outputs, when one screen tile's state for all views fits a work-item's private memory;
  // otherwise the volume is rendered and encoded as usual. read_volume() needs it off.
  bool fuse_encode = false;
  bool multipass_snapped = false;  // test mode: multipass fed PMR's snapped per-view positions
  // Subpixel needs a display and --method pmr. The views are rendered on their grids as well only when
  // fuse_encode is off (a product needs them); debug outputs are per voxel of those views, or without
  // them per display subpixel ([row][3 * column + k]).
  Sampling sampling = Sampling::View;
  Shading shading = Shading::Pbr;
  double exposure_ev = 0.0;  // colour x 2^EV, either model
  // Bilinear here (the library's default keeps the images every existing test compares bit for bit);
  // the command line's default is trilinear (cli/options.cpp).
  TextureFilter texture_filter = TextureFilter::Bilinear;
  double environment_intensity = 1.0;  // pbr: scales the uniform default environment (radiance 0.2)
  // pbr: every light's term times its visibility from the frame's shadow maps (DESIGN section 4d).
  // Off here (the library's images stay those of the tests that pin them); the command line's default
  // is on. Off: every visibility 1, the images bit for bit those before shadows.
  bool shadows = false;
  // pbr, with shadows on: the environment's occlusion (shading/environment_occlusion.h); off leaves the
  // environment unoccluded and reads none of its 64 maps (--environment-occlusion).
  bool environment_occlusion = true;
  // pbr, with shadows on: --ground shadow, a shadow catcher under the scene (scene/ground_catcher.h),
  // placed by the framing (FrameRenderer::attach).
  bool ground_shadow = false;
  // pbr: the output's background is transparent (the default; not with --background). The part of the
  // light through glass that left the scene, the environment behind it, is then not drawn: the glass
  // lowers alpha by that part's weight, so what is behind the image (a panel's black, a plate) shows
  // through it, as with Cycles' Transparent Glass. Off: the environment is drawn there, alpha 1.
  bool clear_glass = false;
  ShadowSizes shadow_sizes;
  // pbr: an environment image, prefiltered once (Environment::make) and shared by every pipeline of
  // a process; its rotation and intensity are its own (the intensity must equal environment_intensity).
  // It replaces the uniform default and turns the default light off (host/shading/lights.h; the file's
  // lights stay). Null: the uniform default.
  std::shared_ptr<const Environment> environment;
  // --limit tile-queue: a frame whose tile raster produces more entries is refused (before the queue
  // grows to hold them), naming the budget.
  uint64_t tile_queue_limit = InputLimits().tile_queue;
  // Called every few seconds while a frame is still rendering after a few seconds (seconds so far,
  // the frame's tile-queue entries), so that a slow frame (10^4 full-screen triangles take a minute)
  // shows progress. Empty: render() just waits.
  std::function<void(double seconds, uint64_t tile_queue_entries)> slow_frame;
  double slow_frame_seconds = 5.0;  // the first call after this long, then one per this long
};

}  // namespace pmr
