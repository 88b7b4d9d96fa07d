/* Stage 5, pixel encoding (DESIGN section 5): one work-item per display pixel. Subpixel k of pixel
 * (j, i) shows view v = floor(N t) mod N, evaluated exactly in int64 (see PmrEncodeParams), sampled at
 * normalized position ((j + (k + 0.5) / 3) / W_d, (i + 0.5) / H_d) of that view. Alpha is the mean
 * coverage of the three sampled voxels. */
#include "common.h"

/* Channel `ch` of view v at the sampling position of subpixel k of display pixel (j, i). */
inline float sample_channel(global const PmrEncodeParams* E, global const half* volume, int v, int k, int ch, int j, int i) {
  const size_t plane = (size_t)v * (size_t)E->view_h * (size_t)E->view_w;
  if (!E->bilinear) {
    /* exact nearest pixel: floor((3j + k + 0.5) / (3 W_d) * W) */
    const int px = (int)(((long)(6 * j + 2 * k + 1) * E->view_w) / (6L * E->display_w));
    const int py = (int)(((long)(2 * i + 1) * E->view_h) / (2L * E->display_h));
    return vload_half(4 * (plane + (size_t)py * E->view_w + px) + (size_t)ch, volume);
  }
  const float fx = ((float)j + ((float)k + 0.5f) / 3.0f) / (float)E->display_w * (float)E->view_w - 0.5f;
  const float fy = ((float)i + 0.5f) / (float)E->display_h * (float)E->view_h - 0.5f;
  const float x0f = floor(fx), y0f = floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  const int x0 = clamp((int)x0f, 0, E->view_w - 1), x1 = clamp((int)x0f + 1, 0, E->view_w - 1);
  const int y0 = clamp((int)y0f, 0, E->view_h - 1), y1 = clamp((int)y0f + 1, 0, E->view_h - 1);
  const float c00 = vload_half(4 * (plane + (size_t)y0 * E->view_w + x0) + (size_t)ch, volume);
  const float c10 = vload_half(4 * (plane + (size_t)y0 * E->view_w + x1) + (size_t)ch, volume);
  const float c01 = vload_half(4 * (plane + (size_t)y1 * E->view_w + x0) + (size_t)ch, volume);
  const float c11 = vload_half(4 * (plane + (size_t)y1 * E->view_w + x1) + (size_t)ch, volume);
  const float top = c00 + (c10 - c00) * ax, bottom = c01 + (c11 - c01) * ax;
  return top + (bottom - top) * ay;
}

kernel void encode_display(global const PmrEncodeParams* E, global const half* volume, global half* display) {
  const uint gid = get_global_id(0);
  if (gid >= (uint)E->display_w * (uint)E->display_h) return;
  const int j = (int)(gid % (uint)E->display_w), i = (int)(gid / (uint)E->display_w);
  float rgba[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  const long row = E->num_i * (long)i + E->num_0;
  for (int k = 0; k < 3; ++k) {
    long v = floor_div_l(E->num_jk * (long)(3 * j + k) - row, E->den) % E->views;
    if (v < 0) v += E->views;
    if (E->reversed) v = E->views - 1 - v;
    rgba[k] = sample_channel(E, volume, (int)v, k, k, j, i);
    rgba[3] += sample_channel(E, volume, (int)v, k, 3, j, i);
  }
  vstore_half4((float4)(rgba[0], rgba[1], rgba[2], rgba[3] / 3.0f), gid, display);
}
