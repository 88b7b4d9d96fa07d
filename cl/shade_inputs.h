/* The shading module's inputs (docs/SHADING.md): the buffers every kernel that shades takes first, and
 * the one struct the module reads them through. Part of the one shading module (cl/shade.h). */
#ifndef PMR_CL_SHADE_INPUTS_H
#define PMR_CL_SHADE_INPUTS_H

#include "common.h"
#include "lanes.h"

/* The shading inputs: the leading parameters of every kernel that shades, bound in this order by the
 * host (SceneBuffers::bind_shading, host/pipeline/scene_buffers.cpp), and gathered into one ShadeInputs
 * by PMR_SHADE_INPUTS. A new input is one entry in each of the three lists and in the struct. */
#define PMR_SHADE_PARAMS                                                                                   \
  global const PmrParams *P, global const PmrTriangle *tris, global const PmrVertexAttr *attrs,            \
      global const PmrMaterial *materials, global const PmrTexture *textures, global const uchar4 *texels, \
      global const float *srgb_lut, global const float *positions, global const float4 *eyes,              \
      global const float2 *split_sum, global const float *ltc, global const float *sheen_albedo, global const float2 *texcoords,    \
      global const float4 *tangents, global const PmrEnvironment *env, global const float4 *env_data,      \
      global const PmrLight *lights, global const PmrShadowMap *shadow_maps, global const uint *shadow_depth, \
      global const half *source, global const PmrSource *source_info, global uint *source_tiles
#define PMR_SHADE_INPUTS                                                                                        \
  {                                                                                                             \
    tris, attrs, materials, textures, texels, srgb_lut, P, positions, eyes, split_sum, ltc, sheen_albedo, texcoords, \
        tangents, env, env_data, lights, shadow_maps, shadow_depth, source, source_info, source_tiles           \
  }

typedef struct {
  global const PmrTriangle* tris;
  global const PmrVertexAttr* attrs;
  global const PmrMaterial* materials;
  global const PmrTexture* textures;
  global const uchar4* texels;
  global const float* srgb_lut;
  global const PmrParams* P;
  global const float* positions;       /* world space, 3 floats per vertex: the surface point (pbr)  */
  global const float4* eyes;           /* each view's camera position, world space (pbr)            */
  global const float2* split_sum;      /* PMR_SPLIT_SUM_N^2 (A, B) (see PMR_SPLIT_SUM_N)             */
  global const float* ltc;             /* the area lights' LTC fit, PMR_LTC_N^2 nodes (cl/area_lights.h) */
  global const float* sheen_albedo;    /* PMR_SHEEN_ALBEDO_N^2 E (see PMR_SHEEN_ALBEDO_N)            */
  global const float2* texcoords;      /* TEXCOORD set k of vertex v at k * num_vertices + v (the maps) */
  global const float4* tangents;       /* world tangent per vertex (w: bitangent sign), pbr normal maps */
  global const PmrEnvironment* env;    /* pbr: the environment image's tables, level_count 0 = none */
  global const float4* env_data;       /* ... their data (cl/environment.h)                        */
  global const PmrLight* lights;       /* P->num_lights punctual lights, world space (pbr)           */
  global const PmrShadowMap* shadow_maps; /* the lights' shadow maps (PmrLight.shadow), and their  */
  global const uint* shadow_depth;        /* ... depths (cl/shadow.cl), this frame's               */
  global const half* source;           /* pbr: the transmission source (cl/transmission.h)           */
  global const PmrSource* source_info; /* ... its levels, and whether this is the opaque pass       */
  global uint* source_tiles;           /* ... per 3D tile: 1 if the opaque pass left a transmissive MTA out  */
} ShadeInputs;

/* 0 in programs that never see alphaMode BLEND (the fused raster + encode: the host renders BLEND
 * scenes through the view volume), which then carry none of its per-lane work. */
#ifndef PMR_WITH_BLEND
#define PMR_WITH_BLEND 1
#endif

#define LANE3(a) s3(vload_s(0, (a)[0]), vload_s(0, (a)[1]), vload_s(0, (a)[2]))

#endif
