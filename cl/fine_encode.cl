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
 * subpixel's owner and its alpha, the mean of the subpixels' own alphas, from encode_straddle_alpha
 * once all tiles are done (write_display_pixel in fine_core.h, which fine_subpixel.cl's display pixels
 * go through too). */
/* BLEND scenes never come here (Pipeline::choose_paths): compiled without its work */
#define PMR_WITH_BLEND 0
#include "fine_raster.h"

#define FUSED_ROWS (PMR_TILE_Y * PMR_FUSED_VIEWS * FINE_CHUNKS)

/* The tile's shaded voxels (half RGBA bits, background zero) and what maps a display subpixel to one:
 * the column table's planes column_soa[(field * 3 + k) * width + j] for subpixel s = 3 j + k, fields
 * a_mod_n, b, px (so that eight columns load as vectors). */
typedef struct {
  const ushort4* colour;
  global const int* column_soa;
  int width, views, reversed, x0;
} FusedTile;

/* colour[] index of voxel (view, ly, lx): view * FUSED_VIEW_STRIDE + ly * FUSED_ROW_STRIDE + lx, the
 * visibility state's order (fine_raster_queue). */
#define FUSED_ROW_STRIDE (FINE_CHUNKS * VW)
#define FUSED_VIEW_STRIDE (PMR_TILE_Y * FINE_CHUNKS * VW)

/* The colour display subpixel s of row `row` (view row ly of the tile) samples. */
PMR_HOT ushort4 fused_subpixel(const FusedTile* T, const PmrEncodeRow* row, int ly, int s) {
  global const int* plane = T->column_soa + (size_t)(s % 3) * T->width + s / 3;
  PmrEncodeColumn c;
  c.a_mod_n = plane[0];
  c.b = plane[3 * T->width];
  c.px = plane[6 * T->width];
  c.phase_frac = 0.0f; /* (only view blending reads it; the fused path does not blend) */
  const int view = encode_view(T->views, T->reversed, &c, row);
  return T->colour[view * FUSED_VIEW_STRIDE + ly * FUSED_ROW_STRIDE + c.px - T->x0];
}

/* Display pixel j of row i, of whose subpixels the tile owns [s_lo, s_hi). */
PMR_HOT void fused_pixel(const DisplayOut* D, const FusedTile* T, const PmrEncodeRow* row, int i, int ly, int j,
                         int s_lo, int s_hi) {
  ushort4 s[3];
  for (int k = 0; k < 3; ++k)
    s[k] = 3 * j + k >= s_lo && 3 * j + k < s_hi ? fused_subpixel(T, row, ly, 3 * j + k) : (ushort4)(0);
  write_display_pixel(D, i, j, s_lo, s_hi, s[0], s[1], s[2]);
}

/* Eight wholly owned display pixels j .. j + 7 of row i: each subpixel's view and colour index in 8-lane
 * vector arithmetic on the column planes (encode_view8), then the colours fetched one by one. */
PMR_HOT void fused_pixels8(const DisplayOut* D, const FusedTile* T, const PmrEncodeRow* row, int i, int ly, int j) {
  const int8 base = (int8)(ly * FUSED_ROW_STRIDE - T->x0);
  int idx[3][8];
  for (int k = 0; k < 3; ++k) {
    global const int* plane = T->column_soa + (size_t)k * T->width + j;
    const int8 a = vload8(0, plane), b = vload8(0, plane + 3 * T->width), px = vload8(0, plane + 6 * T->width);
    vstore8(encode_view8(T->views, T->reversed, a, b, row) * FUSED_VIEW_STRIDE + base + px, 0, idx[k]);
  }
  const ulong* colour_bits = (const ulong*)T->colour;
  for (int l = 0; l < 8; ++l)
    write_display_pixel(D, i, j + l, 3 * (j + l), 3 * (j + l) + 3, as_ushort4(colour_bits[idx[0][l]]),
                        as_ushort4(colour_bits[idx[1][l]]), as_ushort4(colour_bits[idx[2][l]]));
}

/* The display pixels of row i (view row ly of the tile) with a subpixel in [s_lo, s_hi), the tile's. */
inline void fused_display_row(const DisplayOut* D, const FusedTile* T, const PmrEncodeRow* row, int i, int ly, int s_lo,
                              int s_hi) {
  const int j_a = (s_lo + 2) / 3, j_b = s_hi / 3; /* wholly owned: [j_a, j_b) */
  int j = j_a;
  for (; j + 8 <= j_b; j += 8) fused_pixels8(D, T, row, i, ly, j);
  /* the rest one at a time: a partly owned pixel at each end, wholly owned ones after the last eight */
  if (s_lo % 3 != 0 && s_lo < s_hi) fused_pixel(D, T, row, i, ly, s_lo / 3, s_lo, s_hi);
  for (; 3 * j < s_hi; ++j) fused_pixel(D, T, row, i, ly, j, s_lo, s_hi);
}

/* The tile's voxels rasterized and shaded: colour[] as half bits, background zero, in the visibility
 * state's order (FUSED_VIEW_STRIDE, FUSED_ROW_STRIDE). */
