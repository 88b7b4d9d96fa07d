// --background environment: the environment behind the scene, drawn as if painted on a plane at a
// chosen depth z_b in front of the center camera (docs/OUTPUTS.md, "Backgrounds").
//
// Voxel (x, y, i) sees, through its pixel center on the shared focal-plane window (DESIGN section 2),
// the point P_i of the plane z = -z_b on camera i's ray; the backdrop there is the environment along
// the center camera's direction to P_i. In the center camera's view space, divided by D:
//   d_i(x, y) = ((2 (x + 1/2) / W - 1) A t - f s_i / D,  (1 - 2 (y + 1/2) / H) t,  -1),  t = tan(phi / 2)
// with the parallax fraction f = 1 - D / z_b: f = 0 on the focal plane (every view sees the same
// picture, no disparity), f = 1 at infinity (each camera's own view of the environment, whose disparity
// on this rig is the largest there is: several view widths across a Looking Glass's views). So the
// backdrop shifts between views 0 and N-1 by f Delta(inf) = Delta(z_b) view pixels, as a surface at z_b.
// f is clamped to [0, f_max]: at most kBackdropMaxStepPx of disparity between neighbouring views, where
// a lenticular panel still shows it without doubling.
#pragma once
#include <cstdint>
#include <vector>

#include "output/background.h"
#include "pmr/rig.h"

namespace pmr {

class Environment;

constexpr double kBackdropMaxStepPx = 1.0;

struct BackdropParallax {
  double fraction = 0.0;  // f, clamped
  double step_px = 0.0;   // the largest disparity between neighbouring views, view pixels, after the clamp
  bool clamped = false;   // the depth asked for more (or was nearer than the focal plane)
};
BackdropParallax backdrop_parallax(const Rig& rig, const BackdropDepth& depth);

// Whether two rigs draw the same backdrop (the same cameras, rasters and window).
bool same_backdrop_rig(const Rig& a, const Rig& b);

// The world-space directions the voxels sample (not unit length), with what every voxel shares
// (tan(phi / 2), the inverse rotation) worked out once.
class BackdropRays {
 public:
  BackdropRays(const Rig& rig, double fraction);
  glm::dvec3 direction(int view, int x, int y) const;

 private:
  const Rig& rig_;
  double fraction_, tan_half_;
  glm::dmat3 to_world_;
};

// The backdrop volume (half RGBA, premultiplied, alpha 1, view-major as the pipeline's volume): one
// environment lookup (Environment::radiance, bilinear in the image) per voxel; with f = 0 one view's,
// copied to every view.
std::vector<uint16_t> render_backdrop(const Rig& rig, const Environment& environment, double fraction);

}  // namespace pmr
