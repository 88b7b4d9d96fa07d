/* Stage 1, vertex transform: every scene vertex is transformed ONCE, world -> center view space,
 * and projected to its view-0 raster x, per-view disparity, raster y, depth and 1/w. */
#include "common.h"

kernel void vertex_transform(global const PmrParams* P, global const float* positions, global PmrVertex* out) {
  const uint v = pmr_item_id();
  if (v >= P->num_vertices) return;
  const double px = positions[3 * v], py = positions[3 * v + 1], pz = positions[3 * v + 2];
  global const double* V = P->view; /* column-major */
  const double xv = V[0] * px + V[4] * py + V[8] * pz + V[12];
  const double yv = V[1] * px + V[5] * py + V[9] * pz + V[13];
  const double zv = V[2] * px + V[6] * py + V[10] * pz + V[14];
  PmrVertex r;
  project_vertex(P, xv, yv, zv, &r);
  out[v] = r;
}

/* Test mode of the multipass baseline: a view's snapped positions taken from PMR's vertex records
 * (x = x0 + F dx with the view's view coordinate F, no disparity), so that a single-view pass sees
 * exactly PMR's positions. */
kernel void vertex_select_view(global const PmrParams* P, global const PmrVertex* pmr_verts, int coord,
                               global PmrVertex* out) {
  const uint v = pmr_item_id();
  if (v >= P->num_vertices) return;
  PmrVertex r = pmr_verts[v];
  r.x0 = (int)((long)r.x0 + (long)coord * (long)r.dx);
  r.dx = 0;
  out[v] = r;
}
