// Compile-time check that the structs in include/pmr/shared.h have the layout the kernels assume
// (OpenCL C aligns every scalar to its size, as x86-64 C++ does; these asserts catch a field added
// without thinking about padding). tests/test_layout.cpp checks the device side at run time.
#include <cstddef>

#include "pmr/shared.h"

static_assert(sizeof(PmrParams) == 16 * 8 + 9 * 8 + 16 + 24 * 4 + 2 * PMR_MAX_SAMPLES * 4 + 2 * 8 +
                                       4 * (PMR_MAX_VIEWS + PMR_VIEW_COORD_SLACK),
              "PmrParams layout");
static_assert(offsetof(PmrParams, sample_x) == 312 && offsetof(PmrParams, view_anchor) == 440 &&
                  offsetof(PmrParams, view_coord) == 456 && offsetof(PmrParams, lod_scale_x) == 292 &&
                  offsetof(PmrParams, clear_glass) == 304,
              "PmrParams layout");
static_assert(offsetof(PmrParams, light_world) == 200, "PmrParams layout");
static_assert(offsetof(PmrParams, view_w) == 216, "PmrParams layout");
static_assert(sizeof(PmrVertex) == 64 && offsetof(PmrVertex, x0) == 32 && offsetof(PmrVertex, z) == 48,
              "PmrVertex layout");
static_assert(sizeof(PmrMta) == 27 * 4, "PmrMta layout");
static_assert(offsetof(PmrMta, bary) == 60 && offsetof(PmrMta, tri) == 84 && offsetof(PmrMta, flags) == 104,
              "PmrMta layout");
static_assert(sizeof(PmrVertexAttr) == 32 && offsetof(PmrVertexAttr, color) == 12, "PmrVertexAttr layout");
static_assert(sizeof(PmrTriangle) == 32, "PmrTriangle layout");
static_assert(sizeof(PmrMaterial) == 52 + PMR_MAPS * 32 + 116 && offsetof(PmrMaterial, maps) == 52 &&
                  offsetof(PmrMaterial, attenuation_color) == 52 + PMR_MAPS * 32 + 28 &&
                  offsetof(PmrMaterial, clearcoat) == 52 + PMR_MAPS * 32 + 40 &&
                  offsetof(PmrMaterial, specular_color) == 52 + PMR_MAPS * 32 + 56,
              "PmrMaterial layout");
static_assert(sizeof(PmrSource) == 8 * PMR_SOURCE_MAX_LEVELS + 16 && offsetof(PmrSource, opaque_only) == 132,
              "PmrSource layout");
static_assert(sizeof(PmrTextureMap) == 32, "PmrTextureMap layout");
static_assert(sizeof(PmrTexture) == 32 && offsetof(PmrTexture, levels) == 20, "PmrTexture layout");
static_assert(sizeof(PmrEncodeParams) == 48 && offsetof(PmrEncodeParams, display_w) == 0, "PmrEncodeParams layout");
static_assert(sizeof(PmrEncodeColumn) == 16 && sizeof(PmrEncodeRow) == 16, "encoder table layout");
static_assert(sizeof(PmrSampleChunk) == 32, "PmrSampleChunk layout");
static_assert(sizeof(PmrEnvLevel) == 16 && offsetof(PmrEnvLevel, roughness) == 12, "PmrEnvLevel layout");
static_assert(sizeof(PmrEnvironment) == 48 + 16 * PMR_ENV_MAX_LEVELS && offsetof(PmrEnvironment, intensity) == 24 &&
                  offsetof(PmrEnvironment, levels) == 48,
              "PmrEnvironment layout");
static_assert(offsetof(PmrParams, num_lights) == 280, "PmrParams layout");
static_assert(sizeof(PmrLight) == 96 && offsetof(PmrLight, half_width) == 64 && offsetof(PmrLight, half_height) == 80 &&
                  offsetof(PmrLight, type) == 12 && offsetof(PmrLight, range) == 28 &&
                  offsetof(PmrLight, direction) == 32 && offsetof(PmrLight, cos_outer) == 48,
              "PmrLight layout");
static_assert(sizeof(PmrShadowMap) == 80 && offsetof(PmrShadowMap, offset) == 12 &&
                  offsetof(PmrShadowMap, size) == 28 && offsetof(PmrShadowMap, perspective) == 44 &&
                  offsetof(PmrShadowMap, texel) == 60 && offsetof(PmrShadowMap, near_z) == 64,
              "PmrShadowMap layout");
