/* Shadow maps (DESIGN section 4d): the frame's posed triangles rasterized into one map of a light
 * (PmrShadowMap), each texel keeping the nearest opaque caster's depth along the map's axis. Depths
 * are non-negative floats, whose bits order as the floats do, so the nearest is an atomic minimum of
 * the bits. Translucent casters (alphaMode BLEND, transmissive materials) add -ln(1 - opacity) to the
 * texel's optical depth in fixed point (an integer sum) and their depth to its nearest translucent
 * depth. So a map does not depend on the order in which triangles arrive. MASK casters are
 * alpha-tested at each texel. Rendered once per frame, before any fine raster, and read by the shading
 * of every view (cl/lights.h, shadow_visibility_lanes). */
#include "shade.h"

#define PMR_SHADOW_EMPTY 0x7f800000u /* +infinity: no caster */

/* Clears texels [first, first + count): depths to empty, or (pairs) depth empty and optical depth 0. */
kernel void shadow_clear(global uint* depth, uint first, uint count, uint pairs) {
  const uint i = pmr_item_id();
  if (i >= count) return;
  if (pairs) depth[first + 2 * i] = PMR_SHADOW_EMPTY, depth[first + 2 * i + 1] = 0u;
  else depth[first + i] = PMR_SHADOW_EMPTY;
}

/* A corner of a triangle in map space: (right . d, up . d, axis . d), d = q - origin, and its source
 * barycentrics (a vertex's, or interpolated where the near plane clips). */
typedef struct {
  float3 c, b;
} ShadowCorner;

/* The corners of a triangle clipped to z >= near_z (perspective maps; up to 4). */
inline int clip_near(const ShadowCorner* c, float near_z, ShadowCorner* out) {
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const ShadowCorner a = c[k], b = c[(k + 1) % 3];
    if (a.c.z >= near_z) out[n++] = a;
    if ((a.c.z >= near_z) != (b.c.z >= near_z)) {
      const float t = (near_z - a.c.z) / (b.c.z - a.c.z);
      out[n].c = mix(a.c, b.c, t), out[n].b = mix(a.b, b.b, t);
      ++n;
    }
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

/* Up to SW covered texels of a translucent or MASK caster, whose opacity is evaluated together. */
typedef struct {
  int n;
  uint texel[SW];
  float z[SW], b[3][SW];
} ShadowBatch;

/* The batch's texels take the caster: opaque ones (opacity 1) its depth if nearer, partial ones its
 * optical depth and nearest translucent depth. */
inline void shadow_flush(const ShadeInputs* in, global const PmrShadowMap* m, uint tri, global uint* depth,
                         ShadowBatch* B) {
  if (B->n == 0) return;
  for (int j = B->n; j < SW; ++j) B->b[0][j] = B->b[0][0], B->b[1][j] = B->b[1][0], B->b[2][j] = B->b[2][0];
  float opacity[SW];
  caster_opacity_lanes(in, tri, B->b, B->n, opacity);
  for (int j = 0; j < B->n; ++j) {
    const float a = opacity[j];
    if (a >= 1.0f) {
      atomic_min(depth + m->offset + B->texel[j], as_uint(B->z[j]));
    } else if (a > 0.0f && m->translucent != PMR_NO_TRANSLUCENT) {
      global uint* pair = depth + m->translucent + 2 * B->texel[j];
      atomic_min(pair, as_uint(B->z[j]));
      atomic_add(pair + 1, (uint)(fmin(-log1p(-a), 40.0f) * PMR_SHADOW_OPTICAL_ONE + 0.5f));
    }
  }
  B->n = 0;
}

/* Rasterizes the clipped triangle of texel-space corners t[.] (source barycentrics s[.]), the rows
 * `row`, row + rows, ... of its bounding box: every texel whose center it covers (edges included) takes
 * the depth at the center. `opaque`: the caster is opaque everywhere (its depth goes straight to the
 * map), else texels gather in batches. */
inline void shadow_triangle(const ShadeInputs* in, global const PmrShadowMap* m, uint tri, bool opaque,
                            global uint* depth, const float3* t, const float3* s, int row, int rows) {
  const float3 a = t[0], b = t[1], c = t[2];
  const float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(fabs(area) > 0.0f)) return;
  const float inv = 1.0f / area;
  const int size = m->size;
  const int x0 = max(0, (int)floor(fmin(fmin(a.x, b.x), c.x) - 0.5f)),
            x1 = min(size - 1, (int)ceil(fmax(fmax(a.x, b.x), c.x) - 0.5f));
  const int y0 = max(0, (int)floor(fmin(fmin(a.y, b.y), c.y) - 0.5f)),
            y1 = min(size - 1, (int)ceil(fmax(fmax(a.y, b.y), c.y) - 0.5f));
  ShadowBatch B;
  B.n = 0;
  for (int y = y0 + row; y <= y1; y += rows) {
    const float py = (float)y + 0.5f;
    for (int x = x0; x <= x1; ++x) {
      const float px = (float)x + 0.5f;
      const float wa = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) * inv;
      const float wb = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) * inv;
      const float wc = 1.0f - wa - wb;
      if (wa < 0.0f || wb < 0.0f || wc < 0.0f) continue;
      const float q = wa * a.z + wb * b.z + wc * c.z;
      const float z = fmax(m->perspective ? 1.0f / q : q, 0.0f);
      const uint texel = (uint)y * (uint)size + (uint)x;
      if (opaque) {
        atomic_min(depth + m->offset + texel, as_uint(z));
        continue;
      }
      /* perspective-correct weights of the corners (1/z is linear in the map), then source barycentrics */
      const float3 w = m->perspective ? (float3)(wa * a.z, wb * b.z, wc * c.z) / q : (float3)(wa, wb, wc);
      const float3 sb = w.x * s[0] + w.y * s[1] + w.z * s[2];
      B.texel[B.n] = texel, B.z[B.n] = z, B.b[0][B.n] = sb.x, B.b[1][B.n] = sb.y, B.b[2][B.n] = sb.z;
      if (++B.n == SW) shadow_flush(in, m, tri, depth, &B);
    }
  }
  shadow_flush(in, m, tri, depth, &B);
}

