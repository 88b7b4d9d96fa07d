/* Transmission (docs/DESIGN.md section 4c step 2, KHR_materials_transmission with KHR_materials_volume
 * and KHR_materials_ior), part of the one shading module (cl/shade.h). The frame's opaque pass leaves
 * each view's opaque image in the transmission source (PmrSource: premultiplied half RGBA with a mip
 * chain); a transmissive winner of the full pass refracts its view ray, follows it through the volume's
 * thickness, projects the end point into its OWN view and reads the source there, blurred through the
 * mips by roughness and ior. So what is seen through glass shifts between the views as through real
 * glass, each view from its own image. */
#ifndef PMR_CL_TRANSMISSION_H
#define PMR_CL_TRANSMISSION_H

#include "environment_light.h"
#include "lane_winners.h"

/* Texel (x, y) of level k (w x h texels a view) of view slice `slice`, premultiplied RGBA. */
inline float4 source_texel(global const half* src, global const PmrSource* S, int k, size_t slice, int w, int h, int x,
                           int y) {
  x = clamp(x, 0, w - 1), y = clamp(y, 0, h - 1);
  return vload_half4((size_t)S->level_offset[k] + (slice * (size_t)h + (size_t)y) * (size_t)w + (size_t)x, src);
}

/* Bilinear at raster point (x, y) (level-0 pixels, centers at + 1/2) of level k, clamped to the edge. */
inline float4 source_bilinear(global const half* src, global const PmrSource* S, int k, size_t slice, int W, int H,
                              float x, float y) {
  const int w = max(1, W >> k), h = max(1, H >> k);
  const float tx = x * ((float)w / (float)W) - 0.5f, ty = y * ((float)h / (float)H) - 0.5f;
  const float fx0 = floor(tx), fy0 = floor(ty);
  const float fx = tx - fx0, fy = ty - fy0;
  const int x0 = (int)fx0, y0 = (int)fy0;
  const float4 a = source_texel(src, S, k, slice, w, h, x0, y0), b = source_texel(src, S, k, slice, w, h, x0 + 1, y0);
  const float4 c = source_texel(src, S, k, slice, w, h, x0, y0 + 1),
               d = source_texel(src, S, k, slice, w, h, x0 + 1, y0 + 1);
  return mix(mix(a, b, fx), mix(c, d, fx), fy);
}

/* The source of view slice `slice` at raster point (x, y), trilinear at level `lod`; (0, 0, 0, 0) off
 * the raster (what is not in the image is not in front of the environment either). */
inline float4 source_sample(const ShadeInputs* in, size_t slice, float x, float y, float lod) {
  global const PmrSource* S = in->source_info;
  const int W = in->P->view_w, H = in->P->view_h;
  if (S->levels == 0u || !(x >= 0.0f && x <= (float)W && y >= 0.0f && y <= (float)H)) return (float4)(0.0f);
  const float l = clamp(lod, 0.0f, (float)(S->levels - 1u));
  const int k0 = (int)l;
  const float f = l - (float)k0;
  const float4 s0 = source_bilinear(in->source, S, k0, slice, W, H, x, y);
  if (f == 0.0f) return s0;
  return mix(s0, source_bilinear(in->source, S, k0 + 1, slice, W, H, x, y), f);
}

/* World points q projected into view `view` of the pass (P->view: the center camera's, or a multipass
 * view's own): raster x, y (the vertex stage's projection, in float) and whether in front of the camera. */
inline sint project_lanes(global const PmrParams* P, sfloat3 q, int view, sfloat* x, sfloat* y) {
  global const double* V = P->view; /* column-major */
  const sfloat xv = (float)V[0] * q.x + (float)V[4] * q.y + (float)V[8] * q.z + (float)V[12];
  const sfloat yv = (float)V[1] * q.x + (float)V[5] * q.y + (float)V[9] * q.z + (float)V[13];
  const sfloat w = -((float)V[2] * q.x + (float)V[6] * q.y + (float)V[10] * q.z + (float)V[14]);
  const sfloat iw = 1.0f / w;
  const float half_w = 0.5f * (float)P->view_w, half_h = 0.5f * (float)P->view_h;
  *x = ((float)P->ndc_scale_x * xv * iw + (float)P->ndc_offset_x + 1.0f) * half_w;
  if (P->views > 1) {
    const float at = (float)(P->view_anchor + (double)view_coord(P, view) / P->view_scale);
    *x += at * (float)P->disparity_k * (1.0f - (float)P->focal * iw);
  }
  *y = (1.0f - (float)P->ndc_scale_y * yv * iw) * half_h;
  return w > 0.0f;
}

