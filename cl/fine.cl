/* Stage 4, fine raster: one work-item per 3D tile (PMR_TILE_X x PMR_TILE_Y pixels x PMR_TILE_V views).
 * The work-item walks its tile's queue once; for each MTA and each of its views in the tile it
 * evaluates the exact edge functions at the tile's first pixel center and steps them across the
 * tile with integer additions (E grows by dy per pixel in x and by -dx(i) per pixel in y), which is
 * exactly what evaluating them at every voxel gives. The closest fragment per voxel is kept in private
 * memory: the volume needs no depth buffer and no clear. Visibility is a total order on
 * (depth, key), so the result does not depend on queue order, tile size or thread count. Only the
 * winners are shaded (except for alphaMode MASK, whose alpha decides visibility). Scalar stepping code
 * per tile suits CPU devices far better than one work-item per voxel re-deriving everything. */
#include "shade.h"

#define PMR_TILE_VOXELS (PMR_TILE_X * PMR_TILE_Y * PMR_TILE_V)

kernel void fine_raster(global const PmrParams* P, global const PmrMta* mtas,
                        global const uint* tile_offsets, global const uint* tile_queue,
                        global const PmrTriangle* tris, global const PmrVertexAttr* attrs,
                        global const PmrMaterial* materials, global const PmrTexture* textures,
                        global const uchar4* texels, global const float* srgb_lut,
                        global half* volume, global uint* debug_key, global float* debug_depth,
                        global uint* debug_count) {
  const uint tile = get_global_id(0);
  const uint tiles_xy = (uint)P->tiles_x * (uint)P->tiles_y;
  if (tile >= tiles_xy * (uint)P->tiles_v) return;
  const int x0 = (int)(tile % (uint)P->tiles_x) * PMR_TILE_X;
  const int y0 = (int)((tile / (uint)P->tiles_x) % (uint)P->tiles_y) * PMR_TILE_Y;
  const int v0 = (int)(tile / tiles_xy) * PMR_TILE_V;
  const int nx = min(PMR_TILE_X, P->view_w - x0), ny = min(PMR_TILE_Y, P->view_h - y0);
  const int nv = min(PMR_TILE_V, P->views - v0);
  const long X0 = (long)x0 * PMR_X_ONE + PMR_HALF_X, Y0 = (long)y0 * PMR_Y_ONE + PMR_HALF_Y;

  ShadeInputs in = {tris, attrs, materials, textures, texels, srgb_lut};
  float best_depth[PMR_TILE_VOXELS];
  uint best_key[PMR_TILE_VOXELS], best_mta[PMR_TILE_VOXELS], covered[PMR_TILE_VOXELS];
  for (int k = 0; k < PMR_TILE_VOXELS; ++k) {
    best_depth[k] = INFINITY;
    best_key[k] = PMR_NO_KEY;
    best_mta[k] = 0;
    covered[k] = 0;
  }

  const uint q0 = tile_offsets[tile], q1 = tile_offsets[tile + 1];
  for (uint q = q0; q < q1; ++q) {
    const uint id = tile_queue[q];
    const PmrMta m = mtas[id];
    const long bias[3] = {mta_edge_bias(&m, 1, 2), mta_edge_bias(&m, 2, 0), mta_edge_bias(&m, 0, 1)};
    const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
    const int i_lo = max(v0, m.view_lo), i_hi = min(v0 + nv - 1, m.view_hi);
    /* the tile's pixel-center box, to skip views in which the (sheared) prism misses the tile */
    const long tile_x_lo = X0, tile_x_hi = X0 + (long)(nx - 1) * PMR_X_ONE;
    for (int i = i_lo; i <= i_hi; ++i) {
      const long xa = (long)m.x0[0] + (long)i * m.dx[0], xb = (long)m.x0[1] + (long)i * m.dx[1];
      const long xc = (long)m.x0[2] + (long)i * m.dx[2];
      if (max(xa, max(xb, xc)) < tile_x_lo || min(xa, min(xb, xc)) > tile_x_hi) continue;
      long row[3], step_x[3], step_y[3];
      for (int e = 0; e < 3; ++e) {
        const int a = ea[e], b = eb[e];
        const long xa = (long)m.x0[a] + (long)i * m.dx[a], xb = (long)m.x0[b] + (long)i * m.dx[b];
        const long dy = (long)(m.y[b] - m.y[a]), dx = xb - xa;
        row[e] = m.sign * (dy * (X0 - xa) - dx * (Y0 - (long)m.y[a]));
        step_x[e] = m.sign * dy * PMR_X_ONE;
        step_y[e] = -m.sign * dx * PMR_Y_ONE;
      }
      const int vbase = (i - v0) * PMR_TILE_X * PMR_TILE_Y;
      for (int ly = 0; ly < ny; ++ly) {
        long e0 = row[0], e1 = row[1], e2 = row[2];
        for (int lx = 0; lx < nx; ++lx) {
          if (e0 >= bias[0] && e1 >= bias[1] && e2 >= bias[2]) {
            const int k = vbase + ly * PMR_TILE_X + lx;
            ++covered[k];
            /* depth is linear in screen space: barycentrics from the edge functions */
            const float depth = ((float)e0 * m.z[0] + (float)e1 * m.z[1] + (float)e2 * m.z[2]) / (float)(e0 + e1 + e2);
            bool wins = depth < best_depth[k] || (depth == best_depth[k] && m.key < best_key[k]);
            if (wins && (m.flags & PMR_MTA_MASK)) {
              const long ev[3] = {e0, e1, e2};
              wins = base_color(&in, m.tri, source_barycentrics(&m, ev)).w >= materials[tris[m.tri].material].alpha_cutoff;
            }
            if (wins) {
              best_depth[k] = depth;
              best_key[k] = m.key;
              best_mta[k] = id;
            }
          }
          e0 += step_x[0];
          e1 += step_x[1];
          e2 += step_x[2];
        }
        row[0] += step_y[0];
        row[1] += step_y[1];
        row[2] += step_y[2];
      }
    }
  }

  /* frame constants in registers: stores through the output pointers could alias P */
  const bool debug = P->debug_outputs != 0;
  const size_t W = (size_t)P->view_w, H = (size_t)P->view_h, view_base = (size_t)P->view_base;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  for (int lv = 0; lv < nv; ++lv)
    for (int ly = 0; ly < ny; ++ly)
      for (int lx = 0; lx < nx; ++lx) {
        const int k = (lv * PMR_TILE_Y + ly) * PMR_TILE_X + lx;
        const int view = v0 + lv, px = x0 + lx, py = y0 + ly;
        const size_t voxel = (((size_t)view + view_base) * H + (size_t)py) * W + (size_t)px;
        if (best_key[k] != PMR_NO_KEY) {
          const PmrMta m = mtas[best_mta[k]];
          /* the winner's edge functions at this voxel, for its barycentrics */
          long e[3];
          e[0] = m.sign * mta_edge(&m, 1, 2, (long)px * PMR_X_ONE + PMR_HALF_X, (long)py * PMR_Y_ONE + PMR_HALF_Y, view);
          e[1] = m.sign * mta_edge(&m, 2, 0, (long)px * PMR_X_ONE + PMR_HALF_X, (long)py * PMR_Y_ONE + PMR_HALF_Y, view);
          e[2] = m.sign * mta_edge(&m, 0, 1, (long)px * PMR_X_ONE + PMR_HALF_X, (long)py * PMR_Y_ONE + PMR_HALF_Y, view);
          vstore_half4(shade(&in, light, m.tri, source_barycentrics(&m, e), (m.flags & PMR_MTA_BACK) != 0), voxel, volume);
        } else {
          vstore4((ushort4)(0), voxel, (global ushort*)volume); /* background */
        }
        if (debug) {
          debug_key[voxel] = best_key[k];
          debug_depth[voxel] = best_depth[k];
          debug_count[voxel] = covered[k];
        }
      }
}
