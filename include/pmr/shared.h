/* Structs and constants shared by the C++ host and the OpenCL C kernels.
 *
 * This header is compiled twice: as C++17 by the host (which static_asserts every size and offset in
 * host/runtime/layout_check.cpp) and as OpenCL C 1.2 by the device (the host embeds it into the program
 * source). Only 32-bit scalars, 64-bit doubles and fixed-size arrays of them are used, so the layout
 * is the same on both sides without packing pragmas.
 *
 * Fixed-point formats (DESIGN section 3):
 *   raster x: signed 16.16 (PMR_X_FRAC_BITS), range |x| < 2^15 px, stored in int32
 *   raster y: signed 24.8  (PMR_Y_FRAC_BITS), stored in int32
 * Edge functions are evaluated in int64: (dy)*(x - xA) is at most 2^23 * 2^32 = 2^55 in magnitude and
 * (dx)*(y - yA) the same, so a sum of two fits with room to spare.
 * x gets more fractional bits than y because the per-view disparity d is snapped on the same grid and
 * multiplied by up to N - 1 views: 16 bits keep x_0 + i*d within 0.002 px of the exact projection at
 * i = 95.
 *
 * View coordinates (host/rig/rig.cpp, docs/DESIGN.md): view i's x is x_0 + F_i d with an integer F_i
 * (PmrParams.view_coord). Linear spacing has F_i = i. Angular spacing has F_i = round(Q g_i), where g_i
 * is camera i's offset from the center camera in view spacings B / (N - 1); x_0 is then the center
 * camera's x and d the disparity per 1/Q view spacing. Every x_0 + F_i d, F_i of a real view, is a
 * vertex x in that view, inside the guard band, so the edge-function bound above holds as it is; the
 * view coordinate only adds the products F_i d (|F_i| <= PMR_MAX_VIEW_COORD, |d| < 2^31: below 2^45).
 * The snapping error of x_0 + F_i d is at most (1 + |F_i|) 2^-17 px, so at most 1/8 px.
 */
#ifndef PMR_SHARED_H
#define PMR_SHARED_H

#ifdef __OPENCL_VERSION__
typedef int pmr_i32;
typedef uint pmr_u32;
#else
#include <cstdint>
typedef int32_t pmr_i32;
typedef uint32_t pmr_u32;
#endif
#ifdef __OPENCL_VERSION__
typedef ulong pmr_u64;
#else
typedef uint64_t pmr_u64;
#endif

#define PMR_X_FRAC_BITS 16
#define PMR_Y_FRAC_BITS 8
#define PMR_X_ONE (1 << PMR_X_FRAC_BITS)
#define PMR_Y_ONE (1 << PMR_Y_FRAC_BITS)

/* Guard band: after clipping, every vertex satisfies |x_raster - W/2| <= PMR_GUARD_PX in every view
 * (and |y_raster - H/2| <= PMR_GUARD_PX), so |x| < 2^15 px fits 16.16 in int32 for W, H <= 2^13. */
#define PMR_GUARD_PX 16384.0
#define PMR_MAX_RASTER 8192

/* A display image's side in pixels: the encode kernels index its subpixels in 32 bits. */
#define PMR_MAX_DISPLAY_SIDE 16384
/* A side of the 3D tile (--tile XxYxV): the subpixel raster keeps a tile's x offsets in 16.16 below
 * 2^22 (cl/fine_subpixel.cl). */
#define PMR_MAX_TILE_SIDE 64
/* --sampling subpixel tests a view's samples this many at a time (one vector of doubles); the host pads
 * each view's run of samples to whole vectors when it sizes the chunks (host/pipeline/tile_tables.cpp). */
#define PMR_SUBPIXEL_LANES 8

/* Views of a rig, and the largest |view coordinate| (see above). PmrParams.view_coord has
 * PMR_VIEW_COORD_SLACK entries past the last view (copies of the last one), so that a 16-view vector
 * load at any view stays inside the struct. */
#define PMR_MAX_VIEWS 4096
#define PMR_MAX_VIEW_COORD (1 << 14)
#define PMR_VIEW_COORD_SLACK 16

/* A triangle clipped by near, far and the six guard-band planes has at most 3 + 8 vertices, i.e. a fan
 * of 9 triangles (the visibility key's sub-triangle index). */
