/* Stage 4 with --sampling subpixel: every display subpixel rasterized at its own sample in its own view
 * (DESIGN section 5's sample position, in the view the encoder maps it to), shaded, and written straight
 * into the display image. No view volume.
 *
 * One work-item per sample chunk (PmrSampleChunk): a block of display subpixels whose samples all lie in
 * one screen tile, so the tile queues the tile raster built (with PMR_SAMPLES_PIXEL: whole-pixel boxes)
 * hold every MTA that can cover them. The chunk first sorts its samples by view (a counting sort; each
 * view's run padded to whole vectors), then walks the tile's queues: per MTA and view, the run of that
 * view's samples is tested SP_LANES at a time.
 *
 * Why the double-precision edge test is exact. Relative to the chunk's first sample (Xc, Yc), a sample
 * is (Xc + x, Yc + y) with 0 <= x < 2^22 (a tile is at most 64 px wide, 16.16) and 0 <= y < 2^14
 * (24.8). The exact test sign * E(X, Y, v) >= bias becomes
 *   (sign dy) x - (sign dx_ab(v)) y >= bias - sign * E(Xc, Yc, v) = T
 * with |dy| < 2^24 and |dx_ab| < 2^32 (the guard band), so both products are integers below 2^46 and
 * their difference below 2^47: every double operation on the left is exact, and T, clamped to
 * +-2^48 (beyond which the comparison cannot change), converts exactly. So the outcome is the integer
 * one, bit for bit, in vectors of SP_LANES doubles.
 *
 * Depth at a sample: the one depth formula of every path (DepthPlane in cl/common.h), a function of the
 * MTA, the view and the sample alone, so the result does not depend on chunks, tiles or threads.
 * Visibility is the (depth, key) order as everywhere. */
#include "fine_core.h"

#define SP_LANES PMR_SUBPIXEL_LANES
#define SP_SLOTS PMR_SUBPIXEL_SLOTS /* the host keeps area + (SP_LANES - 1) * min(views, area) within */

/* A chunk's samples sorted by view: run v holds count[v] samples from first[v], padded to whole vectors
 * of SP_LANES; per sample its offset from the chunk's first sample (Xc, Yc) (fixed point), its index
 * n = (i - i0) * width + (s - s0) in the chunk and its channel k (s = 3 j + k); per vector its bounding
 * box (x0, x1, y0, y1); and the visibility state per sample (best_mta is read only where best_key says
 * drawn). */
typedef struct {
  long Xc, Yc, Xl, Yl; /* the chunk's first and last sample */
  int first[PMR_SUBPIXEL_VIEWS + 1], count[PMR_SUBPIXEL_VIEWS];
  int sx[SP_SLOTS], sy[SP_SLOTS];
  ushort sid[SP_SLOTS];
  uchar channel[SP_SLOTS];
  int4 box[SP_SLOTS / SP_LANES];
  float best_depth[SP_SLOTS];
  uint best_key[SP_SLOTS], best_mta[SP_SLOTS];
} SpChunk;

/* The view of each of the chunk's samples, by sample index n (row by row), eight columns at a time from
 * the column table's planes (a_mod_n, b); each row's last vector may run past the chunk, into lanes the
 * next row overwrites. */
inline void sp_sample_views(global const PmrEncodeParams* E, global const int* column_a, global const int* column_b,
                            global const PmrEncodeRow* rows, const PmrSampleChunk* ch, int views, ushort* view_of) {
  const int width = ch->s1 - ch->s0;
  for (int i = ch->i0, n = 0; i < ch->i1; ++i) {
    const size_t block =
        (size_t)(E->cell_rows > 1 ? (E->display_h - 1 - i) % E->cell_rows : 0) * (size_t)(3 * E->display_w);
    const PmrEncodeRow row = rows[i];
    for (int s = ch->s0; s < ch->s1; s += 8, n += 8) {
      const int8 a = vload8(0, column_a + block + s), b = vload8(0, column_b + block + s);
      vstore8(convert_ushort8(encode_view8(views, E->reversed, a, b, &row)), 0, view_of + n);
    }
    n -= (8 - width % 8) % 8;
  }
}

