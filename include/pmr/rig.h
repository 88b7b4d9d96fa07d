// The camera rig (DESIGN section 2) and the display (DESIGN section 5).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "pmr/shared.h"

namespace pmr {

// An exact rational number p / q with q > 0, used for the encoder's display parameters so that the
// view index of every subpixel is computed exactly.
struct Rational {
  int64_t num = 0, den = 1;
  double value() const { return double(num) / double(den); }
};
// Parses "16", "-0.0833", "1/18", "-1/12". Throws pmr::Error naming `what` on bad input.
Rational parse_rational(const std::string& text, const std::string& what);
std::string to_string(const Rational& r);
// The default encoder offset -L / (2N), exact.
Rational default_offset(const Rational& lens_pitch, int views);

struct Display {
  int width = 7680, height = 4320;  // pixels
  double size_w_cm = 166.0, size_h_cm = 93.0, viewing_distance_cm = 200.0;
  Rational lens_pitch{16, 1};  // L, in subpixels
  Rational tan_slant{1, 18};   // tan(alpha)
  Rational offset{-1, 12};     // subpixels
  bool reversed = false;       // v -> N - 1 - v
  // Extensions for real panels (docs/DISPLAYS.md): the Looking Glass shader takes its view from
  // 1 - frac(t), i.e. from frac(-t) (phase_sign -1), and on BGR panels (or a flipped image) subpixel k
  // of pixel j sits at phase position 3j + 2 - k instead of 3j + k (subpixel_bgr). The position each
  // subpixel samples its view at stays its own (DESIGN section 5).
  int phase_sign = 1;
  bool subpixel_bgr = false;
  // Blend views v and v + 1 by the phase's fraction (Looking Glass's webxr 0.6 default filter); off by
  // default, so that every subpixel shows exactly one view.
  bool blend_views = false;
  // Gen3 Looking Glass panels' subpixel cells (docs/DISPLAYS.md): when cell_offsets is not empty, every
  // subpixel's phase position is 3j (no k) and its offset, instead of `offset`, is
  // cell_offsets[(c * 2 + j % 2) * 3 + k] / 10^14 for row class c = (height - 1 - i) % cell_rows
  // (exact numerators over a common denominator, so the encoder stays exact).
  int cell_rows = 1;
  std::vector<int64_t> cell_offsets;
  bool bilinear = false;  // sample views bilinearly instead of nearest
  double aspect() const { return size_w_cm / size_h_cm; }
};

// How the default camera frames the scene (DESIGN section 2): Box, the largest picture that keeps the
// 8 corners of the scene's box inside views 0 and N-1 (one pixel from their edges); Sphere, the bounding
// sphere's cross-section through its center fits the focal-plane window (turntables: the picture stays
// the same size as the scene turns).
enum class Framing { Box, Sphere };
const char* to_string(Framing f);

struct RigConfig {
  int views = 96;
  int view_w = 1024, view_h = 512;
  double cone_deg = 80.0;
  double yfov_deg = 0.0;  // 0 = from the display: 2 atan(size_h / 2 / viewing_distance)
  int camera = -1;        // glTF camera index, -1 = frame the scene's bounding sphere
  // Camera spacing along the baseline: linear (DESIGN section 2, PMR's evenly spaced views) or
  // angular as Looking Glass software places them, D tan(cone ((i + 1/2) / N - 1/2)), each camera
  // moved onto a fixed-point view coordinate (make_rig).
  bool angular_spacing = false;
  // The scene appears `zoom` times larger: D = D_fit / zoom, the focal plane still through the
  // sphere's center (only when framing the bounding sphere, camera < 0).
  double zoom = 1.0;
  // --orbit AZ,EL (degrees): the framing camera sits at c + D (sin az cos el, sin el, cos az cos el),
  // looking at c with +Y up (only when framing the bounding sphere, camera < 0).
  double orbit_az_deg = 0.0, orbit_el_deg = 0.0;
  // --framing (only when framing the scene, camera < 0). Sphere here, so that the library's rigs stay
  // those the tests pin; the command line's default is box (cli/options.cpp).
  Framing framing = Framing::Sphere;
};

// The resolved rig of one frame.
struct Rig {
  int views = 0, view_w = 0, view_h = 0;
  double yfov = 0, cone = 0;                      // radians
  double aspect = 0;                              // display physical aspect A
  double focal = 0;                               // D
  double near = 0, far = 0;                       // the planes as requested (default or camera)
  double near_eff = 0;                            // near raised (if needed) to keep disparity inside the guard band
  bool angular = false;                           // camera spacing (RigConfig::angular_spacing)
  glm::dmat4 center_view{1.0};                    // world -> center view space
  double zoom = 1.0;                              // RigConfig::zoom (1 with a glTF camera)
  double orbit_az_deg = 0.0, orbit_el_deg = 0.0;  // RigConfig's orbit (0 with a glTF camera)
  Framing framing = Framing::Sphere;              // RigConfig's (unused with a glTF camera)