#define PMR_MAX_CLIP_VERTS 11
/* Visibility key = (triangle index << PMR_KEY_SUB_BITS) | sub-triangle index; lower key wins ties. */
#define PMR_KEY_SUB_BITS 5
#define PMR_MAX_TRIANGLES (1u << (32 - PMR_KEY_SUB_BITS))
#define PMR_NO_KEY 0xffffffffu

/* Outcode bits of a vertex, computed once per vertex in clip space of the center camera. */
#define PMR_CLIP_NEAR (1u << 0)     /* w < near_eff              */
#define PMR_CLIP_FAR (1u << 1)      /* w > far                   */
#define PMR_CLIP_GUARD (0x3fu << 2) /* outside one of 6 guard-band planes (x in views 0 and N-1, y) */
#define PMR_CULL_LEFT (1u << 8)     /* left of every view's frustum  */
#define PMR_CULL_RIGHT (1u << 9)
#define PMR_CULL_BOTTOM (1u << 10)
#define PMR_CULL_TOP (1u << 11)
#define PMR_CULL_NEAR (1u << 12) /* same as PMR_CLIP_NEAR, kept in the cull set */
#define PMR_CULL_FAR (1u << 13)

/* Display pixels one encoder work-item handles (amortizes the device's per-work-item cost). */
#define PMR_ENCODE_RUN 16

/* Material alpha modes (glTF). */
#define PMR_ALPHA_OPAQUE 0
#define PMR_ALPHA_MASK 1
#define PMR_ALPHA_BLEND 2

/* PmrMaterial.flags: what the host found once, so that shading reads one word per winner */
#define PMR_MATERIAL_MAPS 1u     /* some map (PMR_MAP_*) is sampled                                 */
#define PMR_MATERIAL_SPECULAR 2u /* KHR_materials_specular changes the Fresnel term (a factor or a map) */
#define PMR_MATERIAL_ANISOTROPY 4u /* KHR_materials_anisotropy with a strength above 0               */
#define PMR_MATERIAL_IRIDESCENCE 8u /* KHR_materials_iridescence with a factor above 0               */
#define PMR_MATERIAL_SHEEN 16u      /* KHR_materials_sheen with a colour factor above 0              */
#define PMR_MATERIAL_SHADOW_CATCHER 32u /* --ground shadow's catcher (BLEND): black, of alpha the shadow
                                           cast on it; casts none (DESIGN section 4d)               */

/* Texture wrap modes (glTF sampler enums). */
#define PMR_WRAP_REPEAT 10497
#define PMR_WRAP_CLAMP 33071
#define PMR_WRAP_MIRROR 33648

/* Mta.flags */
#define PMR_MTA_BACK 1u /* back-facing in its view range (double-sided): shading flips the normal */
#define PMR_MTA_MASK 2u /* material uses alphaMode MASK: visibility must evaluate alpha */
#define PMR_MTA_TRANSMISSIVE 4u /* pbr, KHR_materials_transmission: left out of the opaque pass (PmrSource) */
#define PMR_MTA_BLEND 8u /* alphaMode BLEND (not transmissive): composited over the opaque result (DESIGN 4c) */

/* PmrParams.setup_mode: one MTA per orientation range (PMR), or one single-view MTA per view
 * (the geometry-duplication baseline). */
#define PMR_SETUP_MTA 0u
#define PMR_SETUP_DUPLICATE 1u

/* PmrParams.shading (docs/SHADING.md): view-independent Lambert, or glTF metallic-roughness. */
#define PMR_SHADING_LAMBERT 0u
#define PMR_SHADING_PBR 1u

/* The split-sum table of --shading pbr (host/shading/environment.h): (A, B) pairs, node (i, j) at
 * cos(n, v) = (i / (N - 1))^2 and roughness j / (N - 1), stored at j * N + i. */
#define PMR_SPLIT_SUM_N 64
/* The area lights' LTC table (cl/area_lights.h): PMR_LTC_N^2 nodes of PMR_LTC_NODE_FLOATS floats. */
#define PMR_LTC_N 64
#define PMR_LTC_NODE_FLOATS 10