/* Step 1: the chunk's samples by view (a counting sort), with a clear visibility state. */
inline void sp_sort_samples(global const PmrEncodeParams* E, global const int* column_a, global const int* column_b,
                            global const PmrEncodeRow* rows, global const int* sample_x, global const int* sample_y,
                            const PmrSampleChunk* ch, int views, SpChunk* C) {
  const int width = ch->s1 - ch->s0;
  C->Xc = sample_x[ch->s0], C->Yc = sample_y[ch->i0], C->Xl = sample_x[ch->s1 - 1], C->Yl = sample_y[ch->i1 - 1];
  ushort view_of[PMR_SUBPIXEL_CAP + 8];
  sp_sample_views(E, column_a, column_b, rows, ch, views, view_of);
  for (int v = 0; v < views; ++v) C->count[v] = 0;
  for (int n = 0; n < width * (ch->i1 - ch->i0); ++n) ++C->count[view_of[n]];
  int run = 0;
  for (int v = 0; v < views; ++v) {
    C->first[v] = run;
    run += (C->count[v] + SP_LANES - 1) / SP_LANES * SP_LANES;
  }
  C->first[views] = run;
  for (int k = 0; k < run; k += 8) {
    vstore8((float8)(INFINITY), 0, C->best_depth + k);
    vstore8((uint8)(PMR_NO_KEY), 0, C->best_key + k);
    vstore8((int8)(0), 0, C->sx + k); /* padding lanes: any value, masked by the run's length */
    vstore8((int8)(0), 0, C->sy + k);
  }
  int fill[PMR_SUBPIXEL_VIEWS];
  for (int v = 0; v < views; ++v) fill[v] = C->first[v];
  /* column by column: a vector's samples then lie close together in x (all rows of a few columns),
   * which the bounding boxes exploit */
  for (int s = ch->s0; s < ch->s1; ++s) {
    const int x = (int)(sample_x[s] - C->Xc);
    const uchar c = (uchar)(s % 3);
    for (int i = ch->i0, n = s - ch->s0; i < ch->i1; ++i, n += width) {
      const int k = fill[view_of[n]]++;
      C->sx[k] = x;
      C->sy[k] = (int)(sample_y[i] - C->Yc);
      C->sid[k] = (ushort)n;
      C->channel[k] = c;
    }
  }
}

/* Each vector's bounding box: an MTA skips the vectors it cannot reach; x0 and x1 do not decrease along a
 * run. */
inline void sp_boxes(int views, SpChunk* C) {
  const int8 lane = vload8(0, lane_index);
  for (int v = 0; v < views; ++v)
    for (int k = C->first[v]; k < C->first[v] + C->count[v]; k += SP_LANES) {
      const int8 valid = lane < (int8)(C->first[v] + C->count[v] - k); /* padding lanes repeat lane 0 */
      const int8 x = select((int8)(C->sx[k]), vload8(0, C->sx + k), valid);
      const int8 y = select((int8)(C->sy[k]), vload8(0, C->sy + k), valid);
      const int4 x0 = min(x.lo, x.hi), x1 = max(x.lo, x.hi), y0 = min(y.lo, y.hi), y1 = max(y.lo, y.hi);
      const int2 a = min(x0.lo, x0.hi), b = max(x1.lo, x1.hi), c = min(y0.lo, y0.hi), d = max(y1.lo, y1.hi);
      C->box[k / SP_LANES] = (int4)(min(a.x, a.y), max(b.x, b.y), min(c.x, c.y), max(d.x, d.y));
    }
}

/* An MTA's edges relative to the chunk's first sample (see the head of this file): per edge sign * dy,
 * and bias - sign * E(Xc, Yc, v) and -sign * dx_ab(v) at view coordinate f_lo with their exact
 * increments per unit of view coordinate (both are linear in it); and the MTA's y extent relative to
 * Yc. */
typedef struct {
  long f_lo, t_lo[3], dt[3], dx_lo[3], ddx[3];
  double dy[3];
  long my0, my1;
} SpEdges;

