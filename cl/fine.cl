/* Stage 4, fine raster: one work-item per 3D tile (PMR_TILE_X x PMR_TILE_Y pixels x PMR_TILE_V views)
 * rasterizes its queue (fine_raster.h), shades the winners and writes them to the view volume. This is
 * the path for jobs that need the views themselves (--write views, bilinear encoding, the baselines,
 * the debug outputs) and for every path's transmission source (the opaque pass, into the source's level
 * 0); the encoded-only job uses fine_encode.cl, which never writes the volume. */
#include "blend.h"

/* The tile's voxels (nv views from v0, ny rows from y0, nx columns from x0) copied from the transmission
 * source's level 0 (the same layout) into the volume. */
inline void copy_source_tile(global const half* source, global half* volume, global const PmrParams* P, int x0, int y0,
                             int v0, int nx, int ny, int nv) {
  const size_t W = (size_t)P->view_w, H = (size_t)P->view_h, view_base = (size_t)P->view_base;
  for (int lv = 0; lv < nv; ++lv)
    for (int ly = 0; ly < ny; ++ly) {
      const size_t row = (((size_t)(v0 + lv) + view_base) * H + (size_t)(y0 + ly)) * W + (size_t)x0;
      for (int lx = 0; lx < nx; ++lx)
        vstore4(vload4(row + (size_t)lx, (global const ushort*)source), row + (size_t)lx, (global ushort*)volume);
    }
}

kernel void fine_raster(PMR_SHADE_PARAMS, global const PmrMta* mtas, global const uint* tile_offsets,
                        global const uint* tile_queue, global half* volume, global uint* debug_key,
                        global float* debug_depth, global uint* debug_count, global uint* blend_overflow) {
  const uint tile = pmr_item_id();
  const uint tiles_xy = (uint)P->tiles_x * (uint)P->tiles_y;
  if (tile >= tiles_xy * (uint)P->tiles_v) return;
  const int x0 = (int)(tile % (uint)P->tiles_x) * PMR_TILE_X;
  const int y0 = (int)((tile / (uint)P->tiles_x) % (uint)P->tiles_y) * PMR_TILE_Y;
  const int v0 = (int)(tile / tiles_xy) * PMR_TILE_V;
  const int nx = min(PMR_TILE_X, P->view_w - x0), ny = min(PMR_TILE_Y, P->view_h - y0);
  const int nv = min(PMR_TILE_V, P->views - v0);
  ShadeInputs in = PMR_SHADE_INPUTS;
  const bool opaque_pass = source_info->opaque_only != 0;
  const bool debug = P->debug_outputs != 0 && !opaque_pass; /* the frame's outputs: its last pass */
  if (!debug && source_info->levels > 0u && source_tiles[tile] == 0u) {
    /* no glass here: the opaque pass drew this tile as this pass would */
    copy_source_tile(source, volume, P, x0, y0, v0, nx, ny, nv);
    return;
  }
  vfloat best_depth[FINE_ROWS * NS];
  vuint best_key[FINE_ROWS * NS], best_mta[FINE_ROWS * NS], best_cover[NS > 1 ? FINE_ROWS * NS : 1];
  vint covered[FINE_ROWS * NS];
  uint glass = 0u, blend = 0u;
  /* the opaque walk: BLEND comes after it, and the transmission source's pass leaves the glass out */
  FineState st = fine_state(best_depth, best_key, best_mta, best_cover, debug ? covered : 0,
                            PMR_MTA_BLEND | (opaque_pass ? PMR_MTA_TRANSMISSIVE : 0u));
  st.glass = opaque_pass ? &glass : 0;
  st.blend = &blend;
  fine_clear_state(FINE_ROWS * NS, &st);
  for (int r = 0; r < FINE_ROWS * NS; ++r) covered[r] = (vint)(0);
  const TileWalk walk = {mtas, tile_queue, tile_offsets[tile], tile_offsets[tile + 1], x0, y0, v0, nx, ny, nv};
  walk_tile(&in, &walk, &st);
  if (opaque_pass) source_tiles[tile] = glass;
  vfloat T[FINE_ROWS * NS], acc[4 * FINE_ROWS];
  if (blend) {
    /* the source's pass holds the BLEND fragments behind each sample's nearest glass */
    vfloat glass_depth[FINE_ROWS * NS];
    vuint glass_key[FINE_ROWS * NS], glass_mta[FINE_ROWS * NS], glass_cover[NS > 1 ? FINE_ROWS * NS : 1];
    FineState front = fine_state(glass_depth, glass_key, glass_mta, glass_cover, 0, PMR_MTA_BLEND);
    front.need = PMR_MTA_TRANSMISSIVE;
    if (glass) {
      fine_clear_state(FINE_ROWS * NS, &front);
      walk_tile(&in, &walk, &front);
    }
    const uint beyond = blend_layers(&in, &walk, &st, glass ? &front : 0, T, acc);
    if (beyond && !opaque_pass) atomic_add(blend_overflow, beyond);
  }

  /* frame constants in registers: stores through the output pointers could alias P */
  const size_t W = (size_t)P->view_w, H = (size_t)P->view_h, view_base = (size_t)P->view_base;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  const float* depth_of = (const float*)best_depth;
  const uint* key_of = (const uint*)best_key;
  const int* count_of = (const int*)covered;
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  for (int lv = 0; lv < nv; ++lv)
    for (int ly = 0; ly < ny; ++ly)
      for (int c = 0; c * VW < nx; ++c) {
        const int r = (lv * PMR_TILE_Y + ly) * FINE_CHUNKS + c;
        const int view = v0 + lv, py = y0 + ly;
        ushort4 colour[VW];
        vint won[NS];
        for (int s = 0; s < NS; ++s) won[s] = best_key[FINE_SLOT(r, s)] != (vuint)(PMR_NO_KEY);
        fine_shade_chunk(&in, mtas, &cache, light, best_mta + FINE_SLOT(r, 0),
                         best_cover + (NS > 1 ? FINE_SLOT(r, 0) : 0), won, blend ? acc + 4 * r : 0,
                         blend ? T + FINE_SLOT(r, 0) : 0, x0 + c * VW, py, view, colour);
        for (int l = 0; l < VW && c * VW + l < nx; ++l) {
          const int px = x0 + c * VW + l;
          const size_t voxel = (((size_t)view + view_base) * H + (size_t)py) * W + (size_t)px;
          vstore4(colour[l], voxel, (global ushort*)volume);
          for (int s = 0; s < NS && debug; ++s) { /* per sample: [voxel][sample] */
            const int k = FINE_SLOT(r, s) * VW + l;
            debug_key[voxel * NS + s] = key_of[k];
            debug_depth[voxel * NS + s] = depth_of[k];
            debug_count[voxel * NS + s] = (uint)count_of[k];
          }
        }
      }
}
