// Plain C++ references for the kernels. They are written the obvious, slow way (per view, per pixel)
// so that the tiled multi-view kernels can be checked against them: the snapping and clipping are the
// definitions of DESIGN sections 2-3 transcribed in scalar double arithmetic, the rasterizer is a
// conventional single-view rasterizer fed each view's snapped positions x0 + F_i * dx (F_i the view's
// view coordinate, P.view_coord[i]: i with linear spacing).
#pragma once
#include <cstdint>
#include <vector>

#include "pmr/scene.h"
#include "pmr/shared.h"

namespace pmr::ref {

// Vertex stage: world position -> snapped vertex record.
PmrVertex transform_vertex(const PmrParams& P, const float* world_pos);

// One clipped triangle with its snapped vertices, before the orientation split.
struct ClippedTriangle {
  PmrVertex v[3];
  double bary[3][2];
  uint32_t tri = 0, key = 0;
  bool double_sided = false, mask = false, transmissive = false;
};
// Setup without the orientation split: culling, clipping, fan triangulation.
std::vector<ClippedTriangle> clip_triangles(const PmrParams& P, const Scene& scene,
                                            const std::vector<PmrVertex>& verts);
// The MTA records setup must produce, sorted by (key, view_lo).
std::vector<PmrMta> make_mtas(const PmrParams& P, const std::vector<ClippedTriangle>& tris);
void sort_mtas(std::vector<PmrMta>& mtas);

// A clipped triangle in the view with view coordinate v: its snapped vertices, orientation sign, each
// edge's top-left bias, and whether it is drawn there (not degenerate, front-facing or double-sided).
struct ViewTriangle {
  int64_t x[3], y[3], sign, bias[3];
  bool drawn;
};
ViewTriangle view_triangle(const ClippedTriangle& c, int64_t v);
// Whether the triangle covers raster point (X, Y) (16.16, 24.8) under section 3's rules.
bool covers(const ViewTriangle& t, int64_t X, int64_t Y);

struct RasterResult {
  std::vector<uint32_t> key;    // [view][y][x][sample], PMR_NO_KEY when empty
  std::vector<float> depth;     // INFINITY when empty
  std::vector<uint32_t> count;  // number of triangles covering the sample (before depth test)
};
// Conventional per-view rasterization with the top-left rule and (depth, key) visibility, at each
// pixel's P.samples samples (P.sample_x/y from its center; DESIGN section 3b).
RasterResult rasterize(const PmrParams& P, const std::vector<ClippedTriangle>& tris);

// --sampling subpixel (DESIGN section 5, docs/SAMPLING.md): display subpixel (j, i, k) sampled at
// ((3j + k + 1/2) / (3 W_d) W, (i + 1/2) / H_d H) of its view's raster, truncated to 16.16 / 24.8, in view
// view_of[i * 3 W_d + 3j + k], each of its P.samples samples at the offsets P.sample_x/y from there; the
// same top-left rule and (depth, key) visibility, the depth being the one depth formula (depth_at, as at
// pixel centers) evaluated at the sample.
struct SubpixelResult {
  std::vector<uint32_t> key;  // [row][3 * column + k][sample], PMR_NO_KEY when empty
  std::vector<float> depth;   // INFINITY when empty
  std::vector<int64_t> x, y;  // [row][3 * column + k]: each subpixel's own sample, fixed point
};
SubpixelResult rasterize_subpixels(const PmrParams& P, const std::vector<ClippedTriangle>& tris,
                                   const std::vector<int>& view_of, int display_w, int display_h);

// Convenience: the whole reference pipeline for a scene.
RasterResult render(const PmrParams& P, const Scene& scene);

}  // namespace pmr::ref
