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
 * one, bit for bit, in 4-wide vector doubles.
 *
 * Depth at a sample: the plane through the MTA's three vertices in view v, in double and anchored at
 * vertex 0, z = (float)(z_0 + (g_x (X - x_0) + g_y (Y - y_0))): a function of the MTA, the view and the
 * sample alone, so the result does not depend on chunks, tiles or threads. Visibility is the (depth,
 * key) order as everywhere. */
#include "fine_core.h"

#define SP_LANES 8
#define SP_SLOTS PMR_SUBPIXEL_SLOTS /* the host keeps area + (SP_LANES - 1) * min(views, area) within */

kernel void fine_subpixel(global const PmrParams* P, global const PmrMta* mtas, global const uint* tile_offsets,
                          global const uint* tile_queue, global const PmrTriangle* tris,
                          global const PmrVertexAttr* attrs, global const PmrMaterial* materials,
                          global const PmrTexture* textures, global const uchar4* texels,
                          global const float* srgb_lut, global const float* positions,
                        global const float4* eyes, global const float2* split_sum, global const float2* texcoords, global const float4* tangents, global const PmrEncodeParams* E,
                          global const int* column_a, global const int* column_b, global const PmrEncodeRow* rows,
                          global const int* sample_x, global const int* sample_y,
                          global const PmrSampleChunk* chunks, uint num_chunks, global const int* straddle_slot,
                          uint straddle_slots, global uchar* straddle_cov, global half* display, global ushort* sub_alpha,
                          uint debug, global uint* dbg_key, global float* dbg_depth,
                          global const PmrEnvironment* env, global const float4* env_data,
                          global const PmrLight* lights) {
  const uint chunk = pmr_item_id();
  if (chunk >= num_chunks) return;
  const PmrSampleChunk ch = chunks[chunk];
  const int views = P->views, width = ch.s1 - ch.s0;
  const int Wd = E->display_w;
  const long Xc = sample_x[ch.s0], Yc = sample_y[ch.i0], Xl = sample_x[ch.s1 - 1], Yl = sample_y[ch.i1 - 1];

  /* 1. The samples by view: run v holds count[v] samples from first[v], padded to whole vectors. */
  int first[PMR_SUBPIXEL_VIEWS + 1], count[PMR_SUBPIXEL_VIEWS];
  ushort view_of[PMR_SUBPIXEL_CAP + 8];
  for (int v = 0; v < views; ++v) count[v] = 0;
  for (int i = ch.i0, n = 0; i < ch.i1; ++i) {
    /* encode_view for 8 columns at a time from the column table's planes (a_mod_n, b) */
    const size_t block = (size_t)(E->cell_rows > 1 ? (E->display_h - 1 - i) % E->cell_rows : 0) * (size_t)(3 * Wd);
    const PmrEncodeRow row = rows[i];
    for (int s = ch.s0; s < ch.s1; s += 8, n += 8) {
      const int8 a = vload8(0, column_a + block + s), b = vload8(0, column_b + block + s);
      vstore8(convert_ushort8(encode_view8(views, E->reversed, a, b, &row)), 0, view_of + n);
    }
    n -= (8 - width % 8) % 8; /* the last vector's lanes past the chunk are overwritten by the next row */
  }
  for (int n = 0; n < width * (ch.i1 - ch.i0); ++n) ++count[view_of[n]];
  int run = 0;
  for (int v = 0; v < views; ++v) {
    first[v] = run;
    run += (count[v] + SP_LANES - 1) / SP_LANES * SP_LANES;
  }
  first[views] = run;
  int sx[SP_SLOTS], sy[SP_SLOTS];     /* sample offsets from (Xc, Yc), fixed point */
  ushort sid[SP_SLOTS];               /* sample index (i - i0) * width + (s - s0) */
  uchar channel[SP_SLOTS];            /* k of the sample's subpixel s = 3j + k */
  float best_depth[SP_SLOTS];
  uint best_key[SP_SLOTS], best_mta[SP_SLOTS]; /* best_mta is read only where best_key says drawn */
  for (int k = 0; k < run; k += 8) {
    vstore8((float8)(INFINITY), 0, best_depth + k);
    vstore8((uint8)(PMR_NO_KEY), 0, best_key + k);
    vstore8((int8)(0), 0, sx + k); /* padding lanes: any value, masked by the run's length */
    vstore8((int8)(0), 0, sy + k);
  }
  {
    int fill[PMR_SUBPIXEL_VIEWS];
    for (int v = 0; v < views; ++v) fill[v] = first[v];
    /* column by column: a vector's samples then lie close together in x (all rows of a few columns),
     * which the bounding boxes below exploit */
    for (int s = ch.s0; s < ch.s1; ++s) {
      const int x = (int)(sample_x[s] - Xc);
      const uchar c = (uchar)(s % 3);
      for (int i = ch.i0, n = s - ch.s0; i < ch.i1; ++i, n += width) {
        const int k = fill[view_of[n]]++;
        sx[k] = x;
        sy[k] = (int)(sample_y[i] - Yc);
        sid[k] = (ushort)n;
        channel[k] = c;
      }
    }
  }
  /* each vector's bounding box (x0, x1, y0, y1): an MTA skips the vectors it cannot reach; x0 and x1
   * do not decrease along a run */
  int4 box[SP_SLOTS / SP_LANES];
  const int8 lane = vload8(0, lane_index);
  for (int v = 0; v < views; ++v)
    for (int k = first[v]; k < first[v] + count[v]; k += SP_LANES) {
      const int8 valid = lane < (int8)(first[v] + count[v] - k); /* padding lanes repeat lane 0 */
      const int8 x = select((int8)(sx[k]), vload8(0, sx + k), valid);
      const int8 y = select((int8)(sy[k]), vload8(0, sy + k), valid);
      const int4 x0 = min(x.lo, x.hi), x1 = max(x.lo, x.hi), y0 = min(y.lo, y.hi), y1 = max(y.lo, y.hi);
      const int2 a = min(x0.lo, x0.hi), b = max(x1.lo, x1.hi), c = min(y0.lo, y0.hi), d = max(y1.lo, y1.hi);
      box[k / SP_LANES] = (int4)(min(a.x, a.y), max(b.x, b.y), min(c.x, c.y), max(d.x, d.y));
    }

  /* 2. Visibility: the tile's queues, every view slab. */
  ShadeInputs in = {tris, attrs, materials, textures, texels, srgb_lut, P, positions, eyes, split_sum, texcoords, tangents, env, env_data,
                    lights};
  const double8 lane_d = convert_double8(lane);
  const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
  for (int tv = 0; tv < P->tiles_v; ++tv) {
    const int v0 = tv * PMR_TILE_V, v1 = min(views, v0 + PMR_TILE_V) - 1;
    if (first[v1 + 1] == first[v0]) continue; /* no sample of the chunk shows these views */
    const uint tile = ((uint)tv * (uint)P->tiles_y) * (uint)P->tiles_x + (uint)ch.tile;
    const uint q1 = tile_offsets[tile + 1];
    for (uint q = tile_offsets[tile]; q < q1; ++q) {
      const uint id = tile_queue[q];
      const PmrMta m = mtas[id];
      const long ylo = min(m.y[0], min(m.y[1], m.y[2])), yhi = max(m.y[0], max(m.y[1], m.y[2]));
      if (yhi < Yc || ylo > Yl) continue;
      const int i_lo = max(v0, m.view_lo), i_hi = min(v1, m.view_hi);
      const float cutoff = (m.flags & PMR_MTA_MASK) ? materials[tris[m.tri].material].alpha_cutoff : 0.0f;
      /* per edge: sign * dy, and bias - sign * E(Xc, Yc, v) and -sign * dx_ab(v) at view i_lo with their
       * exact increments per unit of view coordinate (both are linear in it) */
      const long f_lo = view_coord(P, i_lo), f_first = view_coord(P, m.view_lo);
      long t_lo[3], dt[3], dx_lo[3], ddx[3];
      double dy[3];
      for (int e = 0; e < 3; ++e) {
        const int a = ea[e], b = eb[e];
        const long sg = m.sign, d_y = (long)(m.y[b] - m.y[a]), d_dx = (long)m.dx[b] - (long)m.dx[a];
        t_lo[e] = mta_edge_bias(&m, a, b, f_first) - sg * mta_edge(&m, a, b, Xc, Yc, f_lo);
        dt[e] = sg * (d_y * (long)m.dx[a] + d_dx * (Yc - (long)m.y[a]));
        dx_lo[e] = -sg * ((long)m.x0[b] - (long)m.x0[a] + f_lo * d_dx);
        ddx[e] = -sg * d_dx;
        dy[e] = (double)(sg * d_y);
      }
      const long my0 = ylo - Yc, my1 = yhi - Yc;
      for (int ib = i_lo; ib <= i_hi; ib += 16) {
        uint pass = view_pass_mask(P, &m, ib, min(i_hi - ib + 1, 16), Xc, 0, Xl - Xc);
        while (pass != 0) { /* the passing views, lowest first */
          const int v = ib + (31 - (int)clz(pass & (0u - pass)));
          pass &= pass - 1u;
          const int k0 = first[v], k1 = k0 + count[v];
          if (k0 == k1) continue;
          long xv[3];
          const long fv = view_coord(P, v);
          for (int k = 0; k < 3; ++k) xv[k] = (long)m.x0[k] + fv * (long)m.dx[k];
          const long mx0 = min(xv[0], min(xv[1], xv[2])) - Xc, mx1 = max(xv[0], max(xv[1], xv[2])) - Xc;
          double dx[3], T[3];
          const long di = fv - f_lo;
          for (int e = 0; e < 3; ++e) {
            T[e] = (double)clamp(t_lo[e] + di * dt[e], -(1L << 48), 1L << 48);
            dx[e] = (double)(dx_lo[e] + di * ddx[e]);
          }
          bool have_plane = false;
          double z0 = 0.0, gx = 0.0, gy = 0.0, bx = 0.0, by = 0.0;
          for (int k = k0; k < k1; k += SP_LANES) {
            const int4 b = box[k / SP_LANES];
            if (b.x > mx1) break; /* a run's vectors go left to right (sorted by column) */
            if (b.y < mx0 || b.w < my0 || b.z > my1) continue;
            const double8 x = convert_double8(vload8(0, sx + k)), y = convert_double8(vload8(0, sy + k));
            long8 hit = ((double8)(dy[0]) * x + (double8)(dx[0]) * y >= (double8)(T[0])) &
                        ((double8)(dy[1]) * x + (double8)(dx[1]) * y >= (double8)(T[1])) &
                        ((double8)(dy[2]) * x + (double8)(dx[2]) * y >= (double8)(T[2]));
            if (k1 - k < SP_LANES) hit &= lane_d < (double8)(k1 - k); /* the run's padding */
            /* any(hit) as an OR of the lanes (a true lane is -1): any() on long8 compiles to a slow
             * sequence of branches here */
            const long4 h4 = hit.lo | hit.hi;
            const long2 h2 = h4.lo | h4.hi;
            if ((h2.x | h2.y) == 0) continue;
            if (!have_plane) { /* set up on the first covered sample: tiny MTAs often cover none */
              const long y0 = m.y[0], y1 = m.y[1], y2 = m.y[2];
              const long area = (y1 - y0) * (xv[2] - xv[0]) - (xv[1] - xv[0]) * (y2 - y0);
              const double inv = 1.0 / (double)area;
              const double dz1 = (double)m.z[1] - (double)m.z[0], dz2 = (double)m.z[2] - (double)m.z[0];
              gx = (dz1 * (double)(y0 - y2) + dz2 * (double)(y1 - y0)) * inv;
              gy = (dz1 * (double)(xv[2] - xv[0]) - dz2 * (double)(xv[1] - xv[0])) * inv;
              z0 = (double)m.z[0];
              bx = (double)(Xc - xv[0]);
              by = (double)(Yc - y0);
              have_plane = true;
            }
            const float8 z = convert_float8((double8)(z0) + ((double8)(gx) * ((double8)(bx) + x) +
                                                             (double8)(gy) * ((double8)(by) + y)));
            const float8 bd = vload8(0, best_depth + k);
            const uint8 bk = vload8(0, best_key + k);
            int8 win = convert_int8(hit) & ((z < bd) | ((z == bd) & ((uint8)(m.key) < bk)));
            if ((m.flags & PMR_MTA_MASK) && any(win)) {
              int w[SP_LANES];
              vstore8(win, 0, w);
              const SampleLanes S = offset_samples(Xc, Yc, sx + k, sy + k);
              mask_alpha_lanes(&in, &m, w, SP_LANES, &S, v, cutoff);
              win = vload8(0, w);
            }
            vstore8(select(bd, z, win), 0, best_depth + k);
            vstore8(select(bk, (uint8)(m.key), as_uint8(win)), 0, best_key + k);
            vstore8(select(vload8(0, best_mta + k), (uint8)(id), as_uint8(win)), 0, best_mta + k);
          }
        }
      }
    }
  }

  /* 3. The winners shaded at their samples: channel k of subpixel s = 3j + k, half bits, by sample. */
  const float3 light = (float3)(P->light_world[0], P->light_world[1], P->light_world[2]);
  ushort value[PMR_SUBPIXEL_CAP];
  uchar covered[PMR_SUBPIXEL_CAP];
  MtaCache cache;
  cache.id = PMR_NO_KEY;
  for (int v = 0; v < views; ++v)
    for (int k0 = first[v]; k0 < first[v] + count[v]; k0 += SW) {
      /* SW samples of view v at a time, one per lane */
      const int kn = min(SW, first[v] + count[v] - k0);
      int todo[SW], ids[SW];
      for (int l = 0; l < SW; ++l) {
        const int k = k0 + l;
        todo[l] = l < kn && best_key[k] != PMR_NO_KEY ? -1 : 0;
        ids[l] = todo[l] ? (int)best_mta[k] : 0;
        if (l >= kn) continue;
        const int n = sid[k];
        if (debug) {
          const size_t at = (size_t)(ch.i0 + n / width) * (size_t)(3 * Wd) + (size_t)(ch.s0 + n % width);
          dbg_key[at] = best_key[k];
          dbg_depth[at] = best_depth[k];
        }
        if (!todo[l]) value[n] = 0, covered[n] = 0;
      }
      const sint act = vload_s(0, todo);
      if (!any(act)) continue;
      const SampleLanes S = offset_samples(Xc, Yc, sx + k0, sy + k0);
      LaneWinners L;
      lanes_gather(&in, mtas, &cache, act, vload_s(0, ids), &S, v, &L);
      float c[3][SW];
      s3_store(shade_lanes(&in, &L, light, v), c[0], c[1], c[2]);
      for (int l = 0; l < kn; ++l) {
        if (!todo[l]) continue;
        const int k = k0 + l, n = sid[k];
        ushort h;
        vstore_half(c[channel[k]][l], 0, (half*)&h);
        value[n] = h;
        covered[n] = 1;
      }
    }

  /* 4. The display pixels (write_display_pixel): a sample's half RGBA bits are its value in every
   * channel (the pixel takes channel k from subpixel k) and its coverage as alpha. */
  const DisplayOut D = {(global ushort*)display, sub_alpha, straddle_cov, straddle_slot, straddle_slots, Wd};
  const ushort one = 0x3c00; /* 1.0 as a half */
  for (int i = ch.i0; i < ch.i1; ++i) {
    const int r = (i - ch.i0) * width - ch.s0; /* sample index of subpixel s: r + s */
    for (int j = ch.s0 / 3; 3 * j < ch.s1; ++j) {
      ushort4 s[3];
      for (int k = 0; k < 3; ++k) {
        const int n = r + 3 * j + k;
        const bool own = 3 * j + k >= ch.s0 && 3 * j + k < ch.s1;
        s[k] = own ? (ushort4)(value[n], value[n], value[n], covered[n] ? one : 0) : (ushort4)(0);
      }
      write_display_pixel(&D, i, j, ch.s0, ch.s1, s[0], s[1], s[2]);
    }
  }
}
