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
 * With S samples per pixel (DESIGN section 3b) a subpixel is S samples around its own: the pattern
 * scaled to a display pixel's footprint in the view (P->sample_x/y, set so by the host), consecutive in
 * its view's run. Each sample has its own winner; the subpixel shades each distinct winner once, at its
 * shading point, and takes the box mean. The tile raster binned each pixel with its samples' box
 * (PMR_SAMPLES_PIXEL), so the tile's queues hold every MTA that can cover a sample that spills over
 * into a neighbouring tile.
 *
 * Why the double-precision edge test is exact. Relative to the chunk's first sample (Xc, Yc), a sample
 * is (Xc + x, Yc + y) with |x| < 2^22 (a tile is at most 64 px wide, 16.16; samples spill at
 * most half a display pixel) and |y| < 2^14 (24.8). The exact test sign * E(X, Y, v) >= bias becomes
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
#define SP_SLOTS PMR_SUBPIXEL_SLOTS /* the host keeps NS area + (SP_LANES - 1) min(views, area) within */
#define NS PMR_SAMPLES

/* A chunk's samples sorted by view: run v holds count[v] samples from first[v] (each subpixel's NS
 * consecutively, sample s of it at first[v] + NS j + s), padded to whole vectors of SP_LANES; per
 * sample its offset from the chunk's first subpixel's sample (Xc, Yc) (fixed point), its subpixel's
 * index n = (i - i0) * width + (s - s0) in the chunk and channel k (s = 3 j + k); per vector its
 * bounding box (x0, x1, y0, y1); and the visibility state per sample (best_mta is read only where
 * best_key says drawn). */