inline void fused_raster_shade(const ShadeInputs* in, global const PmrMta* mtas, global const uint* tile_offsets,
                               global const uint* tile_queue, uint tile_xy, int x0, int y0, int nx, int ny,
                               ushort4* colour) {
  global const PmrParams* P = in->P;
  const int views = P->views;
  vfloat best_depth[FUSED_ROWS * NS];
  vuint best_key[FUSED_ROWS * NS], best_mta[FUSED_ROWS * NS], best_cover[NS > 1 ? FUSED_ROWS * NS : 1];
  const FineState st = fine_state(best_depth, best_key, best_mta, best_cover, 0, 0u);
  fine_clear_state(FUSED_ROWS * NS, &st);
  for (int tv = 0; tv < P->tiles_v; ++tv) {
    const uint tile = ((uint)tv * (uint)P->tiles_y) * (uint)P->tiles_x + tile_xy;
    const int v0 = tv * PMR_TILE_V;
    fine_raster_queue(mtas, tile_queue, tile_offsets[tile], tile_offsets[tile + 1], in, in->tris, in->materials, x0, y0,
                      v0, nx, ny, min(PMR_TILE_V, views - v0), 0, &st);
  }
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  for (int view = 0; view < views; ++view)
    for (int ly = 0; ly < ny; ++ly)
      for (int c = 0; c * VW < nx; ++c) {
        const int r = (view * PMR_TILE_Y + ly) * FINE_CHUNKS + c;
        vint won[NS];
        for (int s = 0; s < NS; ++s) won[s] = best_key[FINE_SLOT(r, s)] != (vuint)(PMR_NO_KEY);
        fine_shade_chunk(in, mtas, &cache, light, best_mta + FINE_SLOT(r, 0),
                         best_cover + (NS > 1 ? FINE_SLOT(r, 0) : 0), won, 0, 0, x0 + c * VW, y0 + ly, view,
                         colour + r * VW);
      }
}

/* With a transmission source, whether no 3D tile of screen tile tile_xy holds glass: the opaque pass
 * then drew its voxels exactly as this pass would (the same core, the same MTAs). */
inline bool glass_free(global const PmrParams* P, global const PmrSource* S, global const uint* source_tiles,
                       uint tile_xy) {
  if (S->levels == 0u) return false;
  for (int tv = 0; tv < P->tiles_v; ++tv)
    if (source_tiles[((uint)tv * (uint)P->tiles_y) * (uint)P->tiles_x + tile_xy] != 0u) return false;
  return true;
}

/* The tile's voxels from the transmission source's level 0, in colour[]'s order. */
inline void fused_source_colours(global const half* source, global const PmrParams* P, int x0, int y0, int nx, int ny,
                                 ushort4* colour) {
  const size_t W = (size_t)P->view_w, H = (size_t)P->view_h;
  for (int view = 0; view < P->views; ++view)
    for (int ly = 0; ly < ny; ++ly) {
      const size_t row = ((size_t)view * H + (size_t)(y0 + ly)) * W + (size_t)x0;
      for (int lx = 0; lx < nx; ++lx)
        colour[view * FUSED_VIEW_STRIDE + ly * FUSED_ROW_STRIDE + lx] =
            vload4(row + (size_t)lx, (global const ushort*)source);
    }
}

kernel void fine_encode(PMR_SHADE_PARAMS, global const PmrMta* mtas, global const uint* tile_offsets,
                        global const uint* tile_queue, global const PmrEncodeParams* E, global const int* column_soa,
                        global const PmrEncodeRow* rows, global const int* column_start, global const int* row_start,
                        global half* display, global ushort* sub_alpha) {
  const uint tile_xy = pmr_item_id();
  const uint tiles_x = (uint)P->tiles_x, tiles_y = (uint)P->tiles_y;
  if (tile_xy >= tiles_x * tiles_y) return;
  const int x0 = (int)(tile_xy % tiles_x) * PMR_TILE_X, y0 = (int)(tile_xy / tiles_x) * PMR_TILE_Y;
  const int nx = min(PMR_TILE_X, P->view_w - x0), ny = min(PMR_TILE_Y, P->view_h - y0);
  ShadeInputs in = PMR_SHADE_INPUTS;
  ushort4 colour[FUSED_ROWS * VW];
  if (glass_free(P, source_info, source_tiles, tile_xy)) fused_source_colours(source, P, x0, y0, nx, ny, colour);
  else fused_raster_shade(&in, mtas, tile_offsets, tile_queue, tile_xy, x0, y0, nx, ny, colour);

  /* the display pixels this tile owns, whole or in part */
  const DisplayOut D = {(global ushort*)display, sub_alpha, E->display_w};
  const FusedTile T = {colour, column_soa, E->display_w, P->views, E->reversed, x0};
  const int s_lo = column_start[x0], s_hi = column_start[x0 + nx];
  const int i_lo = row_start[y0], i_hi = row_start[y0 + ny];
  for (int i = i_lo; i < i_hi; ++i) {
    const PmrEncodeRow row = rows[i];
    fused_display_row(&D, &T, &row, i, row.py - y0, s_lo, s_hi);
  }
}
