/* Stages 4 and 5 fused, for the encoded-only job with nearest sampling: one work-item per screen tile
 * (PMR_TILE_X x PMR_TILE_Y pixels) and ALL PMR_FUSED_VIEWS views. It rasterizes the queues of the
 * tile's view slabs (fine_raster.h) into one private visibility state, shades the winners, and writes
 * the display pixels whose subpixels sample these voxels, with the same map as encode.cl (DESIGN
 * section 5). The view volume (403 MB at paper-8k) is never written nor read, and the display image is
 * bit-identical to fine.cl followed by encode.cl.
 *
 * Ownership: display subpixel s belongs to the tile holding its view column px(s), display row i to the
 * tile holding its view row py(i) (both maps are monotone; column_start / row_start give each view
 * column's and row's first subpixel and display row). A display pixel whose three subpixels belong to
 * different tiles ("straddling", a column property the host lists) gets each colour channel from the
 * subpixel's owner and its alpha, the mean coverage, from encode_straddle_alpha once all tiles are
 * done: the owners leave one coverage byte per subpixel in straddle_cov. */
#include "fine_raster.h"

#define FUSED_ROWS (PMR_TILE_Y * PMR_FUSED_VIEWS * FINE_CHUNKS)

/* Subpixel s's entry of the encoder column table, from its planes (see the display scan below). */
inline PmrEncodeColumn soa_column(global const int* column_soa, int width, int s) {
  const int j = s / 3, k = s % 3;
  PmrEncodeColumn c;
  c.a_mod_n = column_soa[k * width + j];
  c.b = column_soa[(3 + k) * width + j];
  c.px = column_soa[(6 + k) * width + j];
  c.phase_frac = 0.0f;  /* (only view blending reads it; the fused path does not blend) */
  return c;
}

/* Index of voxel (view, ly, lx) in the visibility state and colour arrays. */
inline int fused_voxel(int view, int ly, int lx) {
  return ((view * PMR_TILE_Y + ly) * FINE_CHUNKS + lx / VW) * VW + lx % VW;
}

