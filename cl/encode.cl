/* Stage 5, pixel encoding (DESIGN section 5): one work-item per display pixel. Subpixel k of pixel
 * (j, i) shows view v = floor(N t) mod N, evaluated exactly in int64 (see PmrEncodeParams), sampled at
 * normalized position ((j + (k + 0.5) / 3) / W_d, (i + 0.5) / H_d) of that view. Alpha is the mean
 * coverage of the three sampled voxels. */
#include "common.h"

/* View v at the sampling position of subpixel k of display pixel (j, i), all four channels. */
inline float4 sample_view(global const PmrEncodeParams* E, global const half* volume, int v, int k, int j, int i) {
  const size_t plane = (size_t)v * (size_t)E->view_h * (size_t)E->view_w;
  if (!E->bilinear) {
    /* exact nearest pixel: floor((j + (k + 0.5) / 3) / W_d * W) = floor((6j + 2k + 1) W / (6 W_d)) */
    const uint px = ((uint)(6 * j + 2 * k + 1) * (uint)E->view_w) / (6u * (uint)E->display_w);
    const uint py = ((uint)(2 * i + 1) * (uint)E->view_h) / (2u * (uint)E->display_h);
    return vload_half4(plane + (size_t)py * E->view_w + px, volume);
  }
  const float fx = ((float)j + ((float)k + 0.5f) / 3.0f) / (float)E->display_w * (float)E->view_w - 0.5f;
  const float fy = ((float)i + 0.5f) / (float)E->display_h * (float)E->view_h - 0.5f;
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

kernel void encode_display(global const PmrEncodeParams* E, global const half* volume, global half* display) {
  const uint gid = get_global_id(0);
  if (gid >= (uint)E->display_w * (uint)E->display_h) return;
  const int j = (int)(gid % (uint)E->display_w), i = (int)(gid / (uint)E->display_w);
  const long row = E->num_i * (long)i + E->num_0;
  float rgb[3], alpha = 0.0f;
  for (int k = 0; k < 3; ++k) {
    long v = floor_div_l(E->num_jk * (long)(3 * j + k) - row, E->den) % E->views;
    if (v < 0) v += E->views;
    if (E->reversed) v = E->views - 1 - v;
    const float4 c = sample_view(E, volume, (int)v, k, j, i);
    rgb[k] = k == 0 ? c.x : (k == 1 ? c.y : c.z);
    alpha += c.w;
  }
  vstore_half4((float4)(rgb[0], rgb[1], rgb[2], alpha / 3.0f), gid, display);
}