/* The light arriving through the transmissive lanes `glass` (DESIGN 4c step 2), before the BTDF's
 * weights: the view ray -v refracted at n (Snell, eta = 1 / ior; ior 0 or a thin surface: straight on),
 * travelled thickness along it, the end point's source (divided by the exposure it was drawn with) plus
 * (1 - its alpha) x the environment along the refracted ray (*escaped: that 1 - alpha, the part that
 * left the scene; with P->clear_glass the environment is not added: the caller lowers alpha by it),
 * attenuated by Beer-Lambert,
 * attenuationColor^(distance / attenuationDistance) (*attenuation: that factor, which the lights seen
 * through the surface take too). r: the roughness; thickness: the volume's, textured and in world units. */
inline sfloat3 transmitted_lanes(const ShadeInputs* in, const LaneWinners* L, sfloat3 p, sfloat3 n, sfloat3 v, sfloat r,
                                 sfloat thickness, int view, sfloat3* attenuation, sfloat* escaped) {
  global const PmrParams* P = in->P;
  const sfloat ior = L->ior, nv = clamp(s3_dot(n, v), 0.0f, 1.0f);
  const sfloat eta = select((sfloat)(1.0f), 1.0f / ior, ior >= 1.0f);
  const sfloat k = 1.0f - eta * eta * (1.0f - nv * nv); /* eta <= 1: k > 0 */
  const sfloat3 t = s3_add(s3_scale(v, -eta), s3_scale(n, eta * nv - sqrt(fmax(k, 0.0f))));
  const sfloat tl = sqrt(s3_dot(t, t));
  const sint bend = L->glass & (thickness > 0.0f) & (tl > 0.0f);
  const sfloat3 d = s3_select(s3_neg(v), s3_scale(t, 1.0f / tl), bend);
  /* (a thickness beyond float range, or times a large node scale, walks far but stays finite) */
  const sfloat dist = select((sfloat)(0.0f), fmin(thickness, 1e30f), bend);
  const sfloat3 q = s3_add(p, s3_scale(d, dist));
  sfloat x, y;
  const sint front = project_lanes(P, q, view, &x, &y);
  const sfloat blur = r * clamp(2.0f * ior - 2.0f, 0.0f, 1.0f);
  const sfloat lod = log2((float)P->view_w) * blur;
  float sx[SW], sy[SW], sl[SW], c[4][SW];
  vstore_s(x, 0, sx), vstore_s(y, 0, sy), vstore_s(lod, 0, sl);
  const size_t slice = (size_t)view + (size_t)P->view_base;
  const uint bits = lane_bits(L->glass & front);
  for (int l = 0; l < SW; ++l) c[0][l] = c[1][l] = c[2][l] = c[3][l] = 0.0f;
  for (uint b = bits; b != 0u; b &= b - 1u) {
    const int l = 31 - (int)clz(b & (0u - b));
    const float4 s = source_sample(in, slice, sx[l], sy[l], sl[l]);
    c[0][l] = s.x, c[1][l] = s.y, c[2][l] = s.z, c[3][l] = s.w;
  }
  const sfloat uncovered = 1.0f - clamp(vload_s(0, c[3]), 0.0f, 1.0f);
  *escaped = select((sfloat)(0.0f), uncovered, L->glass);
  const sfloat3 env = P->clear_glass ? s3_splat((float3)(0.0f)) : environment_along(in, d, blur, L->glass);
  const sfloat inv_exposure = (sfloat)(1.0f / P->exposure);
  const sfloat3 light = s3_add(s3_scale(LANE3(c), inv_exposure), s3_scale(env, uncovered));
  const sfloat3 ac = L->att_color;
  const sfloat e = dist / L->att_dist; /* no attenuation (+inf distance): 0, and pow(c, 0) = 1 */
  *attenuation = s3(pow(ac.x, e), pow(ac.y, e), pow(ac.z, e));
  return s3_mul(light, *attenuation);
}

#endif
