/* Test-only kernel: reports the device-side size and field offsets of the shared structs, which
 * tests/test_layout.cpp compares with the host's. Not part of the rendering program. */
#include "common.h"

#define PROBE(i, type, field) out[i] = (uint) __builtin_offsetof(type, field)

kernel void layout_probe(global uint* out) {
  out[0] = sizeof(PmrParams);
  PROBE(1, PmrParams, ndc_scale_x);
  PROBE(2, PmrParams, light_world);
  PROBE(3, PmrParams, view_w);
  PROBE(4, PmrParams, debug_outputs);
  out[5] = sizeof(PmrVertex);
  PROBE(6, PmrVertex, x0);
  PROBE(7, PmrVertex, z);
  out[8] = sizeof(PmrMta);
  PROBE(9, PmrMta, bary);
  PROBE(10, PmrMta, key);
  PROBE(11, PmrMta, flags);
  out[12] = sizeof(PmrVertexAttr);
  PROBE(13, PmrVertexAttr, color);
  out[14] = sizeof(PmrTriangle);
  PROBE(15, PmrTriangle, face_normal);
  out[16] = sizeof(PmrMaterial);
  PROBE(17, PmrMaterial, alpha_cutoff);
  out[18] = sizeof(PmrTexture);
  PROBE(19, PmrTexture, wrap_t);
  out[20] = sizeof(PmrEncodeParams);
  PROBE(21, PmrEncodeParams, display_w);
  PROBE(22, PmrEncodeParams, bilinear);
  PROBE(23, PmrMaterial, maps);
  PROBE(24, PmrMaterial, occlusion_strength);
  out[25] = sizeof(PmrTextureMap);
  PROBE(26, PmrParams, num_lights);
  out[27] = sizeof(PmrLight);
  PROBE(28, PmrLight, type);
  PROBE(29, PmrLight, range);
  PROBE(30, PmrLight, direction);
  PROBE(31, PmrLight, cos_outer);
  out[40] = sizeof(PmrEnvironment);
  PROBE(41, PmrEnvironment, intensity);
  PROBE(42, PmrEnvironment, levels);
  out[43] = sizeof(PmrEnvLevel);
  PROBE(44, PmrParams, view_anchor);
  PROBE(45, PmrParams, view_coord);
  PROBE(48, PmrMaterial, attenuation_color);
  out[49] = sizeof(PmrSource);
  PROBE(50, PmrSource, opaque_only);
  PROBE(46, PmrParams, lod_scale_x);
  PROBE(47, PmrTexture, levels);
  PROBE(51, PmrLight, half_width);
  PROBE(52, PmrLight, half_height);
}
