/* Stage 5, pixel encoding (DESIGN section 5): one work-item per display pixel. Subpixel k of pixel
 * (j, i) shows view v = floor(N t) mod N, evaluated exactly in int64 (see PmrEncodeParams), sampled at
 * normalized position ((j + (k + 0.5) / 3) / W_d, (i + 0.5) / H_d) of that view. Alpha is the mean
 * coverage of the three sampled voxels. */
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

/* One work-item encodes PMR_ENCODE_RUN consecutive pixels of one display row. Along a row the
 * subpixel index s = 3j + k grows by one per subpixel, so both the view index floor(N t) mod N (N t
 * grows by num_jk / den) and the nearest view column floor((2s + 1) W / (6 W_d)) are stepped with
 * integer additions, after one division each at the start of the run. */
#define PMR_ENCODE_RUN 32

kernel void encode_display(global const PmrEncodeParams* E, global const half* volume, global half* display) {
  const int runs = (E->display_w + PMR_ENCODE_RUN - 1) / PMR_ENCODE_RUN;
  const uint gid = get_global_id(0);
  if (gid >= (uint)runs * (uint)E->display_h) return;
  const int i = (int)(gid / (uint)runs);
  const int j0 = (int)(gid % (uint)runs) * PMR_ENCODE_RUN;
  const int j1 = min(j0 + PMR_ENCODE_RUN, E->display_w);
  const int N = E->views;

  /* N t = (num_jk s - row) / den = q + r / den, 0 <= r < den */
  const long num = E->num_jk * (long)(3 * j0) - (E->num_i * (long)i + E->num_0);
  long q = floor_div_l(num, E->den);
  long r = num - q * E->den;
  const long step_q = E->num_jk / E->den, step_r = E->num_jk % E->den; /* num_jk > 0 */
  int v = (int)(q % N);
  if (v < 0) v += N;
  const int step_v = (int)(step_q % N);

  /* nearest column: (2s + 1) W = cx * 6 W_d + cr */
  const long six_wd = 6L * E->display_w;
  const long cnum = (long)(6 * j0 + 1) * E->view_w;
  int cx = (int)(cnum / six_wd);
  long cr = cnum - (long)cx * six_wd;
  const long cstep = 2L * E->view_w;
  const int py = (int)(((long)(2 * i + 1) * E->view_h) / (2L * E->display_h));
  const size_t plane = (size_t)E->view_h * (size_t)E->view_w;
  const size_t row_off = (size_t)py * (size_t)E->view_w;
  const float t = ((float)i + 0.5f) / (float)E->display_h;

  for (int j = j0; j < j1; ++j) {
    float rgb[3], alpha = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const int view = E->reversed ? N - 1 - v : v;
      float4 c;
      if (!E->bilinear)
        c = vload_half4((size_t)view * plane + row_off + (size_t)cx, volume);
      else
        c = sample_bilinear(E, volume, view, ((float)j + ((float)k + 0.5f) / 3.0f) / (float)E->display_w, t);
      rgb[k] = k == 0 ? c.x : (k == 1 ? c.y : c.z);
      alpha += c.w;
      /* next subpixel */
      r += step_r;
      v += step_v;
      if (r >= E->den) {
        r -= E->den;
        ++v;
      }
      if (v >= N) v -= N;
      cr += cstep;
      while (cr >= six_wd) {
        cr -= six_wd;
        ++cx;
      }
    }
    vstore_half4((float4)(rgb[0], rgb[1], rgb[2], alpha / 3.0f), (size_t)i * E->display_w + j, display);
  }
}