typedef struct {
  long Xc, Yc, Xl, Yl;    /* the chunk's first and last subpixel's own sample */
  int ox0, ox1, oy0, oy1; /* the box of the sample offsets around it */
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
inline void sp_sort_samples(global const PmrParams* P, global const PmrEncodeParams* E, global const int* column_a,
                            global const int* column_b, global const PmrEncodeRow* rows, global const int* sample_x,
                            global const int* sample_y, const PmrSampleChunk* ch, SpChunk* C) {
  const int width = ch->s1 - ch->s0, views = P->views;
  C->Xc = sample_x[ch->s0], C->Yc = sample_y[ch->i0], C->Xl = sample_x[ch->s1 - 1], C->Yl = sample_y[ch->i1 - 1];
  C->ox0 = C->ox1 = C->oy0 = C->oy1 = 0;
  for (int s = 0; s < NS; ++s) {
    C->ox0 = min(C->ox0, P->sample_x[s]), C->ox1 = max(C->ox1, P->sample_x[s]);
    C->oy0 = min(C->oy0, P->sample_y[s]), C->oy1 = max(C->oy1, P->sample_y[s]);
  }
  ushort view_of[PMR_SUBPIXEL_CAP + 8];
  sp_sample_views(E, column_a, column_b, rows, ch, views, view_of);
  for (int v = 0; v < views; ++v) C->count[v] = 0;
  for (int n = 0; n < width * (ch->i1 - ch->i0); ++n) C->count[view_of[n]] += NS;
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
    for (int i = ch->i0, n = s - ch->s0; i < ch->i1; ++i, n += width)
      for (int t = 0; t < NS; ++t) {
        const int k = fill[view_of[n]]++;
        C->sx[k] = x + P->sample_x[t];
        C->sy[k] = (int)(sample_y[i] - C->Yc) + P->sample_y[t];
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

/* A subpixel's shading point for MTA m, as an offset from the chunk's first sample: its own sample
 * (vector slot j of the run, offsets sx, sy) where m covers that, else the centroid of the subpixel's
 * samples m covers (shading_point); one sample: the sample itself. */
inline void sp_shading_point(global const PmrParams* P, const PmrMta* m, int j, int v, int sx, int sy, const SpChunk* C,
                             int* ox, int* oy) {
  *ox = sx, *oy = sy;
  if (NS == 1) return;
  const int t = j % NS; /* the lane's sample of its subpixel */
  const long X = C->Xc + sx - P->sample_x[t], Y = C->Yc + sy - P->sample_y[t];
  bool center;
  const uint bits = mta_sample_cover(P, m, X, Y, view_coord(P, v), &center);
  int dx, dy;
  shading_point(P, center, bits, &dx, &dy);
  *ox = (int)(X - C->Xc) + dx, *oy = (int)(Y - C->Yc) + dy;
}

/* alphaMode MASK for the winning lanes `win` of a vector (its first sample the run's j-th, at offsets
 * sx, sy): tested at each lane's sample, or with several samples once per subpixel at its shading point
 * (shading_point around the subpixel's own sample), so that a failure leaves all its samples. */
inline int8 sp_mask(const ShadeInputs* in, const PmrMta* m, int8 win, int j, int v, float cutoff, const int* sx,
                    const int* sy, const SpChunk* C) {
  int w[SP_LANES], ox[SP_LANES], oy[SP_LANES];
  vstore8(win, 0, w);
  for (int l = 0; l < SP_LANES; ++l) {
    ox[l] = sx[l], oy[l] = sy[l];
    if (NS > 1 && w[l]) sp_shading_point(in->P, m, j + l, v, sx[l], sy[l], C, ox + l, oy + l);
  }
  const SampleLanes L = offset_samples(C->Xc, C->Yc, ox, oy);
  mask_alpha_lanes(in, m, w, SP_LANES, &L, v, cutoff);
  return vload8(0, w);
}

/* What a walk of the queues takes (blend.h's scheme, per sample of the chunk): every MTA but those with
 * flags `skip` and without `need`; for a BLEND layer only fragments after (after_depth, after_key) and
 * not behind `limit`, `found` set where one wins, and with `rest` every such fragment accumulated there
 * (sp_rest_add) instead of competing. `blend` is set when a BLEND MTA is left out. */
typedef struct {
  long* ca; /* a c of the subpixel's channel (REST_COLOUR_ONE) */
  long* a;  /* a and -ln(1 - a) (REST_ALPHA_ONE) */
  long* ln;
} SpRest;

typedef struct {
  uint skip, need;
  uint* blend;
  const float* after_depth;
  const uint* after_key;
  const float* limit;
  uint* found;
  SpRest* rest;
} SpWalk;

/* The rest beyond the exact BLEND layers (blend.h): MTA m (queue entry id) shaded at the shading points
 * of the samples `win` of a vector (slots k.., the run's j-th on, view v) and added to their sums. */
inline void sp_rest_add(const ShadeInputs* in, const PmrMta* m, uint id, int8 win, int k, int j, int v,
                        const SpChunk* C, SpRest* R) {
  int w[SP_LANES], sx[SW], sy[SW];
  vstore8(win, 0, w);
  for (int l = 0; l < SW; ++l) {
    sx[l] = sy[l] = 0;
    if (w[l]) sp_shading_point(in->P, m, j + l, v, C->sx[k + l], C->sy[k + l], C, sx + l, sy + l);
  }
  MtaCache one; /* the shading's MTA cache, holding m */
  one.id = id, one.m = *m;
  global const PmrParams* P = in->P;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  const SampleLanes S = offset_samples(C->Xc, C->Yc, sx, sy);
  float c[4][SW];
  shade_sample_lanes(in, 0, &one, light, vload8(0, w) != 0, (sint)((int)id), &S, v, c);
  for (int l = 0; l < SP_LANES; ++l) {
    if (!w[l]) continue;
    const float a = c[3][l];
    R->ca[k + l] += convert_long_rte(c[C->channel[k + l]][l] * a * REST_COLOUR_ONE);
    R->a[k + l] += convert_long_rte(a * REST_ALPHA_ONE);
    R->ln[k + l] += convert_long_rte(REST_LN(a) * REST_ALPHA_ONE);
  }
}

/* MTA m (queue entry id) in view v against the view's run of samples, SP_LANES at a time, into the
 * visibility state. */
PMR_HOT void sp_raster_view(const ShadeInputs* in, const PmrMta* m, uint id, const SpEdges* S, int v, float cutoff,
                            const SpWalk* W, SpChunk* C) {
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
    /* a run's subpixels go left to right (sorted by column): no later vector has a sample left of this
     * one's first subpixel plus the leftmost offset */
    if (C->sx[k] - in->P->sample_x[(k - k0) % NS] + C->ox0 > mx1) break;
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
    int8 win = convert_int8(hit);
    if (W->after_depth) {
      const float8 ad = vload8(0, W->after_depth + k);
      win &=
          ((z > ad) | ((z == ad) & ((uint8)(m->key) > vload8(0, W->after_key + k)))) & (z <= vload8(0, W->limit + k));
    }
    if (!W->rest) win &= (z < bd) | ((z == bd) & ((uint8)(m->key) < bk));
    if ((m->flags & PMR_MTA_MASK) && any(win)) win = sp_mask(in, m, win, k - k0, v, cutoff, C->sx + k, C->sy + k, C);
    if (W->found && any(win)) *W->found = 1u;
    if (W->rest) {
      if (any(win)) sp_rest_add(in, m, id, win, k, k - k0, v, C, W->rest);
      continue;
    }
    vstore8(select(bd, z, win), 0, C->best_depth + k);
    vstore8(select(bk, (uint8)(m->key), as_uint8(win)), 0, C->best_key + k);
    vstore8(select(vload8(0, C->best_mta + k), (uint8)(id), as_uint8(win)), 0, C->best_mta + k);
  }
}

/* Step 2, visibility: the queues of the chunk's screen tile, every view slab; per MTA the views whose
 * x extent can reach the chunk's samples. */
inline void sp_visibility(const ShadeInputs* in, global const PmrMta* mtas, global const uint* tile_offsets,
                          global const uint* tile_queue, int tile_xy, const SpWalk* W, SpChunk* C) {
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
      if (m.flags & W->skip) {
        if (W->blend && (m.flags & PMR_MTA_BLEND)) *W->blend = 1u;
        continue;
      }
      if ((m.flags & W->need) != W->need) continue;
      const long ylo = min(m.y[0], min(m.y[1], m.y[2])), yhi = max(m.y[0], max(m.y[1], m.y[2]));
      if (yhi < C->Yc + C->oy0 || ylo > C->Yl + C->oy1) continue;
      const int i_lo = max(v0, m.view_lo), i_hi = min(v1, m.view_hi);
      const float cutoff = (m.flags & PMR_MTA_MASK) ? in->materials[in->tris[m.tri].material].alpha_cutoff : 0.0f;
      SpEdges S;
      sp_edges(P, &m, i_lo, C, &S);
      for (int ib = i_lo; ib <= i_hi; ib += 16) {
        uint pass =
            view_pass_mask(P, &m, ib, min(i_hi - ib + 1, 16), C->Xc + C->ox0, 0, C->Xl + C->ox1 - C->Xc - C->ox0);
        while (pass != 0) { /* the passing views, lowest first */
          const int v = ib + (31 - (int)clz(pass & (0u - pass)));
          pass &= pass - 1u;
          sp_raster_view(in, &m, id, &S, v, cutoff, W, C);
        }
      }
    }
  }
}