PMR_HOT void sp_edges(global const PmrParams* P, const PmrMta* m, int i_lo, const SpChunk* C, SpEdges* S) {
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  const long f_first = view_coord(P, m->view_lo);
  S->f_lo = view_coord(P, i_lo);
  for (int e = 0; e < 3; ++e) {
    const int a = ea[e], b = eb[e];
    const long sg = m->sign, d_y = (long)(m->y[b] - m->y[a]), d_dx = (long)m->dx[b] - (long)m->dx[a];
    S->t_lo[e] = mta_edge_bias(m, a, b, f_first) - sg * mta_edge(m, a, b, C->Xc, C->Yc, S->f_lo);
    S->dt[e] = sg * (d_y * (long)m->dx[a] + d_dx * (C->Yc - (long)m->y[a]));
    S->dx_lo[e] = -sg * ((long)m->x0[b] - (long)m->x0[a] + S->f_lo * d_dx);
    S->ddx[e] = -sg * d_dx;
    S->dy[e] = (double)(sg * d_y);
  }
  S->my0 = min(m->y[0], min(m->y[1], m->y[2])) - C->Yc;
  S->my1 = max(m->y[0], max(m->y[1], m->y[2])) - C->Yc;
}

/* The depth plane of an MTA in view fv (depth_plane, cl/common.h) at samples (Xc + x, Yc + y): the one
 * depth formula, in vectors. The offsets from the plane's anchor are integers below 2^53, exact in
 * double, and their scaling by a power of two is exact, so each lane's value is the formula's. The
 * column offsets mostly fit 32 bits (x < 2^22): then they are summed as integers, which round to float
 * as the doubles would. */
PMR_HOT float8 sp_depth(const DepthPlane* d, const SpChunk* C, double8 x, int8 xi, double8 y) {
  const double8 rows = ((double8)((double)(C->Yc - ((long)d->qr * PMR_Y_ONE + PMR_HALF_Y))) + y) / (double)PMR_Y_ONE;
  const long bx = C->Xc - ((long)d->pr * PMR_X_ONE + PMR_HALF_X);
  const float8 columns = (bx > -(1L << 30) && bx < (1L << 30) ? convert_float8((int8)((int)bx) + xi)
                                                              : convert_float8((double8)((double)bx) + x)) /
                         (float)PMR_X_ONE;
  return convert_float8((double8)(d->zr) + (double8)(d->gy) * rows) + (float8)(d->gx) * columns;
}

/* MTA m (queue entry id) in view v against the view's run of samples, SP_LANES at a time, into the
 * visibility state. */
PMR_HOT void sp_raster_view(const ShadeInputs* in, const PmrMta* m, uint id, const SpEdges* S, int v, float cutoff,
                            SpChunk* C) {
  const int k0 = C->first[v], k1 = k0 + C->count[v];
  if (k0 == k1) return;
  long xv[3];
  const long fv = view_coord(in->P, v);
  for (int k = 0; k < 3; ++k) xv[k] = (long)m->x0[k] + fv * (long)m->dx[k];
  const long mx0 = min(xv[0], min(xv[1], xv[2])) - C->Xc, mx1 = max(xv[0], max(xv[1], xv[2])) - C->Xc;
  double dx[3], T[3];
  const long di = fv - S->f_lo;
  for (int e = 0; e < 3; ++e) {
    T[e] = (double)clamp(S->t_lo[e] + di * S->dt[e], -(1L << 48), 1L << 48);
    dx[e] = (double)(S->dx_lo[e] + di * S->ddx[e]);
  }
  const double8 lane_d = convert_double8(vload8(0, lane_index));
  bool have_plane = false;
  DepthPlane p;
  for (int k = k0; k < k1; k += SP_LANES) {
    const int4 b = C->box[k / SP_LANES];
    if (b.x > mx1) break; /* a run's vectors go left to right (sorted by column) */
    if (b.y < mx0 || b.w < S->my0 || b.z > S->my1) continue;
    const int8 xi = vload8(0, C->sx + k);
    const double8 x = convert_double8(xi), y = convert_double8(vload8(0, C->sy + k));
    long8 hit = ((double8)(S->dy[0]) * x + (double8)(dx[0]) * y >= (double8)(T[0])) &
                ((double8)(S->dy[1]) * x + (double8)(dx[1]) * y >= (double8)(T[1])) &
                ((double8)(S->dy[2]) * x + (double8)(dx[2]) * y >= (double8)(T[2]));
    if (k1 - k < SP_LANES) hit &= lane_d < (double8)(k1 - k); /* the run's padding */
    /* any(hit) as an OR of the lanes (a true lane is -1): any() on long8 compiles to a slow sequence of
     * branches here */
    const long4 h4 = hit.lo | hit.hi;
    const long2 h2 = h4.lo | h4.hi;
    if ((h2.x | h2.y) == 0) continue;
    if (!have_plane) p = depth_plane(m, fv), have_plane = true; /* tiny MTAs often cover no sample */
    const float8 z = sp_depth(&p, C, x, xi, y);
    const float8 bd = vload8(0, C->best_depth + k);
    const uint8 bk = vload8(0, C->best_key + k);
    int8 win = convert_int8(hit) & ((z < bd) | ((z == bd) & ((uint8)(m->key) < bk)));
    if ((m->flags & PMR_MTA_MASK) && any(win)) {
      int w[SP_LANES];
      vstore8(win, 0, w);
      const SampleLanes L = offset_samples(C->Xc, C->Yc, C->sx + k, C->sy + k);
      mask_alpha_lanes(in, m, w, SP_LANES, &L, v, cutoff);
      win = vload8(0, w);
    }
    vstore8(select(bd, z, win), 0, C->best_depth + k);
    vstore8(select(bk, (uint8)(m->key), as_uint8(win)), 0, C->best_key + k);
    vstore8(select(vload8(0, C->best_mta + k), (uint8)(id), as_uint8(win)), 0, C->best_mta + k);
  }
}