kernel void fine_encode(global const PmrParams* P, global const PmrMta* mtas,
                        global const uint* tile_offsets, global const uint* tile_queue,
                        global const PmrTriangle* tris, global const PmrVertexAttr* attrs,
                        global const PmrMaterial* materials, global const PmrTexture* textures,
                        global const uchar4* texels, global const float* srgb_lut, global const float* positions,
                        global const float4* eyes, global const float2* split_sum, global const float2* texcoords, global const float4* tangents,
                        global const PmrEncodeParams* E, global const int* column_soa,
                        global const PmrEncodeRow* rows, global const int* column_start,
                        global const int* row_start, global const int* straddle_slot, uint straddle_slots,
                        global uchar* straddle_cov, global half* display, global ushort* sub_alpha,
                        global const PmrEnvironment* env,
                        global const float4* env_data, global const PmrLight* lights) {
  const uint tile_xy = pmr_item_id();
  const uint tiles_x = (uint)P->tiles_x, tiles_y = (uint)P->tiles_y;
  if (tile_xy >= tiles_x * tiles_y) return;
  const int x0 = (int)(tile_xy % tiles_x) * PMR_TILE_X, y0 = (int)(tile_xy / tiles_x) * PMR_TILE_Y;
  const int nx = min(PMR_TILE_X, P->view_w - x0), ny = min(PMR_TILE_Y, P->view_h - y0);
  const int views = P->views;

  ShadeInputs in = {tris, attrs, materials, textures, texels, srgb_lut, P, positions, eyes, split_sum, texcoords, tangents, env, env_data,
                    lights};
  vfloat best_depth[FUSED_ROWS];
  vuint best_key[FUSED_ROWS], best_mta[FUSED_ROWS];
  fine_clear_state(FUSED_ROWS, best_depth, best_key, best_mta);
  for (int tv = 0; tv < P->tiles_v; ++tv) {
    const uint tile = ((uint)tv * tiles_y) * tiles_x + tile_xy;
    const int v0 = tv * PMR_TILE_V;
    fine_raster_queue(mtas, tile_queue, tile_offsets[tile], tile_offsets[tile + 1], &in, tris, materials, x0, y0,
                      v0, nx, ny, min(PMR_TILE_V, views - v0), 0, best_depth, best_key, best_mta, 0);
  }

  /* the winners' colours as half bits, background zero */
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  ushort4 colour[FUSED_ROWS * VW];
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  for (int view = 0; view < views; ++view)
    for (int ly = 0; ly < ny; ++ly)
      for (int c = 0; c * VW < nx; ++c) {
        const int r = (view * PMR_TILE_Y + ly) * FINE_CHUNKS + c; /* fused_voxel(view, ly, c * VW) / VW */
        fine_shade_chunk(&in, mtas, &cache, light, best_mta[r], best_key[r] != (vuint)(PMR_NO_KEY), x0 + c * VW, y0 + ly,
                         view, colour + r * VW);
      }

  /* the display pixels this tile owns, whole or in part */
  const int width = E->display_w, reversed = E->reversed;
  const int s_lo = column_start[x0], s_hi = column_start[x0 + nx];
  const int i_lo = row_start[y0], i_hi = row_start[y0 + ny];
  global ushort* bits = (global ushort*)display;
  /* colour[] index of voxel (view, ly, lx) = view * VIEW_STRIDE + ly * ROW_STRIDE + lx (fused_voxel) */
  const int ROW_STRIDE = FINE_CHUNKS * VW, VIEW_STRIDE = PMR_TILE_Y * FINE_CHUNKS * VW;
  const ulong* colour_bits = (const ulong*)colour;
  /* display pixels wholly owned: j in [j_a, j_b) */
  const int j_a = (s_lo + 2) / 3, j_b = s_hi / 3;
  for (int i = i_lo; i < i_hi; ++i) {
    const PmrEncodeRow row = rows[i];
    const int ly = row.py - y0;
    global ulong* row_bits = (global ulong*)display + (size_t)i * (size_t)width;
    /* Eight wholly owned pixels at a time: the view and colour index of each subpixel as 8-lane vector
     * arithmetic on the column tables' planes (column_soa[(field * 3 + k) * width + j], fields a_mod_n,
     * b, px), then the colours fetched one by one. Same map as encode_view. */
    const int8 q = (int8)(row.q_mod_n), srow = (int8)(row.s), base = (int8)(ly * ROW_STRIDE - x0);
    int j = j_a;
    for (; j + 8 <= j_b; j += 8) {
      int idx[3][8];
      for (int k = 0; k < 3; ++k) {
        const int8 a = vload8(0, column_soa + (size_t)(0 * 3 + k) * width + j);
        const int8 b = vload8(0, column_soa + (size_t)(1 * 3 + k) * width + j);
        const int8 px = vload8(0, column_soa + (size_t)(2 * 3 + k) * width + j);
        int8 v = a - q + (b < srow); /* a true comparison is -1 */
        v = select(v, v + views, v < 0);
        if (reversed) v = (int8)(views - 1) - v;
        vstore8(v * VIEW_STRIDE + base + px, 0, idx[k]);
      }
      for (int l = 0; l < 8; ++l) {
        const ulong c0 = colour_bits[idx[0][l]], c1 = colour_bits[idx[1][l]], c2 = colour_bits[idx[2][l]];
        row_bits[j + l] = as_ulong(encode_pixel(as_ushort4(c0), as_ushort4(c1), as_ushort4(c2)));
        store_sub_alpha(sub_alpha, (size_t)i * (size_t)width + (size_t)(j + l), as_ushort4(c0), as_ushort4(c1),
                        as_ushort4(c2));
      }
    }
    /* the rest one at a time: a partly owned pixel at each end, wholly owned ones after the last eight */
    for (int jj = s_lo / 3; 3 * jj < s_hi; ++jj) {
      if (jj == j_a && j > j_a) { /* skip the pixels done eight at a time */
        jj = j - 1;
        continue;
      }
      const size_t pixel = (size_t)i * (size_t)width + (size_t)jj;
      if (3 * jj >= s_lo && 3 * jj + 3 <= s_hi) {
        const PmrEncodeColumn c0 = soa_column(column_soa, width, 3 * jj);
        const PmrEncodeColumn c1 = soa_column(column_soa, width, 3 * jj + 1);
        const PmrEncodeColumn c2 = soa_column(column_soa, width, 3 * jj + 2);
        const ushort4 a = colour[fused_voxel(encode_view(views, reversed, &c0, &row), ly, c0.px - x0)];
        const ushort4 b = colour[fused_voxel(encode_view(views, reversed, &c1, &row), ly, c1.px - x0)];
        const ushort4 c = colour[fused_voxel(encode_view(views, reversed, &c2, &row), ly, c2.px - x0)];
        vstore4(encode_pixel(a, b, c), pixel, bits);
        store_sub_alpha(sub_alpha, pixel, a, b, c);
        continue;
      }
      const size_t slot = ((size_t)i * straddle_slots + (size_t)straddle_slot[jj]) * 3;
      for (int k = 0; k < 3; ++k) {
        const int s = 3 * jj + k;
        if (s < s_lo || s >= s_hi) continue;
        const PmrEncodeColumn col = soa_column(column_soa, width, s);
        const ushort4 a = colour[fused_voxel(encode_view(views, reversed, &col, &row), ly, col.px - x0)];
        bits[pixel * 4 + (size_t)k] = k == 0 ? a.x : (k == 1 ? a.y : a.z);
        straddle_cov[slot + (size_t)k] = a.w != 0 ? 1 : 0;
        sub_alpha[pixel * 3 + (size_t)k] = a.w; /* this subpixel's own: written by its tile alone */
      }
    }
  }
}