/* Shading points of one view waiting for a vector of SW lanes: per lane the winning MTA, the point as
 * an offset from (Xc, Yc), the subpixel (sid, channel) it adds `weight` of its colour to, and the slot of
 * the subpixel's first sample. */
typedef struct {
  int n;
  int ids[SW], sx[SW], sy[SW], sid[SW], channel[SW], slot[SW];
  float weight[SW];
} SpBatch;

/* Shades a batch's points and adds them into their subpixels' premultiplied colour and coverage, with
 * their opacity (1 but for BLEND); with one sample and no layers each subpixel gets exactly its winner's
 * colour (0 + 1 x 1 x c). For a BLEND layer (T not null) the samples each point's winner won then see
 * T (1 - a) behind it. */
inline void sp_flush(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light, int v,
                     const SpChunk* C, SpBatch* B, float* T, float* acc, float* alpha) {
  if (B->n == 0) return;
  float c[4][SW];
  shade_packed_lanes(in, mtas, cache, light, C->Xc, C->Yc, v, B->n, B->ids, B->sx, B->sy, c);
  for (int l = 0; l < B->n; ++l) {
    const float wa = B->weight[l] * c[3][l];
    acc[B->sid[l]] += wa * c[B->channel[l]][l];
    alpha[B->sid[l]] += wa;
    for (int t = 0; t < NS && T; ++t) {
      const int k = B->slot[l] + t;
      if (C->best_key[k] != PMR_NO_KEY && C->best_mta[k] == (uint)B->ids[l]) T[k] *= 1.0f - c[3][l];
    }
  }
  B->n = 0;
}