  // Angular spacing's view-coordinate resolution Q (1 with linear spacing): camera i sits at
  // view_coord(i) / Q view spacings B / (N - 1) from the center camera (make_rig chooses Q).
  int spacing_q = 1;

  double baseline() const;            // B = 2 D tan(theta / 2)
  double camera_offset(int i) const;  // s_i (linear, or angular as quantized: the cameras rendered)
  // Angular spacing's exact Looking Glass offset D tan(theta ((i + 1/2) / N - 1/2)), before quantization.
  double angular_offset(int i) const;
  // The integer view coordinate F_i of view i (pmr/shared.h): i with linear spacing, round(Q g_i) with
  // angular spacing, g_i = angular_offset(i) / B * (N - 1). x_i = x_0 + F_i d in every kernel.
  int view_coord(int i) const;
  double view_anchor() const;           // camera offset at view coordinate 0 over B: -1/2 or 0
  double view_scale() const;            // view coordinate units per baseline: (N - 1) Q
  glm::dmat4 view_matrix(int i) const;  // V_i = T(-s_i, 0, 0) V
  glm::dmat4 projection(int i) const;   // glFrustum(l_i, r_i, b, t, near_eff, far)
  double disparity_k() const;           // W tan(theta/2) / (A tan(phi/2))
  double disparity_px(double w) const;  // Delta(w) = disparity_k * (1 - D / w)
  glm::dvec3 light_view() const;        // normalize(0.3, 0.5, 1.0)
  glm::dvec3 light_world() const;       // the same direction in world space
};

// Angular spacing: the largest distance between a camera and its exact Looking Glass position, in view
// spacings, and the disparity it causes, in view pixels, at the nearest or farthest depth of the rig's
// range [near_eff, far] (whichever has more disparity). 0 with linear spacing.
struct SpacingError {
  double view_spacings = 0, view_px = 0;
};
SpacingError spacing_error(const Rig& rig);
// The bound make_rig keeps spacing_error(rig).view_px within (unless a view-coordinate range of
// +-PMR_MAX_VIEW_COORD cannot hold it; make_rig warns then).
constexpr double kSpacingErrorPx = 0.01;
// Above this error the user is warned (a visible half-pixel shift); below it --verbose notes it.
constexpr double kSpacingWarningPx = 0.5;

// Throws pmr::Error unless |az| <= 360 and |el| < 90 degrees (RigConfig's orbit).
void check_orbit(double az_deg, double el_deg);

// Builds the rig for a scene whose world bounds are [lo, hi]. `camera_pose` (world_from_camera) and
// `camera_yfov` are used when config.camera >= 0. Throws pmr::Error on an impossible configuration.
// camera_aspect: the aspect ratio the camera's yfov was made for (glTF's aspectRatio; 0 = not given).
// Where it is wider than the display's, the field of view widens until the camera's whole frame fits the
// views (with a warning): a Blender camera at a 16:9 render size keeps its frame on a 3:4 panel.
Rig make_rig(const RigConfig& config, const Display& display, const glm::dvec3& lo, const glm::dvec3& hi,
             const glm::dmat4* camera_pose = nullptr, double camera_yfov = 0.0,
             std::vector<std::string>* warnings = nullptr, double camera_aspect = 0.0);

// Frame parameters for the kernels (tile grid and capacities are filled in by the pipeline).
PmrParams make_params(const Rig& rig);

// Encoder parameters (sizes and flags). Throws pmr::Error on an unusable display.
PmrEncodeParams make_encode_params(const Display& display, int views, int view_w, int view_h);

// The encoder's per-subpixel-column and per-row tables (see PmrEncodeColumn in shared.h), computed in
// exact wide integer arithmetic from the display's fractions.
void make_encode_tables(const Display& display, const PmrEncodeParams& p, std::vector<PmrEncodeColumn>& columns,
                        std::vector<PmrEncodeRow>& rows);

// Direct evaluation of DESIGN section 5 in exact arithmetic (one wide division per subpixel): the view
// of subpixel k of display pixel (j, i). The reference the encoder kernels are tested against.
int encode_view_index(const Display& display, int views, int j, int i, int k);

}  // namespace pmr
