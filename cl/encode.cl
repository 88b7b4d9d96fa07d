/* Stage 5, pixel encoding (DESIGN section 5): one work-item per display pixel (2D range: x = column j,
 * y = row i). Subpixel k of pixel (j, i) shows view v = floor(N t) mod N, sampled at normalized position
 * ((j + (k + 0.5) / 3) / W_d, (i + 0.5) / H_d) of that view. The view index is exact and division-free
 * through per-column and per-row tables (PmrEncodeColumn / PmrEncodeRow), which keeps the kernel
 * branch-free so that it vectorizes across work-items. Alpha is the mean coverage of the three samples;
 * each sample's own alpha goes to sub_alpha (store_sub_alpha). */
#include "common.h"

/* Bilinear sample of view v at normalized position (u, t), all four channels. */
inline float4 sample_bilinear(global const PmrEncodeParams* E, global const half* volume, int v, float u, float t) {
  const size_t plane = (size_t)v * (size_t)E->view_h * (size_t)E->view_w;
  const float fx = u * (float)E->view_w - 0.5f, fy = t * (float)E->view_h - 0.5f;
  const float x0f = floor(fx), y0f = floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  const int x0 = clamp((int)x0f, 0, E->view_w - 1), x1 = clamp((int)x0f + 1, 0, E->view_w - 1);
  const int y0 = clamp((int)y0f, 0, E->view_h - 1), y1 = clamp((int)y0f + 1, 0, E->view_h - 1);
  const float4 c00 = vload_half4(plane + (size_t)y0 * E->view_w + x0, volume);
  const float4 c10 = vload_half4(plane + (size_t)y0 * E->view_w + x1, volume);
  const float4 c01 = vload_half4(plane + (size_t)y1 * E->view_w + x0, volume);
  const float4 c11 = vload_half4(plane + (size_t)y1 * E->view_w + x1, volume);
  const float4 top = c00 + (c10 - c00) * ax, bottom = c01 + (c11 - c01) * ax;
  return top + (bottom - top) * ay;
}

/* The column table of row i: with subpixel cells one block per row class (PmrEncodeParams). */
/* Nearest sampling copies the colour's half bits: PoCL converts halves in software, and the
 * conversions would dominate the stage. Separate kernels for nearest and bilinear sampling, because
 * a branch between them would be flattened when the kernel is vectorized across work-items. */
kernel void encode_nearest(global const PmrEncodeParams* E, global const PmrEncodeColumn* all_columns,
                           global const PmrEncodeRow* rows, global const half* volume, global half* display,
                           global ushort* sub_alpha) {
  const int j0 = (int)get_global_id(0) * PMR_ENCODE_RUN, i = (int)get_global_id(1);
  if (j0 >= E->display_w || i >= E->display_h) return;
  global const PmrEncodeColumn* columns = row_columns(E, all_columns, i);
  const int j1 = min(j0 + PMR_ENCODE_RUN, E->display_w);
  const PmrEncodeRow row = rows[i];
  const size_t plane = (size_t)E->view_h * (size_t)E->view_w;
  const size_t row_off = (size_t)row.py * (size_t)E->view_w;
  global const ushort* bits = (global const ushort*)volume;
  for (int j = j0; j < j1; ++j) {
    /* the three subpixels unrolled into scalars: small private arrays written by element and read
     * back as a vector stall the CPU's store forwarding, which cost more than all the rest */
    const PmrEncodeColumn c0 = columns[3 * j], c1 = columns[3 * j + 1], c2 = columns[3 * j + 2];
    const ushort4 s0 =
        vload4((size_t)encode_view(E->views, E->reversed, &c0, &row) * plane + row_off + (size_t)c0.px, bits);
    const ushort4 s1 =
        vload4((size_t)encode_view(E->views, E->reversed, &c1, &row) * plane + row_off + (size_t)c1.px, bits);
    const ushort4 s2 =
        vload4((size_t)encode_view(E->views, E->reversed, &c2, &row) * plane + row_off + (size_t)c2.px, bits);
    vstore4(encode_pixel(s0, s1, s2), (size_t)i * E->display_w + j, (global ushort*)display);
    store_sub_alpha(sub_alpha, (size_t)i * E->display_w + j, s0, s1, s2);
  }
}