/* The subpixel whose samples are slots k .. k + NS - 1: each distinct winner (first occurrence) into the
 * batch at its shading point, weighted by its share of the samples (times their transmittance T through
 * the BLEND layers in front, where given). A winner of all NS samples covers the subpixel's own sample,
 * inside the samples' convex hull (as in shade_point_lanes); others are tested. */
inline void sp_queue_subpixel(const ShadeInputs* in, global const PmrMta* mtas, MtaCache* cache, float3 light, int v,
                              int k, const SpChunk* C, SpBatch* B, float* T, bool layer, float* acc, float* alpha) {
  global const PmrParams* P = in->P;
  const int bx = C->sx[k] - P->sample_x[0], by = C->sy[k] - P->sample_y[0]; /* the subpixel's own sample */
  for (int s = 0; s < NS; ++s) {
    if (C->best_key[k + s] == PMR_NO_KEY) continue;
    const uint id = C->best_mta[k + s];
    bool first = true;
    int count = 0;
    float share = 0.0f;
    for (int t = 0; t < NS; ++t) {
      const bool same = C->best_key[k + t] != PMR_NO_KEY && C->best_mta[k + t] == id;
      first = first && !(same && t < s);
      count += same ? 1 : 0;
      if (same && T) share += T[k + t];
    }
    if (!first) continue;
    int ox = 0, oy = 0;
    if (count < NS) {
      bool center;
      const uint bits =
          mta_sample_cover(P, cached_mta(cache, mtas, id), C->Xc + bx, C->Yc + by, view_coord(P, v), &center);
      shading_point(P, center, bits, &ox, &oy);
    }
    const int l = B->n++;
    B->ids[l] = (int)id, B->sx[l] = bx + ox, B->sy[l] = by + oy, B->slot[l] = k;
    B->sid[l] = C->sid[k], B->channel[l] = C->channel[k];
    B->weight[l] = (T ? share : (float)count) / (float)NS;
    if (B->n == SW) sp_flush(in, mtas, cache, light, v, C, B, layer ? T : 0, acc, alpha);
  }
}

/* Step 3, the winners shaded and resolved (DESIGN section 3b): channel k of subpixel s = 3 j + k as the
 * box mean of its samples' premultiplied colours added into acc[n], its covered fraction into alpha[n].
 * T: the samples' transmittance through the BLEND layers in front (null: none); `layer`: the winners are
 * a BLEND layer's, which multiplies T by 1 - their opacity. */
inline void sp_shade(const ShadeInputs* in, global const PmrMta* mtas, const SpChunk* C, float* T, bool layer,
                     float* acc, float* alpha) {
  global const PmrParams* P = in->P;
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  SpBatch B;
  B.n = 0;
  for (int v = 0; v < P->views; ++v) {
    for (int k = C->first[v]; k < C->first[v] + C->count[v]; k += NS)
      sp_queue_subpixel(in, mtas, &cache, light, v, k, C, &B, T, layer, acc, alpha);
    sp_flush(in, mtas, &cache, light, v, C, &B, layer ? T : 0, acc, alpha);
  }
}