/* KHR_materials_sheen (host/shading/sheen.h): the sheen roughness is clamped to
 * [PMR_SHEEN_MIN_ROUGHNESS, 1]; the table of the Charlie lobe's directional albedo E has
 * PMR_SHEEN_ALBEDO_N^2 nodes, node (i, j) at cos(n, v) = (i / (N - 1))^2 and roughness
 * PMR_SHEEN_MIN_ROUGHNESS + (1 - PMR_SHEEN_MIN_ROUGHNESS) j / (N - 1), stored at j * N + i. */
#define PMR_SHEEN_MIN_ROUGHNESS 0.07f
#define PMR_SHEEN_ALBEDO_N 32
/* The sheen reads n.v at least this: at n.v = 0 exactly its visibility's clamp makes the lobe and its
 * albedo jump to 1.2 to 2.4 times their values just above (host/shading/sheen.h). */
#define PMR_SHEEN_MIN_COS 1e-4f

/* PmrParams.texture_filter (--texture-filter): level 0 alone, bilinear (the textures have no mips);
 * or trilinear between the mip levels around the analytic level of detail (DESIGN section 3b). */
#define PMR_FILTER_BILINEAR 0u
#define PMR_FILTER_TRILINEAR 1u

/* PmrParams.sample_area: where the samples of a raster pixel lie, for the tile raster's conservative
 * tests. --sampling view samples around pixel centers; --sampling subpixel samples each display
 * subpixel around its own position, anywhere in [px, px + 1) x [py, py + 1) of its view's raster. Either
 * way a pixel's S samples lie at the offsets PmrParams.sample_x/y from that point. */
#define PMR_SAMPLES_CENTER 0u
#define PMR_SAMPLES_PIXEL 1u

/* Samples per pixel (--samples S, DESIGN section 3b): S positions inside every pixel of every view, the
 * same in every view: the center for S = 1, else Direct3D's standard multisample patterns, as offsets
 * (x, y) from the pixel center in 1/16 pixel, +y down. PmrParams.sample_x/y hold them in the raster's
 * fixed point. */
#define PMR_MAX_SAMPLES 16
#define PMR_SAMPLE_PATTERN_1 \
  { 0, 0 }
#define PMR_SAMPLE_PATTERN_4 \
  { -2, -6, 6, -2, -6, 2, 2, 6 }
#define PMR_SAMPLE_PATTERN_8 \
  { 1, -3, -1, 3, 5, 1, -3, -5, -5, 5, -7, -1, 3, 7, 7, -7 }
#define PMR_SAMPLE_PATTERN_16 \
  { 1, 1, -1, -3, -3, 2, 4, -1, -5, -2, 2, 5, 5, 3, 3, -5, -2, 6, 0, -7, -4, -6, -6, 4, -8, 0, 7, -4, 6, 7, -7, -8 }

/* PmrLight.type: KHR_lights_punctual's three kinds, and EXT_lights_area's two (DESIGN section 4d). */
#define PMR_LIGHT_DIRECTIONAL 0
#define PMR_LIGHT_POINT 1
#define PMR_LIGHT_SPOT 2
#define PMR_LIGHT_RECT 3
#define PMR_LIGHT_DISK 4