/* View blending (Looking Glass webxr 0.6's filter mode 1): subpixel k shows views v and v + 1 (the
 * last view stands in for v + 1 = N) mixed by the fraction of the phase, N t - floor(N t), sampled at
 * its own position. The fraction comes from the tables' float remainders: a weight, not a decision. */
kernel void encode_blend(global const PmrEncodeParams* E, global const PmrEncodeColumn* all_columns,
                         global const PmrEncodeRow* rows, global const half* volume, global half* display,
                         global ushort* sub_alpha) {
  const int j0 = (int)get_global_id(0) * PMR_ENCODE_RUN, i = (int)get_global_id(1);
  if (j0 >= E->display_w || i >= E->display_h) return;
  global const PmrEncodeColumn* columns = row_columns(E, all_columns, i);
  const int j1 = min(j0 + PMR_ENCODE_RUN, E->display_w);
  const PmrEncodeRow row = rows[i];
  const size_t plane = (size_t)E->view_h * (size_t)E->view_w;
  const size_t row_off = (size_t)row.py * (size_t)E->view_w;
  for (int j = j0; j < j1; ++j) {
    float rgb[3], sub[3], alpha = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const PmrEncodeColumn col = columns[3 * j + k];
      const int v0 = encode_view(E->views, 0, &col, &row), v1 = min(v0 + 1, E->views - 1);
      float w = col.phase_frac - row.phase_frac;
      w = w < 0.0f ? w + 1.0f : w;
      const int a = E->reversed ? E->views - 1 - v0 : v0, b = E->reversed ? E->views - 1 - v1 : v1;
      const float4 c0 = vload_half4((size_t)a * plane + row_off + (size_t)col.px, volume);
      const float4 c1 = vload_half4((size_t)b * plane + row_off + (size_t)col.px, volume);
      const float4 c = c0 + (c1 - c0) * w;
      rgb[k] = k == 0 ? c.x : (k == 1 ? c.y : c.z);
      sub[k] = c.w;
      alpha += c.w;
    }
    vstore_half4((float4)(rgb[0], rgb[1], rgb[2], alpha / 3.0f), (size_t)i * E->display_w + j, display);
    vstore_half3((float3)(sub[0], sub[1], sub[2]), (size_t)i * E->display_w + j, (global half*)sub_alpha);
  }
}

kernel void encode_bilinear(global const PmrEncodeParams* E, global const PmrEncodeColumn* all_columns,
                            global const PmrEncodeRow* rows, global const half* volume, global half* display,
                            global ushort* sub_alpha) {
  const int j0 = (int)get_global_id(0) * PMR_ENCODE_RUN, i = (int)get_global_id(1);
  if (j0 >= E->display_w || i >= E->display_h) return;
  global const PmrEncodeColumn* columns = row_columns(E, all_columns, i);
  const int j1 = min(j0 + PMR_ENCODE_RUN, E->display_w);
  const PmrEncodeRow row = rows[i];
  const float t = ((float)i + 0.5f) / (float)E->display_h;
  for (int j = j0; j < j1; ++j) {
    float rgb[3], sub[3], alpha = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const PmrEncodeColumn col = columns[3 * j + k];
      const float4 c = sample_bilinear(E, volume, encode_view(E->views, E->reversed, &col, &row),
                                       ((float)j + ((float)k + 0.5f) / 3.0f) / (float)E->display_w, t);
      rgb[k] = k == 0 ? c.x : (k == 1 ? c.y : c.z);
      sub[k] = c.w;
      alpha += c.w;
    }
    vstore_half4((float4)(rgb[0], rgb[1], rgb[2], alpha / 3.0f), (size_t)i * E->display_w + j, display);
    vstore_half3((float3)(sub[0], sub[1], sub[2]), (size_t)i * E->display_w + j, (global half*)sub_alpha);
  }
}