/* Triangle t's corners in map m clipped to its near plane (poly, n of them), and whether it is opaque. */
inline int shadow_corners(const ShadeInputs* in, global const PmrShadowMap* m, uint t, ShadowCorner* poly,
                          bool* opaque) {
  const PmrTriangle tri = in->tris[t];
  global const PmrMaterial* mat = &in->materials[tri.material];
  *opaque = mat->alpha_mode == PMR_ALPHA_OPAQUE && !(mat->transmission > 0.0f);
  const float3 origin = vload3(0, m->origin);
  ShadowCorner c[3];
  for (int k = 0; k < 3; ++k) {
    const float3 d = vload3(tri.v[k], in->positions) - origin;
    c[k].c = (float3)(dot(vload3(0, m->right), d), dot(vload3(0, m->up), d), dot(vload3(0, m->axis), d));
    c[k].b = (float3)(k == 0, k == 1, k == 2);
  }
  if (m->perspective) return clip_near(c, m->near_z, poly);
  poly[0] = c[0], poly[1] = c[1], poly[2] = c[2];
  return 3;
}

/* Rows `row`, row + rows, ... of triangle t's clipped polygon (a fan) in map m. */
inline void shadow_rows(const ShadeInputs* in, global const PmrShadowMap* m, uint t, const ShadowCorner* poly, int n,
                        bool opaque, global uint* depth, int row, int rows) {
  for (int k = 1; k + 1 < n; ++k) {
    const float3 texel[3] = {shadow_texel(m, poly[0].c), shadow_texel(m, poly[k].c), shadow_texel(m, poly[k + 1].c)};
    const float3 source[3] = {poly[0].b, poly[k].b, poly[k + 1].b};
    shadow_triangle(in, m, t, opaque, depth, texel, source, row, rows);
  }
}

/* Texels of the bounding box of a clipped polygon in map m (0 when nothing is left). */
inline float shadow_box_texels(global const PmrShadowMap* m, const ShadowCorner* poly, int n) {
  if (n < 3) return 0.0f;
  float2 lo = (float2)(INFINITY), hi = (float2)(-INFINITY);
  for (int k = 0; k < n; ++k) {
    const float3 t = shadow_texel(m, poly[k].c);
    lo = fmin(lo, t.xy), hi = fmax(hi, t.xy);
  }
  const float size = (float)m->size;
  const float2 span = clamp(hi, 0.0f, size) - clamp(lo, 0.0f, size);
  return (span.x + 1.0f) * (span.y + 1.0f);
}

/* A caster whose bounding box holds more texels than this is rasterized by its whole work-group, row
 * by row: one work-item alone would hold the pass while the others wait (a ground plane covers most
 * of a map). */
#define PMR_SHADOW_SHARED_TEXELS 1024.0f
#define PMR_SHADOW_GROUP 64

/* One work-item per triangle of the frame's posed scene (the shading inputs' positions: world space)
 * into map `map` of the shading inputs' shadow maps, writing `depth` (the shadow_depth they read).
 * Work-groups of PMR_SHADOW_GROUP: small casters are rasterized by their own work-item, large ones by
 * the whole group together. */
kernel void shadow_raster(PMR_SHADE_PARAMS, uint map, global uint* depth) {
  const ShadeInputs inputs = PMR_SHADE_INPUTS;
  const ShadeInputs* in = &inputs;
  local uint shared[PMR_SHADOW_GROUP];
  local uint shared_count;
  const int lid = (int)get_local_id(0);
  if (lid == 0) shared_count = 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint t = pmr_item_id();
  global const PmrShadowMap* m = &shadow_maps[map];
  ShadowCorner poly[4];
  bool opaque = true;
  /* the ground catcher (--ground shadow) receives shadows and casts none */
  const bool caster = t < P->num_triangles && !(materials[tris[t].material].flags & PMR_MATERIAL_SHADOW_CATCHER);
  const int n = caster ? shadow_corners(in, m, t, poly, &opaque) : 0;
  if (shadow_box_texels(m, poly, n) > PMR_SHADOW_SHARED_TEXELS) shared[atomic_inc(&shared_count)] = t;
  else if (n >= 3) shadow_rows(in, m, t, poly, n, opaque, depth, 0, 1);
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint count = shared_count;
  for (uint k = 0; k < count; ++k) {
    const uint big = shared[k];
    const int bn = shadow_corners(in, m, big, poly, &opaque);
    shadow_rows(in, m, big, poly, bn, opaque, depth, lid, PMR_SHADOW_GROUP);
  }
}