/* The debug outputs: each sample's winning key and depth, sample t of the subpixel at display row i,
 * column s at (i 3 W_d + s) NS + t. */
inline void sp_write_debug(const PmrSampleChunk* ch, int views, int display_w, const SpChunk* C, global uint* dbg_key,
                           global float* dbg_depth) {
  const int width = ch->s1 - ch->s0;
  for (int v = 0; v < views; ++v)
    for (int k = C->first[v]; k < C->first[v] + C->count[v]; ++k) {
      const int n = C->sid[k], t = (k - C->first[v]) % NS;
      const size_t at = ((size_t)(ch->i0 + n / width) * (size_t)(3 * display_w) + (size_t)(ch->s0 + n % width)) * NS;
      dbg_key[at + (size_t)t] = C->best_key[k];
      dbg_depth[at + (size_t)t] = C->best_depth[k];
    }
}

/* Step 4, the chunk's display pixels (write_display_pixel): a subpixel's premultiplied colour in every
 * channel (the pixel takes channel k from subpixel k) and its coverage as alpha, as half bits. */
inline void sp_write_display(const DisplayOut* D, const PmrSampleChunk* ch, const float* acc, const float* alpha) {
  const int width = ch->s1 - ch->s0;
  for (int i = ch->i0; i < ch->i1; ++i) {
    const int r = (i - ch->i0) * width - ch->s0; /* subpixel index of subpixel s: r + s */
    for (int j = ch->s0 / 3; 3 * j < ch->s1; ++j) {
      ushort4 s[3];
      for (int k = 0; k < 3; ++k) {
        const int n = r + 3 * j + k;
        const bool own = 3 * j + k >= ch->s0 && 3 * j + k < ch->s1;
        ushort4 h = (ushort4)(0);
        if (own) vstore_half4((float4)(acc[n], acc[n], acc[n], alpha[n]), 0, (half*)&h);
        s[k] = h;
      }
      write_display_pixel(D, i, j, ch->s0, ch->s1, s[0], s[1], s[2]);
    }
  }
}

/* The rest beyond the exact BLEND layers (after_depth, after_key) of the chunk's samples, one layer
 * behind them (DESIGN section 4c step 3, as blend_rest in blend.h), into acc, alpha and T. Returns the
 * number of samples with such fragments. */
inline uint sp_blend_rest(const ShadeInputs* in, global const PmrMta* mtas, global const uint* tile_offsets,
                          global const uint* tile_queue, int tile_xy, SpWalk* W, SpChunk* C, float* T, float* acc,
                          float* alpha) {
  const int run = C->first[in->P->views];
  long ca[SP_SLOTS], a[SP_SLOTS], ln[SP_SLOTS];
  for (int k = 0; k < run; ++k) ca[k] = a[k] = ln[k] = 0;
  SpRest R = {ca, a, ln};
  uint found = 0u;
  W->found = &found, W->rest = &R;
  sp_visibility(in, mtas, tile_offsets, tile_queue, tile_xy, W, C);
  uint samples = 0u;
  for (int k = 0; k < run && found; ++k) {
    if (a[k] <= 0) continue;
    const float A = REST_OPACITY((float)ln[k]);
    const float w = T[k] * A / (float)NS;
    acc[C->sid[k]] += w * ((float)ca[k] / REST_COLOUR_ONE) / ((float)a[k] / REST_ALPHA_ONE);
    alpha[C->sid[k]] += w;
    T[k] *= 1.0f - A;
    ++samples;
  }
  return samples;
}

/* alphaMode BLEND over a chunk whose opaque walk met BLEND MTAs, by depth peeling per sample (blend.h's
 * scheme): the layers composited into acc and alpha and the samples' transmittance T, with which sp_shade
 * then adds the opaque winners, restored into C. Returns the number of samples with more than
 * PMR_BLEND_LAYERS fragments. */
