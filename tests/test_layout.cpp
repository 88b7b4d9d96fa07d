// The shared structs have the same size and field offsets on the device as on the host.
#include <gtest/gtest.h>

#include <cstddef>

#include "test_util.h"

namespace pmr {
namespace {

TEST(Layout, DeviceStructsMatchHost) {
  const ClRuntime& rt = test::runtime();
  const ClProgram program = rt.build_program({"layout_probe.cl"}, "-cl-std=CL1.2", &test_kernel_sources());
  ClKernel k(program, "layout_probe");
  ClBuffer out = rt.buffer(64 * 4, "probe");
  k.arg(0, out);
  cl_event e = rt.launch(k, 1, 1);
  clReleaseEvent(e);
  uint32_t got[64] = {};
  rt.read(out, got, sizeof got);
  const uint32_t want[] = {sizeof(PmrParams),
                           offsetof(PmrParams, ndc_scale_x),
                           offsetof(PmrParams, light_world),
                           offsetof(PmrParams, view_w),
                           offsetof(PmrParams, debug_outputs),
                           sizeof(PmrVertex),
                           offsetof(PmrVertex, x0),
                           offsetof(PmrVertex, z),
                           sizeof(PmrMta),
                           offsetof(PmrMta, bary),
                           offsetof(PmrMta, key),
                           offsetof(PmrMta, flags),
                           sizeof(PmrVertexAttr),
                           offsetof(PmrVertexAttr, color),
                           sizeof(PmrTriangle),
                           offsetof(PmrTriangle, face_normal),
                           sizeof(PmrMaterial),
                           offsetof(PmrMaterial, alpha_cutoff),
                           sizeof(PmrTexture),
                           offsetof(PmrTexture, wrap_t),
                           sizeof(PmrEncodeParams),
                           offsetof(PmrEncodeParams, display_w),
                           offsetof(PmrEncodeParams, bilinear),
                           offsetof(PmrMaterial, maps),
                           offsetof(PmrMaterial, occlusion_strength),
                           sizeof(PmrTextureMap),
                           offsetof(PmrParams, num_lights),
                           sizeof(PmrLight),
                           offsetof(PmrLight, type),
                           offsetof(PmrLight, range),
                           offsetof(PmrLight, direction),
                           offsetof(PmrLight, cos_outer)};
  for (size_t i = 0; i < sizeof want / sizeof want[0]; ++i) EXPECT_EQ(got[i], want[i]) << "probe " << i;
  // the environment header of --shading pbr (probes 40..43)
  EXPECT_EQ(got[40], sizeof(PmrEnvironment));
  EXPECT_EQ(got[41], offsetof(PmrEnvironment, intensity));
  EXPECT_EQ(got[42], offsetof(PmrEnvironment, levels));
  EXPECT_EQ(got[43], sizeof(PmrEnvLevel));
  // the view coordinates at the end of the frame parameters (probes 44, 45)
  EXPECT_EQ(got[44], offsetof(PmrParams, view_anchor));
  EXPECT_EQ(got[45], offsetof(PmrParams, view_coord));
  // the texture filter's fields (probes 46, 47)
  EXPECT_EQ(got[46], offsetof(PmrParams, lod_scale_x));
  EXPECT_EQ(got[47], offsetof(PmrTexture, levels));
  // the transmission fields of --shading pbr (probes 48..50)
  EXPECT_EQ(got[48], offsetof(PmrMaterial, attenuation_color));
  EXPECT_EQ(got[49], sizeof(PmrSource));
  EXPECT_EQ(got[50], offsetof(PmrSource, opaque_only));
  // an area light's extents (probes 51, 52)
  EXPECT_EQ(got[51], offsetof(PmrLight, half_width));
  EXPECT_EQ(got[52], offsetof(PmrLight, half_height));
}

}  // namespace
}  // namespace pmr
