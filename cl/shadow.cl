/* Shadow maps (DESIGN section 4d): the frame's posed triangles rasterized into one map of a light
 * (PmrShadowMap), each texel keeping the nearest caster's depth along the map's axis. Depths are
 * non-negative floats, whose bits order as the floats do, so the nearest is an atomic minimum of the
 * bits and the map does not depend on the order in which triangles arrive. Rendered once per frame,
 * before any fine raster, and read by the shading of every view (cl/lights.h, shadow_visibility). */
#include "common.h"

#define PMR_SHADOW_EMPTY 0x7f800000u /* +infinity: no caster */

kernel void shadow_clear(global uint* depth, uint first, uint count) {
  const uint i = pmr_item_id();
  if (i < count) depth[first + i] = PMR_SHADOW_EMPTY;
}

/* World point q in the map's space: (right . d, up . d, axis . d), d = q - origin (unscaled by z). */
inline float3 shadow_space(global const PmrShadowMap* m, float3 q) {
  const float3 d = q - vload3(0, m->origin);
  return (float3)(dot(vload3(0, m->right), d), dot(vload3(0, m->up), d), dot(vload3(0, m->axis), d));
}

/* The polygon of a triangle in map space clipped to z >= near (perspective maps; up to 4 corners). */
inline int clip_near(const float3* c, float near_z, float3* out) {
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const float3 a = c[k], b = c[(k + 1) % 3];
    if (a.z >= near_z) out[n++] = a;
    if ((a.z >= near_z) != (b.z >= near_z)) out[n++] = mix(a, b, (near_z - a.z) / (b.z - a.z));
  }
  return n;
}

/* Texel coordinates (x right, y up, texel centers at + 1/2) and 1/z (perspective) or z (orthographic)
 * of a corner in map space. */
inline float3 shadow_texel(global const PmrShadowMap* m, float3 c) {
  const float w = m->perspective ? 1.0f / c.z : 1.0f;
  const float half_size = 0.5f * (float)m->size;
  return (float3)((c.x * w + 1.0f) * half_size, (c.y * w + 1.0f) * half_size, m->perspective ? w : c.z);
}

/* Rasterizes the triangle of texel-space corners a, b, c: every texel whose center it covers (edges
 * included) takes the depth at the center if nearer. Perspective maps interpolate 1/z linearly. */
inline void shadow_triangle(global const PmrShadowMap* m, global uint* depth, float3 a, float3 b, float3 c) {
  const float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(fabs(area) > 0.0f)) return;
  const float inv = 1.0f / area;
  const int size = m->size;
  const int x0 = max(0, (int)floor(fmin(fmin(a.x, b.x), c.x) - 0.5f)),
            x1 = min(size - 1, (int)ceil(fmax(fmax(a.x, b.x), c.x) - 0.5f));
  const int y0 = max(0, (int)floor(fmin(fmin(a.y, b.y), c.y) - 0.5f)),
            y1 = min(size - 1, (int)ceil(fmax(fmax(a.y, b.y), c.y) - 0.5f));
  global uint* map = depth + m->offset;
  for (int y = y0; y <= y1; ++y) {
    const float py = (float)y + 0.5f;
    for (int x = x0; x <= x1; ++x) {
      const float px = (float)x + 0.5f;
      const float wa = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) * inv;
      const float wb = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) * inv;
      const float wc = 1.0f - wa - wb;
      if (wa < 0.0f || wb < 0.0f || wc < 0.0f) continue;
      const float q = wa * a.z + wb * b.z + wc * c.z;
      const float z = fmax(m->perspective ? 1.0f / q : q, 0.0f);
      atomic_min(map + (size_t)y * (size_t)size + (size_t)x, as_uint(z));
    }
  }
}

/* One work-item per triangle of the frame's posed scene (positions: world space, 3 floats a vertex),
 * into map `map`. Casters: every triangle but alphaMode BLEND and transmissive ones (they cast nothing
 * yet), MASK ones whole. */
kernel void shadow_raster(global const float* positions, global const PmrTriangle* tris,
                          global const PmrMaterial* materials, uint num_triangles,
                          global const PmrShadowMap* maps, uint map, global uint* depth) {
  const uint t = pmr_item_id();
  if (t >= num_triangles) return;
  const PmrTriangle tri = tris[t];
  global const PmrMaterial* mat = &materials[tri.material];
  if (mat->alpha_mode == PMR_ALPHA_BLEND || mat->transmission > 0.0f) return;
  global const PmrShadowMap* m = &maps[map];
  float3 c[3];
  for (int k = 0; k < 3; ++k) c[k] = shadow_space(m, vload3(tri.v[k], positions));
  float3 poly[4];
  int n = 3;
  if (m->perspective) n = clip_near(c, m->near_z, poly);
  else poly[0] = c[0], poly[1] = c[1], poly[2] = c[2];
  if (n < 3) return;
  const float3 a = shadow_texel(m, poly[0]);
  for (int k = 1; k + 1 < n; ++k) shadow_triangle(m, depth, a, shadow_texel(m, poly[k]), shadow_texel(m, poly[k + 1]));
}