/* Frame parameters, one copy per frame, read by every stage. Producer: host/pipeline. */
typedef struct {
  double view[16];                   /* center camera view matrix, column-major (world -> center view space) */
  double ndc_scale_x;                /* x_ndc(center) = ndc_scale_x * x_view / w, = D / a              */
  double ndc_scale_y;                /* y_ndc = ndc_scale_y * y_view / w, = 1 / tan(phi / 2)           */
  double disparity_k;                /* Delta(w) = disparity_k * (1 - D / w), px; = W tan(theta/2) / (A tan(phi/2)) */
  double focal;                      /* D, focal (zero-parallax) distance                              */
  double near_eff;                   /* near plane actually used (>= user near, see rig.cpp)           */
  double far;                        /* far plane                                                      */
  double guard_ndc_x;                /* guard band half-width in NDC x: PMR_GUARD_PX / (W / 2)         */
  double guard_ndc_y;                /* guard band half-height in NDC y                                */
  double ndc_offset_x;               /* added to x_ndc: s_i / a for a multipass view, 0 for PMR        */
  float light_world[4];              /* unit vector toward the light, world space (xyz, w unused)      */
  pmr_i32 view_w, view_h;            /* view raster size (px)                                          */
  pmr_i32 views;                     /* N                                                              */
  pmr_i32 tiles_x, tiles_y, tiles_v; /* tile grid size                                      */
  pmr_u32 num_vertices, num_triangles;
  pmr_u32 mta_capacity;              /* size of the MTA queue; setup counts past it and stops writing   */
  pmr_u32 debug_outputs;             /* 1: fine raster writes per-voxel key, depth and coverage count   */
  pmr_u32 view_base;                 /* volume slice of local view 0 (multipass renders one view a pass) */
  pmr_u32 setup_mode;                /* PMR_SETUP_MTA or PMR_SETUP_DUPLICATE                            */
  pmr_u32 sample_area;               /* PMR_SAMPLES_CENTER or PMR_SAMPLES_PIXEL                          */
  pmr_u32 shading;                   /* PMR_SHADING_LAMBERT or PMR_SHADING_PBR                           */
  float exposure;                    /* 2^EV: scales the colour of either model                          */
  float env_radiance;                /* pbr: radiance of the uniform default environment (0.2 x intensity) */
  pmr_u32 num_lights;                /* pbr: entries of the light table (PmrLight), the kernels' last argument */
  pmr_u32 samples;                   /* S samples per pixel (PMR_SAMPLE_PATTERN_S); the kernels are built for it */
  pmr_u32 texture_filter;            /* PMR_FILTER_BILINEAR or PMR_FILTER_TRILINEAR (DESIGN section 3b)   */
  float lod_scale_x, lod_scale_y;    /* view pixels per output pixel, x and y: 1 for view sampling; the
                                        display pixel's footprint in view pixels for subpixel sampling */
  pmr_u32 env_occlusion;              /* pbr, shadows on: 1 when the light table holds one more entry,
                                        lights[num_lights], whose maps give the environment's
                                        occlusion (cl/lights.h environment_visibility_lanes) */
  pmr_u32 clear_glass;               /* pbr, a transparent background: the light through glass that left the
                                        scene is not drawn and lowers alpha instead (DESIGN 4c) */
  pmr_u32 pad_params;                /* keeps sample_x and the doubles after it where they align      */
  pmr_i32 sample_x[PMR_MAX_SAMPLES]; /* sample s at (X + sample_x[s], Y + sample_y[s]) from pixel center */
  pmr_i32 sample_y[PMR_MAX_SAMPLES]; /* (X, Y), in 16.16 / 24.8 raster units                          */
  double view_anchor;                /* camera offset at view coordinate 0 over the baseline: -1/2 linear, 0 angular */
  double view_scale;                 /* view coordinate units per baseline: N - 1 linear, Q (N - 1) angular */
  pmr_i32 view_coord[PMR_MAX_VIEWS + PMR_VIEW_COORD_SLACK]; /* F_i, strictly increasing in i (a
                             multipass pass: its one view at 0) */
} PmrParams;

/* Vertex-stage output, one per scene vertex. Producer: cl/vertex.cl. */
typedef struct {
  double pos_view[3]; /* position in center-camera view space (used by the clipper)      */
  double pad;
  pmr_i32 x0;      /* snapped raster x at view coordinate 0, 16.16 (view 0 if linear)  */
  pmr_i32 dx;      /* snapped disparity per view coordinate, 16.16: x_i = x0 + F_i dx  */
  pmr_i32 y;       /* snapped raster y, 24.8                                          */
  pmr_u32 outcode; /* PMR_CLIP_* | PMR_CULL_* bits                                    */
  float z;         /* window depth in [0, 1] (glFrustum depth mapped from NDC)         */
  float inv_w;     /* 1 / w_clip                                                      */
  float pad1, pad2;
} PmrVertex;

/* Multi-view triangle: one (possibly clipped) triangle over a contiguous view range with constant
 * orientation. Producer: cl/setup.cl. Consumers: cl/bin.cl, cl/fine.cl. */