/* Step 2, visibility: the queues of the chunk's screen tile, every view slab; per MTA the views whose
 * x extent can reach the chunk's samples. */
inline void sp_visibility(const ShadeInputs* in, global const PmrMta* mtas, global const uint* tile_offsets,
                          global const uint* tile_queue, int tile_xy, SpChunk* C) {
  global const PmrParams* P = in->P;
  const int views = P->views;
  for (int tv = 0; tv < P->tiles_v; ++tv) {
    const int v0 = tv * PMR_TILE_V, v1 = min(views, v0 + PMR_TILE_V) - 1;
    if (C->first[v1 + 1] == C->first[v0]) continue; /* no sample of the chunk shows these views */
    const uint tile = ((uint)tv * (uint)P->tiles_y) * (uint)P->tiles_x + (uint)tile_xy;
    const uint q1 = tile_offsets[tile + 1];
    for (uint q = tile_offsets[tile]; q < q1; ++q) {
      const uint id = tile_queue[q];
      const PmrMta m = mtas[id];
      const long ylo = min(m.y[0], min(m.y[1], m.y[2])), yhi = max(m.y[0], max(m.y[1], m.y[2]));
      if (yhi < C->Yc || ylo > C->Yl) continue;
      const int i_lo = max(v0, m.view_lo), i_hi = min(v1, m.view_hi);
      const float cutoff = (m.flags & PMR_MTA_MASK) ? in->materials[in->tris[m.tri].material].alpha_cutoff : 0.0f;
      SpEdges S;
      sp_edges(P, &m, i_lo, C, &S);
      for (int ib = i_lo; ib <= i_hi; ib += 16) {
        uint pass = view_pass_mask(P, &m, ib, min(i_hi - ib + 1, 16), C->Xc, 0, C->Xl - C->Xc);
        while (pass != 0) { /* the passing views, lowest first */
          const int v = ib + (31 - (int)clz(pass & (0u - pass)));
          pass &= pass - 1u;
          sp_raster_view(in, &m, id, &S, v, cutoff, C);
        }
      }
    }
  }
}

/* Step 3, the winners shaded at their samples, SW samples of a view at a time, one per lane: channel k
 * of subpixel s = 3 j + k as half bits into value[n] and covered[n] (0: background), by sample index. */
