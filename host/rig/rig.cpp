// The camera rig (DESIGN section 2): N off-axis cameras sharing one window on the focal plane.
#include "pmr/rig.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstdint>

#include <glm/gtc/matrix_transform.hpp>

#include "pmr/error.h"

namespace pmr {

double Rig::baseline() const { return 2.0 * focal * std::tan(cone / 2.0); }

double Rig::angular_offset(int i) const { return focal * std::tan(cone * ((double(i) + 0.5) / double(views) - 0.5)); }

double Rig::camera_offset(int i) const {
  if (views <= 1) return 0.0;
  if (angular) return baseline() * double(view_coord(i)) / view_scale();
  return (double(i) / double(views - 1) - 0.5) * baseline();
}

int Rig::view_coord(int i) const {
  if (!angular || views <= 1) return angular ? 0 : i;
  return int(std::lround(double(spacing_q) * angular_offset(i) / baseline() * double(views - 1)));
}

double Rig::view_anchor() const { return angular ? 0.0 : -0.5; }

double Rig::view_scale() const { return double(views - 1) * double(angular ? spacing_q : 1); }

glm::dmat4 Rig::view_matrix(int i) const {
  return glm::translate(glm::dmat4(1.0), glm::dvec3(-camera_offset(i), 0.0, 0.0)) * center_view;
}

glm::dmat4 Rig::projection(int i) const {
  const double h = focal * std::tan(yfov / 2.0);
  const double a = aspect * h;
  const double s = camera_offset(i);
  const double n = near_eff;
  const double l = (-a - s) * n / focal, r = (a - s) * n / focal;
  const double t = n * std::tan(yfov / 2.0), b = -t;
  return glm::frustum(l, r, b, t, n, far);
}

double Rig::disparity_k() const { return double(view_w) * std::tan(cone / 2.0) / (aspect * std::tan(yfov / 2.0)); }

double Rig::disparity_px(double w) const { return disparity_k() * (1.0 - focal / w); }

glm::dvec3 Rig::light_view() const { return glm::normalize(glm::dvec3(0.3, 0.5, 1.0)); }

glm::dvec3 Rig::light_world() const {
  // Directions transform with the inverse of the view matrix's rotation part.
  const glm::dmat3 rot(center_view);
  return glm::normalize(glm::inverse(rot) * light_view());
}

namespace {

// Guard band in NDC units along x for a raster of width w_px (see PMR_GUARD_PX), with 1% margin.
double guard_ndc(int size_px) { return 0.99 * PMR_GUARD_PX / (0.5 * size_px); }

void check_positive(double v, const char* what) {
  if (!(v > 0.0) || !std::isfinite(v)) throw Error(std::string("invalid ") + what + ": must be positive");
}

// The largest disparity per view spacing B / (N - 1) over the rig's depth range, in view pixels.
double disparity_per_spacing(const Rig& rig) {
  const double worst = std::max(std::abs(rig.disparity_px(rig.near_eff)), std::abs(rig.disparity_px(rig.far)));
  return worst / double(rig.views - 1);
}

// Angular spacing on fixed-point view coordinates: camera i moves from g_i to F_i / Q view spacings
// (F_i = round(Q g_i)), at most 1 / (2Q) of a spacing, which shifts a point by at most
// disparity_per_spacing / (2Q) view pixels. The smallest Q that keeps this within kSpacingErrorPx and the
// coordinates strictly increasing; at most what keeps |F_i| <= PMR_MAX_VIEW_COORD (the snapping error of
// x_0 + F_i d grows with |F_i|, pmr/shared.h).
void choose_spacing_q(Rig& rig, std::vector<std::string>* warnings) {
  const double per_spacing = disparity_per_spacing(rig);
  const double g_max = std::abs(rig.angular_offset(0)) / rig.baseline() * double(rig.views - 1);
  const int q_max = std::max(1, int(std::floor((PMR_MAX_VIEW_COORD - 0.5) / g_max)));
  int q = int(std::min<double>(q_max, std::max(1.0, std::ceil(per_spacing / (2.0 * kSpacingErrorPx)))));
  for (;; ++q) {
    rig.spacing_q = q;
    // the view coordinates increase, and no camera leaves the baseline (the guard band's clipping
    // planes are those of the cameras at its ends, pmr/shared.h)
    bool ok = 2 * int64_t(std::abs(rig.view_coord(0))) <= int64_t(q) * (rig.views - 1);
    for (int i = 1; i < rig.views && ok; ++i) ok = rig.view_coord(i) > rig.view_coord(i - 1);
    if (ok) break;
    if (q >= q_max) throw InternalError("no fixed-point view coordinates for angular camera spacing");
  }
  // below half a view pixel nobody can see it (the sequence job's --verbose notes it)
  const SpacingError e = spacing_error(rig);
  if (warnings && e.view_px > kSpacingWarningPx)
    warnings->push_back("angular camera spacing: the cameras sit up to " + std::to_string(e.view_px) +
                        " view pixels of disparity from their exact positions, because the depth range is very "
                        "deep for the view cone: narrow --cone, or use --camera-spacing linear");
}

// The framing camera's view matrix (DESIGN section 2): at distance D from c along the orbit's direction
// b = (sin az cos el, sin el, cos az cos el), looking at c, its +X (cos az, 0, -sin az) horizontal. At
// az = el = 0 the basis is exactly the identity and the matrix the translation by -(c + (0, 0, D)).
glm::dmat4 orbit_view(const glm::dvec3& c, double focal, double az_deg, double el_deg) {
  const double az = glm::radians(az_deg), el = glm::radians(el_deg);
  const glm::dvec3 back(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
  const glm::dvec3 right(std::cos(az), 0.0, -std::sin(az));
  const glm::dvec3 up = glm::cross(back, right);
  const glm::dvec3 eye = c + focal * back;
  glm::dmat4 v(1.0);
  for (int k = 0; k < 3; ++k) v[k] = glm::dvec4(right[k], up[k], back[k], 0.0);
  v[3] = glm::dvec4(-glm::dot(right, eye), -glm::dot(up, eye), -glm::dot(back, eye), 1.0);
  return v;
}

// Framing::Box: the smallest distance D at which the box's 8 corners stay inside views 0 and N-1, one
// pixel from their edges. Camera i sits at s_i = D sigma_i along the view's right; a corner at (x, y)
// across and z toward the camera from c (w = D - z) lands at NDC x = (x - z sigma_i) / ((D - z) A t) and
// y = y / ((D - z) t), t = tan(yfov / 2): both shrink as D grows, so each corner's bound is direct.
double box_focal(const Rig& rig, const glm::dvec3& lo, const glm::dvec3& hi) {
  const glm::dmat4 basis = orbit_view(glm::dvec3(0.0), 0.0, rig.orbit_az_deg, rig.orbit_el_deg);
  const glm::dvec3 c = 0.5 * (lo + hi);
  const double t = std::tan(rig.yfov / 2.0);
  const double mx = 1.0 - std::min(0.5, 2.0 / rig.view_w), my = 1.0 - std::min(0.5, 2.0 / rig.view_h);
  // the cameras' offsets at D = 1 (angular: the exact ones; their fixed-point coordinates come later)
  Rig unit = rig;
  unit.focal = 1.0;
  auto sigma = [&](int i) { return unit.angular && unit.views > 1 ? unit.angular_offset(i) : unit.camera_offset(i); };
  double focal = 0.0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec3 p(basis * glm::dvec4(corner - c, 0.0));  // x right, y up, z toward the camera
    for (int i : {0, rig.views - 1}) {
      const double across = std::abs(p.x - p.z * sigma(i)) / (rig.aspect * t * mx);
      focal = std::max(focal, p.z + std::max(across, std::abs(p.y) / (t * my)));
    }
  }
  return focal;
}

}  // namespace

const char* to_string(Framing f) { return f == Framing::Box ? "box" : "sphere"; }

void check_orbit(double az_deg, double el_deg) {
  if (!(std::abs(el_deg) < 90.0) || !(std::abs(az_deg) <= 360.0))
    throw Error("invalid --orbit: the azimuth must lie in [-360, 360] and the elevation in (-90, 90) degrees");
}

Rig make_rig(const RigConfig& config, const Display& display, const glm::dvec3& lo, const glm::dvec3& hi,
             const glm::dmat4* camera_pose, double camera_yfov, std::vector<std::string>* warnings,
             double camera_aspect) {
  if (config.views < 1) throw Error("invalid --views: need at least 1 view");
  if (config.views > PMR_MAX_VIEWS)
    throw Error("invalid --views: at most " + std::to_string(PMR_MAX_VIEWS) + " views are supported");
  if (config.view_w < 1 || config.view_h < 1 || config.view_w > PMR_MAX_RASTER || config.view_h > PMR_MAX_RASTER)
    throw Error("invalid --view-size: each side must be 1.." + std::to_string(PMR_MAX_RASTER));
  check_positive(display.size_w_cm, "display width");
  check_positive(display.size_h_cm, "display height");
  check_positive(display.viewing_distance_cm, "viewing distance");
  if (!(config.cone_deg > 0.0 && config.cone_deg < 180.0)) throw Error("invalid --cone: must be in (0, 180) degrees");
  check_positive(config.zoom, "--zoom");
  if (camera_pose && config.zoom != 1.0)
    throw Error("--zoom scales the framing of the scene's box or sphere; a glTF camera (--camera) sets its own");
  check_orbit(config.orbit_az_deg, config.orbit_el_deg);
  if (camera_pose && (config.orbit_az_deg != 0.0 || config.orbit_el_deg != 0.0))
    throw Error("--orbit moves the camera that frames the scene; a glTF camera (--camera) sets its own");

  Rig rig;
  rig.views = config.views;
  rig.view_w = config.view_w;
  rig.view_h = config.view_h;
  rig.aspect = display.aspect();
  rig.cone = glm::radians(config.cone_deg);
  rig.angular = config.angular_spacing;
  rig.yfov = config.yfov_deg > 0.0 ? glm::radians(config.yfov_deg)
                                   : 2.0 * std::atan(0.5 * display.size_h_cm / display.viewing_distance_cm);
  if (camera_pose && camera_yfov > 0.0 && !(config.yfov_deg > 0.0)) {
    rig.yfov = camera_yfov;
    if (camera_aspect > rig.aspect * 1.001) {  // the camera's frame is wider than the views: fit its width
      rig.yfov = 2.0 * std::atan(std::tan(camera_yfov / 2.0) * camera_aspect / rig.aspect);
      if (warnings) {
        char text[320];
        std::snprintf(text, sizeof text,
                      "the camera frames %.4g:1 (its aspectRatio), the views %.4g:1: the vertical field of view "
                      "widens from %.4g to %.4g degrees so that the camera's whole frame shows; give the camera "
                      "the display's aspect (in Blender, the render size) to fill the views with it",
                      camera_aspect, rig.aspect, glm::degrees(camera_yfov), glm::degrees(rig.yfov));
        warnings->push_back(text);
      }
    }
  }
  if (!(rig.yfov > 0.0 && rig.yfov < glm::pi<double>())) throw Error("invalid --yfov: must be in (0, 180) degrees");

  const glm::dvec3 c = 0.5 * (lo + hi);
  const double R = 0.5 * glm::length(hi - lo);
  if (!(R > 0.0) || !std::isfinite(R)) throw Error("the scene has zero or non-finite extent; nothing to frame");
  const double tan_half = std::tan(rig.yfov / 2.0);

  if (camera_pose) {
    // The camera's rotation and position; scale in the node matrix is dropped (glTF forbids it).
    glm::dmat4 pose = *camera_pose;
    for (int k = 0; k < 3; ++k) pose[k] = glm::dvec4(glm::normalize(glm::dvec3(pose[k])), 0.0);
    rig.center_view = glm::inverse(pose);
    rig.focal = -(rig.center_view * glm::dvec4(c, 1.0)).z;
    if (!(rig.focal > 0.0))
      throw Error("the selected camera looks away from the scene (its center is behind the camera)");
  } else {
    rig.zoom = config.zoom;
    rig.orbit_az_deg = config.orbit_az_deg, rig.orbit_el_deg = config.orbit_el_deg;
    rig.framing = config.framing;
    // Sphere: its cross-section through c fits the focal-plane window (half-height D tan(phi/2),
    // half-width A D tan(phi/2)) in both directions: a portrait display frames by its width.
    const double fit =
        config.framing == Framing::Box ? box_focal(rig, lo, hi) : R / std::min(tan_half, rig.aspect * tan_half);
    // a flat box seen edge-on: no closer than the sphere's near side allows
    rig.focal = std::max(fit, 1e-3 * R) / config.zoom;
    rig.center_view = orbit_view(c, rig.focal, config.orbit_az_deg, config.orbit_el_deg);
  }
  rig.near = std::max(rig.focal - 1.001 * R, 1e-3 * rig.focal);
  rig.far = rig.focal + 1.001 * R;

  // Keep every vertex that is visible in some view inside the fixed-point guard band of every view:
  // views differ by at most 2 k_ndc |1 - D/w| in NDC x. Behind the focal plane |1 - D/w| < 1, in front
  // of it the bound sets the nearest usable depth.
  rig.near_eff = rig.near;
  if (rig.views > 1) {
    const double k_ndc = std::tan(rig.cone / 2.0) / (rig.aspect * tan_half);
    const double room = (guard_ndc(rig.view_w) - 1.0) / (2.0 * k_ndc);
    if (!(room > 1.0)) {
      // the disparity grows with tan(cone / 2) / tan(yfov / 2): name both as the user gave them
      const bool from_camera = camera_pose && camera_yfov > 0.0 && !(config.yfov_deg > 0.0);
      char values[160];
      std::snprintf(values, sizeof values, "a %g degree view cone and a vertical field of view of %g degrees%s",
                    glm::degrees(rig.cone), glm::degrees(rig.yfov), from_camera ? " (the glTF camera's yfov)" : "");
      throw Error(std::string("the views' disparity would leave the fixed-point guard band with ") + values + " in a " +
                  std::to_string(rig.view_w) +
                  "-pixel view: widen the field of view (--yfov) or narrow the cone (--cone)");
    }
    // the near plane moves out to keep the disparity within the fixed-point range; that matters only
    // where it cuts a triangle, which the frame renderer counts (FrameRenderer::Frame::near_clipped)
    rig.near_eff = std::max(rig.near_eff, rig.focal / (1.0 + room));
  }
  if (!(rig.near_eff < rig.far)) throw Error("near plane is not in front of the far plane");
  if (rig.angular && rig.views > 1) choose_spacing_q(rig, warnings);
  return rig;
}

SpacingError spacing_error(const Rig& rig) {
  SpacingError e;
  if (!rig.angular || rig.views <= 1) return e;
  const double spacing = rig.baseline() / double(rig.views - 1);
  for (int i = 0; i < rig.views; ++i)
    e.view_spacings = std::max(e.view_spacings, std::abs(rig.camera_offset(i) - rig.angular_offset(i)) / spacing);
  e.view_px = e.view_spacings * disparity_per_spacing(rig);
  return e;
}

PmrParams make_params(const Rig& rig) {
  PmrParams p{};
  p.samples = 1;  // at the pixel center (offset 0) unless the pipeline sets a pattern
  p.texture_filter = PMR_FILTER_BILINEAR, p.lod_scale_x = p.lod_scale_y = 1.0f;  // the pipeline sets them
  const double* v = &rig.center_view[0][0];
  for (int k = 0; k < 16; ++k) p.view[k] = v[k];
  const double tan_half = std::tan(rig.yfov / 2.0);
  p.ndc_scale_x = 1.0 / (rig.aspect * tan_half);
  p.ndc_scale_y = 1.0 / tan_half;
  p.disparity_k = rig.views > 1 ? rig.disparity_k() : 0.0;
  p.focal = rig.focal;
  p.near_eff = rig.near_eff;
  p.far = rig.far;
  p.guard_ndc_x = guard_ndc(rig.view_w);
  p.guard_ndc_y = guard_ndc(rig.view_h);
  p.view_anchor = rig.view_anchor();
  p.view_scale = rig.view_scale();
  for (int i = 0; i < PMR_MAX_VIEWS + PMR_VIEW_COORD_SLACK; ++i)
    p.view_coord[i] = rig.view_coord(std::min(i, rig.views - 1));
  const glm::dvec3 l = rig.light_world();
  p.light_world[0] = float(l.x);
  p.light_world[1] = float(l.y);
  p.light_world[2] = float(l.z);
  p.view_w = rig.view_w;
  p.view_h = rig.view_h;
  p.views = rig.views;
  return p;
}

}  // namespace pmr