typedef struct {
  pmr_i32 x0[3];            /* vertex raster x at view coordinate 0, 16.16                     */
  pmr_i32 dx[3];            /* disparity per view coordinate, 16.16                            */
  pmr_i32 y[3];             /* raster y, 24.8                                                  */
  float z[3];               /* window depth                                                    */
  float inv_w[3];           /* 1 / w                                                           */
  float bary[3][2];         /* each vertex's barycentrics (b1, b2) in the source triangle        */
  pmr_u32 tri;              /* source triangle index                                           */
  pmr_u32 key;              /* visibility tie-break key (see PMR_KEY_SUB_BITS)                  */
  pmr_i32 view_lo, view_hi; /* inclusive view range in which the MTA is rasterized          */
  pmr_i32 sign;             /* +1 or -1: multiplies the edge functions so that inside is >= 0   */
  pmr_u32 flags;            /* PMR_MTA_*                                                       */
} PmrMta;

/* Per-vertex shading attributes. Producer: host (scene flattening). */
typedef struct {
  float normal[3]; /* world-space unit normal (unused when the triangle has none)     */
  float color[4];  /* COLOR_0 (linear), (1,1,1,1) when absent                         */
  float scale;     /* the uniform scale of its world transform, |det M3|^(1/3) (the skin's
                      blend if skinned): KHR_materials_volume's thickness is in the node's units */
} PmrVertexAttr;

/* Per-triangle data. Producer: host. */
typedef struct {
  pmr_u32 v[3]; /* vertex indices, counter-clockwise = front                        */
  pmr_u32 material;
  float face_normal[3]; /* world-space unit face normal (used when has_normals == 0)        */
  pmr_u32 has_normals;
} PmrTriangle;

/* The texture maps of a material (PmrMaterial.maps), in the order of the scene's texture slots
 * (SceneTextureSlotKind). Both shading models read the base colour map; only --shading pbr reads the
 * others. */
#define PMR_MAP_BASE_COLOR 0         /* RGBA (RGB sRGB-encoded, alpha linear)                  */
#define PMR_MAP_METALLIC_ROUGHNESS 1 /* B metallic, G roughness (linear)                       */
#define PMR_MAP_NORMAL 2             /* tangent-space normal (linear)                          */
#define PMR_MAP_OCCLUSION 3          /* R occlusion (linear)                                   */
#define PMR_MAP_EMISSIVE 4           /* RGB (sRGB-encoded)                                     */
#define PMR_MAP_TRANSMISSION 5       /* R transmission (KHR_materials_transmission, linear)     */
#define PMR_MAP_THICKNESS 6          /* G thickness (KHR_materials_volume, linear)              */
#define PMR_MAP_CLEARCOAT 7          /* R clear coat intensity (KHR_materials_clearcoat, linear)  */
#define PMR_MAP_CLEARCOAT_ROUGHNESS 8 /* G clear coat roughness (linear)                         */
#define PMR_MAP_CLEARCOAT_NORMAL 9   /* the clear coat's tangent-space normal (linear)          */
#define PMR_MAP_SPECULAR 10          /* A specular weight (KHR_materials_specular, linear)      */
#define PMR_MAP_SPECULAR_COLOR 11    /* RGB specular colour (sRGB-encoded)                      */
#define PMR_MAP_ANISOTROPY 12        /* RG direction, B strength (KHR_materials_anisotropy, linear) */
#define PMR_MAP_IRIDESCENCE 13       /* R iridescence factor (KHR_materials_iridescence, linear) */
#define PMR_MAP_IRIDESCENCE_THICKNESS 14 /* G thin-film thickness between the minimum and maximum    */
#define PMR_MAP_SHEEN_COLOR 15       /* RGB sheen colour (KHR_materials_sheen, sRGB-encoded)     */
#define PMR_MAP_SHEEN_ROUGHNESS 16   /* A sheen roughness (linear)                              */
#define PMR_MAPS 17

/* One texture map of a material: which texture, sampled at which TEXCOORD set, through which
 * KHR_texture_transform (the identity without one). Producer: host/pipeline (from the scene's material
 * inputs). */
typedef struct {
  pmr_i32 texture;       /* index into the texture table, -1 = none                         */
  pmr_u32 texcoord;      /* TEXCOORD set: entries [texcoord * num_vertices, ...) of the texcoord buffer */
  float uv_transform[6]; /* u' = t0 u + t1 v + t2, v' = t3 u + t4 v + t5                     */
} PmrTextureMap;