inline void sp_shade(const ShadeInputs* in, global const PmrMta* mtas, const SpChunk* C, ushort* value,
                     uchar* covered) {
  global const PmrParams* P = in->P;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  for (int v = 0; v < P->views; ++v)
    for (int k0 = C->first[v]; k0 < C->first[v] + C->count[v]; k0 += SW) {
      const int kn = min(SW, C->first[v] + C->count[v] - k0);
      int todo[SW], ids[SW];
      for (int l = 0; l < SW; ++l) {
        const int k = k0 + l;
        todo[l] = l < kn && C->best_key[k] != PMR_NO_KEY ? -1 : 0;
        ids[l] = todo[l] ? (int)C->best_mta[k] : 0;
        if (l < kn && !todo[l]) value[C->sid[k]] = 0, covered[C->sid[k]] = 0;
      }
      const sint act = vload_s(0, todo);
      if (!any(act)) continue;
      const SampleLanes S = offset_samples(C->Xc, C->Yc, C->sx + k0, C->sy + k0);
      LaneWinners L;
      lanes_gather(in, mtas, &cache, act, vload_s(0, ids), &S, v, &L);
      float c[3][SW];
      s3_store(shade_lanes(in, &L, light, v), c[0], c[1], c[2]);
      for (int l = 0; l < kn; ++l) {
        if (!todo[l]) continue;
        const int k = k0 + l, n = C->sid[k];
        ushort h;
        vstore_half(c[C->channel[k]][l], 0, (half*)&h);
        value[n] = h;
        covered[n] = 1;
      }
    }
}

/* The debug outputs: each sample's winning key and depth, at its subpixel (display row i, column s). */
inline void sp_write_debug(const PmrSampleChunk* ch, int views, int display_w, const SpChunk* C, global uint* dbg_key,
                           global float* dbg_depth) {
  const int width = ch->s1 - ch->s0;
  for (int v = 0; v < views; ++v)
    for (int k = C->first[v]; k < C->first[v] + C->count[v]; ++k) {
      const int n = C->sid[k];
      const size_t at = (size_t)(ch->i0 + n / width) * (size_t)(3 * display_w) + (size_t)(ch->s0 + n % width);
      dbg_key[at] = C->best_key[k];
      dbg_depth[at] = C->best_depth[k];
    }
}

/* Step 4, the chunk's display pixels (write_display_pixel): a sample's half RGBA bits are its value in
 * every channel (the pixel takes channel k from subpixel k) and its coverage as alpha. */
inline void sp_write_display(const DisplayOut* D, const PmrSampleChunk* ch, const ushort* value, const uchar* covered) {
  const ushort one = 0x3c00; /* 1.0 as a half */
  const int width = ch->s1 - ch->s0;
  for (int i = ch->i0; i < ch->i1; ++i) {
    const int r = (i - ch->i0) * width - ch->s0; /* sample index of subpixel s: r + s */
    for (int j = ch->s0 / 3; 3 * j < ch->s1; ++j) {
      ushort4 s[3];
      for (int k = 0; k < 3; ++k) {
        const int n = r + 3 * j + k;
        const bool own = 3 * j + k >= ch->s0 && 3 * j + k < ch->s1;
        s[k] = own ? (ushort4)(value[n], value[n], value[n], covered[n] ? one : 0) : (ushort4)(0);
      }
      write_display_pixel(D, i, j, ch->s0, ch->s1, s[0], s[1], s[2]);
    }
  }
}

kernel void fine_subpixel(PMR_SHADE_PARAMS, global const PmrMta* mtas, global const uint* tile_offsets,
                          global const uint* tile_queue, global const PmrEncodeParams* E, global const int* column_a,
                          global const int* column_b, global const PmrEncodeRow* rows, global const int* sample_x,
                          global const int* sample_y, global const PmrSampleChunk* chunks, uint num_chunks,
                          global half* display, global ushort* sub_alpha, uint debug, global uint* dbg_key,
                          global float* dbg_depth) {
  const uint chunk = pmr_item_id();
  if (chunk >= num_chunks) return;
  const PmrSampleChunk ch = chunks[chunk];
  SpChunk C;
  sp_sort_samples(E, column_a, column_b, rows, sample_x, sample_y, &ch, P->views, &C);
  sp_boxes(P->views, &C);
  ShadeInputs in = PMR_SHADE_INPUTS;
  sp_visibility(&in, mtas, tile_offsets, tile_queue, ch.tile, &C);
  if (debug) sp_write_debug(&ch, P->views, E->display_w, &C, dbg_key, dbg_depth);
  ushort value[PMR_SUBPIXEL_CAP];
  uchar covered[PMR_SUBPIXEL_CAP];
  sp_shade(&in, mtas, &C, value, covered);
  const DisplayOut D = {(global ushort*)display, sub_alpha, E->display_w};
  sp_write_display(&D, &ch, value, covered);
}