inline uint sp_blend(const ShadeInputs* in, global const PmrMta* mtas, global const uint* tile_offsets,
                     global const uint* tile_queue, int tile_xy, SpChunk* C, float* T, float* acc, float* alpha) {
  const int run = C->first[in->P->views];
  float limit[SP_SLOTS], after_depth[SP_SLOTS];
  uint opaque_key[SP_SLOTS], opaque_mta[SP_SLOTS], after_key[SP_SLOTS];
  for (int k = 0; k < run; ++k) {
    limit[k] = C->best_depth[k], opaque_key[k] = C->best_key[k], opaque_mta[k] = C->best_mta[k];
    T[k] = 1.0f, after_depth[k] = -INFINITY, after_key[k] = 0u;
  }
  uint found = 0u, beyond = 0u;
  SpWalk W = {0u, PMR_MTA_BLEND, 0, after_depth, after_key, limit, &found, 0};
  int layer = 0;
  for (; layer < PMR_BLEND_LAYERS; ++layer) {
    found = 0u;
    for (int k = 0; k < run; ++k) C->best_depth[k] = INFINITY, C->best_key[k] = PMR_NO_KEY;
    sp_visibility(in, mtas, tile_offsets, tile_queue, tile_xy, &W, C);
    if (!found) break;
    sp_shade(in, mtas, C, T, true, acc, alpha);
    for (int k = 0; k < run; ++k) after_depth[k] = C->best_depth[k], after_key[k] = C->best_key[k];
  }
  if (layer == PMR_BLEND_LAYERS)
    beyond = sp_blend_rest(in, mtas, tile_offsets, tile_queue, tile_xy, &W, C, T, acc, alpha);
  for (int k = 0; k < run; ++k)
    C->best_depth[k] = limit[k], C->best_key[k] = opaque_key[k], C->best_mta[k] = opaque_mta[k];
  return beyond;
}

kernel void fine_subpixel(PMR_SHADE_PARAMS, global const PmrMta* mtas, global const uint* tile_offsets,
                          global const uint* tile_queue, global const PmrEncodeParams* E, global const int* column_a,
                          global const int* column_b, global const PmrEncodeRow* rows, global const int* sample_x,
                          global const int* sample_y, global const PmrSampleChunk* chunks, uint num_chunks,
                          global half* display, global ushort* sub_alpha, uint debug, global uint* dbg_key,
                          global float* dbg_depth, global uint* blend_overflow) {
  const uint chunk = pmr_item_id();
  if (chunk >= num_chunks) return;
  const PmrSampleChunk ch = chunks[chunk];
  SpChunk C;
  sp_sort_samples(P, E, column_a, column_b, rows, sample_x, sample_y, &ch, &C);
  sp_boxes(P->views, &C);
  ShadeInputs in = PMR_SHADE_INPUTS;
  uint blend = 0u;
  const SpWalk opaque = {PMR_MTA_BLEND, 0u, &blend, 0, 0, 0, 0, 0}; /* BLEND comes after */
  sp_visibility(&in, mtas, tile_offsets, tile_queue, ch.tile, &opaque, &C);
  if (debug) sp_write_debug(&ch, P->views, E->display_w, &C, dbg_key, dbg_depth);
  float acc[PMR_SUBPIXEL_CAP], alpha[PMR_SUBPIXEL_CAP], T[SP_SLOTS];
  for (int n = 0; n < (ch.s1 - ch.s0) * (ch.i1 - ch.i0); ++n) acc[n] = alpha[n] = 0.0f;
  if (blend) {
    const uint beyond = sp_blend(&in, mtas, tile_offsets, tile_queue, ch.tile, &C, T, acc, alpha);
    if (beyond) atomic_add(blend_overflow, beyond);
  }
  sp_shade(&in, mtas, &C, blend ? T : 0, false, acc, alpha);
  const DisplayOut D = {(global ushort*)display, sub_alpha, E->display_w};
  sp_write_display(&D, &ch, acc, alpha);
}