typedef struct {
  float base_color[4]; /* baseColorFactor (linear)                                        */
  pmr_i32 alpha_mode;  /* PMR_ALPHA_*                                                     */
  float alpha_cutoff;
  pmr_u32 double_sided;
  float metallic;               /* metallicFactor (pbr)                                             */
  float roughness;              /* roughnessFactor (pbr; clamped to [0.03, 1] when shading)          */
  float emissive[3];            /* emissiveFactor x KHR_materials_emissive_strength (pbr, linear)    */
  pmr_u32 unlit;                /* KHR_materials_unlit (pbr): the colour is exposure x base          */
  PmrTextureMap maps[PMR_MAPS]; /* indexed by PMR_MAP_*                                           */
  float normal_scale;           /* normalTexture.scale                                             */
  float occlusion_strength;     /* occlusionTexture.strength                                     */
  float f0_dielectric;          /* F0 of the dielectric part: ((ior - 1) / (ior + 1))^2 for
                                   KHR_materials_ior (0.04 for the default 1.5; 1 for ior 0)       */
  float ior;                    /* KHR_materials_ior (1.5 without it): bends the refracted ray      */
  float transmission;           /* KHR_materials_transmission transmissionFactor (0: opaque)       */
  float thickness;              /* KHR_materials_volume thicknessFactor x the node's scale (0: thin) */
  float attenuation_distance;   /* KHR_materials_volume (+inf: none)                               */
  float attenuation_color[3];   /* KHR_materials_volume (linear)                                   */
  float clearcoat;              /* KHR_materials_clearcoat clearcoatFactor (0: no coat)             */
  float clearcoat_roughness;    /* ... clearcoatRoughnessFactor                                    */
  float clearcoat_normal_scale; /* ... clearcoatNormalTexture.scale                                */
  float specular;               /* KHR_materials_specular specularFactor (1 without it)             */
  float specular_color[3];      /* ... specularColorFactor (linear; (1, 1, 1) without it)          */
  pmr_u32 flags;                /* PMR_MATERIAL_*, set with the maps (host/pipeline/material_tables.cpp) */
  float anisotropy[3];          /* KHR_materials_anisotropy: strength, cos and sin of the rotation */
  float iridescence[4];         /* KHR_materials_iridescence: factor, ior, thickness min and max (nm) */
  float sheen[4];               /* KHR_materials_sheen: colour factor (linear RGB), roughness factor */
} PmrMaterial;

/* A texture and its mip chain: `levels` levels back to back from `offset`, level k of
 * max(1, width >> k) x max(1, height >> k) texels (so level k starts at offset + the sizes of levels
 * 0..k-1). levels is 1 without mips (--texture-filter bilinear). */
typedef struct {
  pmr_u32 offset; /* first texel of level 0 in the texel buffer (RGBA8, sRGB-encoded colour) */
  pmr_i32 width, height; /* level 0                                                      */
  pmr_i32 wrap_s, wrap_t; /* PMR_WRAP_*                                                      */
  pmr_u32 levels;         /* mip levels stored, >= 1                                         */
  pmr_u32 pad1, pad2;
} PmrTexture;

/* One punctual light of --shading pbr, world space, as resolved for the frame (the file's
 * KHR_lights_punctual lights, posed, or the default light; host/shading/lights.h). Producer: host, every
 * frame. cl/brdf.h light_irradiance() evaluates it. */
typedef struct {
  float color[3];     /* colour x intensity, linear: lux (directional), candela (point, spot) or nits
                         (rect, disk: the luminance of the emitting side) */
  pmr_u32 type;       /* PMR_LIGHT_*                                                      */
  float position[3];  /* the light's origin (point, spot)                                  */
  float range;        /* point, spot: the distance window's range; 0 = none                */
  float direction[3]; /* unit: the direction the light travels (its node's -Z); the direction
                             toward a directional light is -direction (directional, spot)      */
  float cos_inner;    /* spot: cos(innerConeAngle)                                         */
  float cos_outer;    /* spot: cos(outerConeAngle)                                         */
  pmr_i32 shadow;     /* its first shadow map (PmrShadowMap), -1: unshadowed (--shadows off) */
  pmr_i32 shadow_maps; /* its maps: shadow_samples groups of 1, or of 6 (a cube: the face of the major axis) */
  pmr_i32 shadow_samples; /* a light with a size: the points (or directions) sampled on it, whose hard
                             visibilities are averaged; 1 for a point-like light */
  float half_width[3];    /* rect, disk: the half extents of the emitting shape along its plane's axes */
  pmr_u32 distant;        /* (world space; a disk's are equal: its radius), centred on `position`, */
  float half_height[3];   /* emitting along `direction` (= half_height x half_width, normalized)   */
  pmr_u32 pad1;
  /* distant (1): a patch of directions at infinity (SceneLight::distant): `position` is the unit
     direction toward its centre, the shape lies on the plane tangent to the unit sphere there and
     is seen alike from every point */
} PmrLight;

