/* Stage 4, fine raster: one work-group per 3D tile, one work-item per voxel (x, y, view). Each
 * work-item walks its tile's queue, tests exact coverage (top-left rule) of its voxel center in its
 * view, and keeps the closest fragment in private memory: the volume needs no depth buffer and no
 * clear. Visibility is a total order on (depth, key), so the result does not depend on queue order,
 * tile size or thread count. Only the winner is shaded (shading does not affect visibility, except
 * for alphaMode MASK, whose alpha is evaluated for candidate fragments). */
#include "shade.h"

kernel void fine_raster(global const PmrParams* P, global const PmrMta* mtas,
                        global const uint* tile_offsets, global const uint* tile_queue,
                        global const PmrTriangle* tris, global const PmrVertexAttr* attrs,
                        global const PmrMaterial* materials, global const PmrTexture* textures,
                        global const uchar4* texels, global const float* srgb_lut,
                        global half* volume, global uint* debug_key, global float* debug_depth,
                        global uint* debug_count) {
  /* 3D range: x, y, view; one work-group is one tile (no divisions per work-item) */
  const int px = (int)get_global_id(0), py = (int)get_global_id(1), view = (int)get_global_id(2);
  const uint tile = ((uint)get_group_id(2) * (uint)P->tiles_y + (uint)get_group_id(1)) * (uint)P->tiles_x + (uint)get_group_id(0);
  const bool valid = px < P->view_w && py < P->view_h && view < P->views;
  const long X = (long)px * PMR_X_ONE + PMR_HALF_X, Y = (long)py * PMR_Y_ONE + PMR_HALF_Y;

  ShadeInputs in = {tris, attrs, materials, textures, texels, srgb_lut};
  float best_depth = INFINITY;
  uint best_key = PMR_NO_KEY, best_mta = 0, covered_count = 0;
  long best_e[3] = {0, 0, 0};

  const uint q0 = tile_offsets[tile], q1 = tile_offsets[tile + 1];
  for (uint q = q0; q < q1; ++q) {
    const uint id = tile_queue[q];
    const PmrMta m = mtas[id];
    if (!valid || view < m.view_lo || view > m.view_hi) continue;
    long e[3];
    e[0] = m.sign * mta_edge(&m, 1, 2, X, Y, view);
    e[1] = m.sign * mta_edge(&m, 2, 0, X, Y, view);
    e[2] = m.sign * mta_edge(&m, 0, 1, X, Y, view);
    if (e[0] < mta_edge_bias(&m, 1, 2) || e[1] < mta_edge_bias(&m, 2, 0) || e[2] < mta_edge_bias(&m, 0, 1))
      continue;
    ++covered_count;
    /* depth is linear in screen space: barycentrics from the edge functions */
    const float area = (float)(e[0] + e[1] + e[2]);
    const float depth = ((float)e[0] * m.z[0] + (float)e[1] * m.z[1] + (float)e[2] * m.z[2]) / area;
    if (depth > best_depth || (depth == best_depth && m.key >= best_key)) continue;
    if (m.flags & PMR_MTA_MASK) {
      const float alpha = base_color(&in, m.tri, source_barycentrics(&m, e)).w;
      if (alpha < materials[tris[m.tri].material].alpha_cutoff) continue;
    }
    best_depth = depth;
    best_key = m.key;
    best_mta = id;
    best_e[0] = e[0];
    best_e[1] = e[1];
    best_e[2] = e[2];
  }
  if (!valid) return;

  const size_t voxel = ((size_t)(view + (int)P->view_base) * (size_t)P->view_h + (size_t)py) * (size_t)P->view_w + (size_t)px;
  if (best_key != PMR_NO_KEY) {
    const PmrMta m = mtas[best_mta];
    vstore_half4(shade(&in, P, m.tri, source_barycentrics(&m, best_e), (m.flags & PMR_MTA_BACK) != 0), voxel, volume);
  } else {
    vstore4((ushort4)(0), voxel, (global ushort*)volume); /* background; PoCL converts halves in software */
  }
  if (P->debug_outputs) {
    debug_key[voxel] = best_key;
    debug_depth[voxel] = best_depth;
    debug_count[voxel] = covered_count;
  }
}