/* One shadow map (DESIGN section 4d), rendered once per frame and read by every view: depth along
 * `axis` from `origin` of the nearest caster over size x size texels of float depth (as uint bits), at
 * `offset` in the depth buffer. A point q maps to d = q - origin, z = axis . d, and
 * (s, t) = (right . d, up . d) / (perspective ? z : 1), in [-1, 1] over the map (right and up are
 * scaled: 1 / half extent, or 1 / tan(half angle)). texel: a texel's world size, at z = 1 when
 * perspective. Producer: host/pipeline/shadow_stage.cpp, every frame. */
typedef struct {
  float origin[3];
  pmr_u32 offset;
  float right[3];
  pmr_i32 size;
  float up[3];
  pmr_u32 perspective;
  float axis[3];
  float texel;
  float near_z;        /* perspective: casters nearer than this are clipped */
  pmr_u32 translucent; /* PMR_NO_TRANSLUCENT, or where its translucent casters' pairs start in the depth
                          buffer: per texel the nearest one's depth and the sum of -ln(1 - opacity) of
                          all, in units of 1 / PMR_SHADOW_OPTICAL_ONE */
  float weight;        /* an environment occlusion map: the environment's radiance about its direction
                          (luminance); a light's map: 1 */
  pmr_u32 pad2;
} PmrShadowMap;
#define PMR_NO_TRANSLUCENT 0xffffffffu
#define PMR_SHADOW_OPTICAL_ONE 4096.0f /* -ln(1 - a) per caster at most 40: 26,000 layers fit 32 bits */

/* Encoder parameters (DESIGN section 5): sizes and flags. The subpixel-to-view map itself is in the
 * tables below, computed exactly by the host (host/rig/display.cpp). */
typedef struct {
  pmr_i32 display_w, display_h;
  pmr_i32 views;
  pmr_i32 view_w, view_h;
  pmr_i32 reversed;  /* 1: v -> N - 1 - v                                                 */
  pmr_i32 bilinear;  /* 1: bilinear sampling of the view, 0: nearest                     */
  pmr_i32 blend;     /* 1: blend views v and v + 1 by the phase's fraction (Looking Glass's
                             webxr filter mode 1), 0: one view per subpixel                     */
  pmr_i32 cell_rows; /* subpixel cells: the column table has one block of 3 W_d entries per
                             row class (H_d - 1 - i) mod cell_rows; 1 without cells            */
  pmr_i32 pad0, pad1, pad2;
} PmrEncodeParams;

/* Encoder tables, computed once per configuration by the host (host/rig/display.cpp). With
 * N t = (P_s - R_i) / Den exactly (s = 3j + k), P_s = A_s Den + rP_s and R_i = Q_i Den + rR_i
 * (0 <= r < Den): floor(N t) = A_s - Q_i - (rP_s < rR_i), so the view of a subpixel needs no division:
 * v = (A_s mod N) - (Q_i mod N) - (B_s < S_i), plus N if negative, where B_s and S_i are the ranks of
 * the wide remainders rP_s and rR_i among all of them (same order, ties kept). */
typedef struct {
  pmr_i32 a_mod_n;  /* A_s mod N                                                      */
  pmr_i32 b;        /* B_s: rank of the column's remainder                             */
  pmr_i32 px;       /* nearest view column: floor((2s + 1) W / (6 W_d))                 */
  float phase_frac; /* rP_s / Den as a float: the phase's fraction, for view blending    */
} PmrEncodeColumn;

typedef struct {
  pmr_i32 q_mod_n;  /* Q_i mod N                                                      */
  pmr_i32 s;        /* S_i: rank of the row's remainder                                */
  pmr_i32 py;       /* nearest view row: floor((2i + 1) H / (2 H_d))                    */
  float phase_frac; /* rR_i / Den as a float                                           */
} PmrEncodeRow;

/* --sampling subpixel: a block of display subpixels whose samples all lie in one screen tile (the
 * view raster's PMR_TILE_X x PMR_TILE_Y pixels, over all views): columns s = 3j + k in [s0, s1), display
 * rows [i0, i1). Blocks split a tile's subpixels at display-pixel boundaries, so a display pixel is cut
 * only where its subpixels' samples fall in different tiles. Producer: host/pipeline. */
typedef struct {
  pmr_i32 tile;   /* screen tile index ty * tiles_x + tx                              */
  pmr_i32 s0, s1; /* subpixel columns                                                */
  pmr_i32 i0, i1; /* display rows                                                    */
  pmr_i32 pad0, pad1, pad2;
} PmrSampleChunk;

/* --shading pbr with an environment image (--environment): where the prefiltered tables lie in the
 * environment data buffer (host/shading/environment.h describes the tables, the mapping and how they
 * are sampled; its Environment::level_sample, irradiance, prefiltered and sheen are the kernels' lookups
 * in double precision). Producer: host/shading/environment.cpp; the pipeline uploads it and the float
 * data. level_count == 0 (no image) selects the uniform default environment, which reads no table.
 * levels[0, level_count): the image and its GGX-prefiltered levels; levels[sheen_first + k],
 * k < PMR_SHEEN_LEVELS: the Charlie-prefiltered levels (KHR_materials_sheen) of sheen roughness
 * PMR_SHEEN_MIN_ROUGHNESS^(1 - k / (PMR_SHEEN_LEVELS - 1)), evenly spaced in log(roughness) up to 1. */
#define PMR_ENV_MAX_LEVELS 32
#define PMR_SHEEN_LEVELS 16
typedef struct {
  pmr_u32 width, height; /* texels                                                          */
  pmr_u32 offset;        /* float offset of the level's first row, the north pole row: texel (j, i)
                            is at offset + 4 ((i + 1) width + j), rows -1 and height the pole rows */
  float roughness;       /* r of this level (level 0: 0, the image)                          */
} PmrEnvLevel;

typedef struct {
  pmr_u32 level_count;              /* GGX levels (level 0 = the image, the last r = 1); 0 = no image */
  pmr_u32 roughness_nodes;          /* nodes of c(r), the fractional level coordinate, at r = i / (nodes - 1) */
  pmr_u32 roughness_offset;         /* float offset of c(r)                                        */
  pmr_u32 split_sum_size;           /* the split-sum table (PMR_SPLIT_SUM_N)                        */
  pmr_u32 split_sum_offset;         /* float offset of its (A, B) pairs                             */
  pmr_u32 sheen_first;              /* the first Charlie-prefiltered level (= level_count)          */
  float intensity;                  /* multiplies every radiance read (0 = off)                     */
  float rotation_cos, rotation_sin; /* of the map's rotation (counter-clockwise seen from above) */
  pmr_u32 pad[3];                   /* the levels 16-byte aligned: each lane's lookup reads its level's */
  PmrEnvLevel levels[PMR_ENV_MAX_LEVELS];
} PmrEnvironment;

/* pbr with transmissive surfaces (DESIGN section 4c step 2): the transmission source, each view's opaque
 * image (premultiplied half RGBA, the volume's layout) with a mip chain. Level k holds every view at
 * max(1, W >> k) x max(1, H >> k) texels from texel level_offset[k] ([view][y][x], 4 halves a texel); each
 * level is the 2x2 box mean of the one before (the last row or column of an odd side is left out).
 * Producer: host/pipeline/transmission_stage.cpp, one copy per pass: the opaque pass has opaque_only 1
 * (transmissive MTAs are skipped, no level is read), the full pass levels > 0. levels 0 and opaque_only 0:
 * a frame without transmission. */
#define PMR_SOURCE_MAX_LEVELS 16
typedef struct {
  pmr_u64 level_offset[PMR_SOURCE_MAX_LEVELS];
  pmr_u32 levels;      /* levels stored (0: none)                                          */
  pmr_u32 opaque_only; /* 1: this pass draws the opaque image: transmissive MTAs are skipped */
  pmr_u32 pad0, pad1;
} PmrSource;

#endif /* PMR_SHARED_H */
