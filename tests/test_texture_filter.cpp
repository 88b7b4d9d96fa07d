// Filtered textures (DESIGN section 3b, "Textures are filtered"): the mip chains built at load, and the
// level of detail the kernels take from the analytic screen-space derivatives, checked on images whose
// expected values follow from the geometry alone (a quad on the focal plane covers the same raster
// rectangle in every view, so its texels per pixel are the texture's size over the rectangle's).
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <cmath>

#include "pipeline/material_tables.h"
#include "pipeline/texture_mips.h"
#include "reference/shade_reference.h"
#include "reference/texture_lod_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

// A w x h texture of grey squares of `cell` texels, white where (x / cell + y / cell) is even, else black.
SceneTexture checker(int w, int h, int cell) {
  SceneTexture t;
  t.width = w, t.height = h;
  t.rgba.assign(size_t(w) * size_t(h) * 4, 255);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t c = (x / cell + y / cell) % 2 == 0 ? 255 : 0;
      for (int k = 0; k < 3; ++k) t.rgba[(size_t(y) * size_t(w) + size_t(x)) * 4 + size_t(k)] = c;
    }
  return t;
}

TEST(TextureMips, ColourChecker2x2AveragesInLinearLight) {
  const SceneTexture t = checker(2, 2, 1);
  ASSERT_EQ(mip_levels(2, 2), 2);
  const std::vector<uint8_t> srgb = build_mips(t.rgba.data(), 2, 2, MipKind::Colour);
  // the mean of linear 0 and 1 is 0.5, stored as sRGB: 255 * (1.055 * 0.5^(1/2.4) - 0.055) = 187.5 -> 188
  EXPECT_EQ(srgb, (std::vector<uint8_t>{188, 188, 188, 255}));
  // as a data map the same texels average to 127.5 -> 128
  EXPECT_EQ(build_mips(t.rgba.data(), 2, 2, MipKind::Data), (std::vector<uint8_t>{128, 128, 128, 255}));
}

TEST(TextureMips, OddSidesRoundDownAndAverageTheirBoxes) {
  // 5 x 3: levels 2 x 1, then 1 x 1; level 1 texel (x, 0) is the mean of texels (2x..2x+1, 0..1)
  // (the last column and row fall outside every box), level 2 the mean of level 1's two texels.
  EXPECT_EQ(mip_levels(5, 3), 3);
  EXPECT_EQ(mip_levels(1, 1), 1);
  EXPECT_EQ(mip_levels(96, 96), 7);
  EXPECT_EQ(mip_chain_texels(5, 3, 3), uint64_t(15 + 2 + 1));
  std::vector<uint8_t> rgba;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) rgba.insert(rgba.end(), {uint8_t(10 * x + 100 * y), uint8_t(4 * x), 0, 255});
  const std::vector<uint8_t> mips = build_mips(rgba.data(), 5, 3, MipKind::Data);
  ASSERT_EQ(mips.size(), size_t(3 * 4));
  // red: texel (0,0): (0 + 10 + 100 + 110) / 4 = 55; (1,0): (20 + 30 + 120 + 130) / 4 = 75; level 2: 65
  // green: (0 + 4 + 0 + 4) / 4 = 2; (8 + 12 + 8 + 12) / 4 = 10; level 2: 6
  EXPECT_EQ(mips, (std::vector<uint8_t>{55, 2, 0, 255, 75, 10, 0, 255, 65, 6, 0, 255}));
}

TEST(TextureMips, TablesHoldEveryLevelAndAColourAndADataChainOfOneImage) {
  Scene s = test::empty_scene();
  s.textures.push_back(checker(4, 2, 1));
  test::base_colour_texture(s, 0, 0);
  test::add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  test::texcoord(s, 0, 0) = glm::vec2(0.0f);
  SceneTextureSlot& ao = s.material_inputs[0].slots[kSlotOcclusion];
  ao.texture = 0, ao.srgb = false;
  const MaterialTables mips = make_material_tables(s, true);
  ASSERT_EQ(mips.textures.size(), 2u);  // the image as a colour map, then as a data map
  EXPECT_EQ(mips.materials[0].maps[PMR_MAP_BASE_COLOR].texture, 0);
  EXPECT_EQ(mips.materials[0].maps[PMR_MAP_OCCLUSION].texture, 1);
  EXPECT_EQ(mips.textures[0].levels, 3u);  // 4 x 2, 2 x 1, 1 x 1
  EXPECT_EQ(mips.textures[1].offset, 8u + 2u + 1u);
  EXPECT_EQ(mips.texels.size(), size_t(2 * 11 * 4));
  EXPECT_EQ(mips.texels[8 * 4], 188);         // the colour chain's level 1
  EXPECT_EQ(mips.texels[(11 + 8) * 4], 128);  // the data chain's
  const MaterialTables none = make_material_tables(s, false);
  ASSERT_EQ(none.textures.size(), 1u);
  EXPECT_EQ(none.textures[0].levels, 1u);
  EXPECT_EQ(none.texels.size(), size_t(8 * 4));
  EXPECT_EQ(none.materials[0].maps[PMR_MAP_OCCLUSION].texture, 0);
}

// A quad on the focal plane over raster x in [x0, x0 + side], y in [y0, y0 + side] in every view, uv
// (0, 0) at its top-left corner and (1, 1) at the bottom-right, its normals toward Lambert's light so
// that the lit colour is the base colour exactly.
Scene focal_quad(const Rig& rig, double x0, double y0, double side, SceneTexture texture) {
  Scene s = test::empty_scene(true);
  s.textures.push_back(std::move(texture));
  test::base_colour_texture(s, 0, 0);
  const glm::vec3 tl = test::focal_point(rig, x0, y0), tr = test::focal_point(rig, x0 + side, y0),
                  br = test::focal_point(rig, x0 + side, y0 + side), bl = test::focal_point(rig, x0, y0 + side);
  test::add_triangle(s, tl, bl, br);
  test::add_triangle(s, tl, br, tr);
  const glm::vec2 uv[6] = {{0, 0}, {0, 1}, {1, 1}, {0, 0}, {1, 1}, {1, 0}};
  const glm::vec3 light(rig.light_world());
  for (size_t k = 0; k < 6; ++k) {
    test::texcoord(s, 0, k) = uv[k];
    for (int c = 0; c < 3; ++c) s.attributes[k].normal[c] = light[c];
  }
  return s;
}

PipelineConfig lambert(TextureFilter filter) {
  PipelineConfig pc;
  pc.tile_x = pc.tile_y = pc.tile_v = 4;
  pc.shading = Shading::Lambert;
  pc.texture_filter = filter;
  return pc;
}

// The red channel of voxel (px, py) of `view`.
float red(const test::Rendered& r, const Rig& rig, int px, int py, int view) {
  const size_t v = (size_t(view) * size_t(rig.view_h) + size_t(py)) * size_t(rig.view_w) + size_t(px);
  half h;
  h.setBits(r.volume[v * 4]);
  return float(h);
}

// 96 x 96 texels over 32 x 32 pixels: rho = 3 texels per pixel in x and y, lambda = log2 3, between
// levels 1 and 2. The texture's squares of 2 texels make level 1 a checker of single texels (0 or 1)
// and level 2 grey (linear 0.5, stored as sRGB 188). The quad starts 1/6 pixel past a pixel edge, so
// that pixel (x0 + i, y0 + j) with i, j even samples level 1 at a texel center: there the colour is
// (1 - f) c + f L2, f = log2 3 - 1, c that texel's 0 or 1 and L2 the decoded 188.
TEST(TextureFilter, LevelOfDetailIsTheAnalyticTexelsPerPixelInEveryView) {
  const int views = 8;
  const Rig rig = test::small_rig(views, 96, 64);
  const int px0 = 20, py0 = 16;
  const Scene s = focal_quad(rig, px0 + 1.0 / 6.0, py0 + 1.0 / 6.0, 32.0, checker(96, 96, 2));
  const test::Rendered out = test::render_with(s, rig, lambert(TextureFilter::Trilinear));
  const double f = std::log2(3.0) - 1.0, level2 = srgb_to_linear(188.0 / 255.0);
  size_t checked = 0;
  for (int view : {0, views / 2, views - 1})
    for (int j = 0; j < 32; j += 2)
      for (int i = 0; i < 32; i += 2) {
        const int k = 3 * i / 2, l = 3 * j / 2;  // the level-1 texel sampled
        const double c = (k + l) % 2 == 0 ? 1.0 : 0.0;
        const double want = (1.0 - f) * c + f * level2;
        ASSERT_NEAR(red(out, rig, px0 + i, py0 + j, view), want, 2e-3)
            << "pixel (" << px0 + i << ", " << py0 + j << ") of view " << view;
        ++checked;
      }
  EXPECT_EQ(checked, size_t(3 * 16 * 16));
}

// A minified black-and-white checker of single texels (256 x 256 over 32 x 32 pixels: lambda = 3)
// renders grey: linear 0.5 (sRGB 188), the mean of the texels' light, not of their sRGB codes (128).
// Bilinear filtering from level 0 reads single texels: the quad starts 1/16 pixel past a pixel edge, so
// that pixel (x0 + i, y0 + j) falls on the center of texel (8i + 3, 8j + 3), always a white one: the
// grey checker aliases to white.
TEST(TextureFilter, MinifiedCheckerIsLinearGreyTrilinearAndAliasedBilinear) {
  const Rig rig = test::small_rig(4, 64, 48);
  const int px0 = 16, py0 = 8;
  const Scene s = focal_quad(rig, px0 + 1.0 / 16.0, py0 + 1.0 / 16.0, 32.0, checker(256, 256, 1));
  const test::Rendered tri = test::render_with(s, rig, lambert(TextureFilter::Trilinear));
  const test::Rendered bi = test::render_with(s, rig, lambert(TextureFilter::Bilinear));
  float lo = 1.0f;
  for (int view = 0; view < 4; ++view)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i) {
        const float g = red(tri, rig, px0 + i, py0 + j, view);
        ASSERT_NEAR(g, 0.5, 0.01) << "pixel (" << px0 + i << ", " << py0 + j << ") of view " << view;
        const double code = 255.0 * linear_to_srgb(double(g));
        EXPECT_NEAR(code, 188.0, 0.6);
        const float b = red(bi, rig, px0 + i, py0 + j, view);
        lo = std::min(lo, b);
      }
  EXPECT_GT(lo, 0.99f);
}

// With --sampling subpixel the level of detail is per display pixel (PmrParams.lod_scale): views of
// 96 x 64 encoded into a 48 x 64 display make a display pixel 2 view pixels wide (into a 96 x 32 one, 2
// tall), so a checker of single texels at one texel per view pixel (lambda 0 on the view grid) is read
// at lambda 1, its level 1: uniformly grey, linear 0.5. At lambda 0 the subpixels' samples would read
// black and white. One display stretches x only and the other y only, so each scale is tested alone.
TEST(TextureFilter, SubpixelSamplingTakesTheDisplayPixelsFootprint) {
  const Rig rig = test::small_rig(4, 96, 64);
  const int px0 = 32, py0 = 16;
  const Scene s = focal_quad(rig, px0, py0, 32.0, checker(32, 32, 1));
  const int sizes[2][2] = {{48, 64}, {96, 32}};
  for (const auto& size : sizes) {
    Display d;
    d.width = size[0], d.height = size[1];
    PipelineConfig pc = lambert(TextureFilter::Trilinear);
    pc.sampling = Sampling::Subpixel;
    pc.fuse_encode = false;
    std::vector<uint16_t> encoded;
    test::render_with(s, rig, pc, &d, &encoded);
    size_t checked = 0;
    for (int i = 0; i < d.height; ++i)
      for (int sub = 0; sub < 3 * d.width; ++sub) {
        const double x = (2.0 * sub + 1.0) * rig.view_w / (6.0 * d.width);
        const double y = (2.0 * i + 1.0) * rig.view_h / (2.0 * d.height);
        if (x < px0 + 2 || x > px0 + 30 || y < py0 + 2 || y > py0 + 30) continue;  // inside, off the edges
        half h;
        h.setBits(encoded[(size_t(i) * size_t(d.width) + size_t(sub / 3)) * 4 + size_t(sub % 3)]);
        ASSERT_NEAR(float(h), 0.5, 0.01) << "display " << d.width << "x" << d.height << ": subpixel " << sub
                                         << " of row " << i;
        ++checked;
      }
    EXPECT_GT(checked, 500u);
  }
}

// Magnified textures (lambda clamped to 0) read level 0 alone: the trilinear image is the bilinear one,
// bit for bit (the quad's 16 texels over 32 pixels).
TEST(TextureFilter, MagnifiedTrilinearIsBilinear) {
  const Rig rig = test::small_rig(4, 64, 48);
  const Scene s = focal_quad(rig, 16.3, 8.7, 32.0, checker(16, 16, 1));
  EXPECT_EQ(test::render_with(s, rig, lambert(TextureFilter::Trilinear)).volume,
            test::render_with(s, rig, lambert(TextureFilter::Bilinear)).volume);
}

// The sidecar records the texture filter (absent in older sidecars: bilinear), and --resume refuses a
// folder rendered with the other one.
TEST(TextureFilter, SidecarRecordsItAndResumeComparesIt) {
  test::expect_resume_compares("--texture-filter bilinear", "\"texture_filter\": \"bilinear\"", "texture_filter");
}

// A texture of smooth ramps with a fine checker in green, so that every level differs.
SceneTexture ramps(int w, int h) {
  SceneTexture t;
  t.width = w, t.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      t.rgba.insert(t.rgba.end(),
                    {uint8_t(255 * x / (w - 1)), uint8_t((x + y) % 2 ? 220 : 30), uint8_t(255 * y / (h - 1)), 255});
  return t;
}

// A quad receding in perspective, its texture repeated and turned by a KHR_texture_transform, from
// magnified near the camera to minified by several levels far away: every covered voxel of every view
// is the reference's trilinear sample (tests/reference/texture_lod_reference.cpp) at the reference's
// analytic derivatives, in double precision.
TEST(TextureFilter, PerspectiveQuadMatchesTheTrilinearReference) {
  const Rig rig = test::small_rig(5, 96, 64);
  Scene s = test::empty_scene(true);
  s.textures.push_back(ramps(64, 32));
  s.textures[0].wrap_t = PMR_WRAP_MIRROR;
  SceneTextureSlot& slot = test::base_colour_texture(s, 0, 0);
  slot.transform = true, slot.rotation = 0.3f, slot.scale[0] = 1.5f, slot.scale[1] = 0.8f;
  slot.offset[0] = 0.25f, slot.offset[1] = -0.5f;
  const glm::vec3 p[4] = {{-1.6f, -1.0f, 1.0f}, {1.6f, -1.0f, 1.0f}, {1.0f, 0.9f, -6.0f}, {-1.0f, 0.9f, -6.0f}};
  test::add_triangle(s, p[0], p[1], p[2]);
  test::add_triangle(s, p[0], p[2], p[3]);
  const glm::vec2 uv[6] = {{0, 8}, {4, 8}, {4, 0}, {0, 8}, {4, 0}, {0, 0}};
  const glm::vec3 light(rig.light_world());
  for (size_t k = 0; k < 6; ++k) {
    test::texcoord(s, 0, k) = uv[k];
    for (int c = 0; c < 3; ++c) s.attributes[k].normal[c] = light[c];
  }
  const test::Rendered out = test::render_with(s, rig, lambert(TextureFilter::Trilinear));
  const std::vector<SceneTexture> chain = ref::mip_chain(s.textures[0], true);
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  size_t compared = 0, bad = 0;
  double lambda_max = 0.0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    if (out.key[v] == PMR_NO_KEY) continue;
    const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
    const PmrMta* m = nullptr;
    for (const PmrMta& c : out.mtas)
      if (c.key == out.key[v] && view >= c.view_lo && view <= c.view_hi) m = &c;
    ASSERT_NE(m, nullptr);
    const glm::dvec3 b = ref::source_barycentrics(*m, px, py, view);
    const ref::BaryDerivatives d = ref::source_barycentric_derivatives(*m, int64_t(px) * PMR_X_ONE + PMR_X_ONE / 2,
                                                                       int64_t(py) * PMR_Y_ONE + PMR_Y_ONE / 2, view);
    glm::dvec2 t(0.0), tx(0.0), ty(0.0);
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 tk(s.texcoords[0][s.triangles[m->tri].v[k]]);
      t += b[k] * tk, tx += d.dx[k] * tk, ty += d.dy[k] * tk;
    }
    const glm::dvec2 origin = ref::transformed_uv(slot, glm::dvec2(0.0));
    const glm::dvec2 dx = ref::transformed_uv(slot, tx) - origin, dy = ref::transformed_uv(slot, ty) - origin;
    lambda_max = std::max(lambda_max, ref::texture_lod(chain, dx, dy));
    const glm::dvec4 want = ref::sample_trilinear(chain, ref::transformed_uv(slot, t), dx, dy, true);
    for (int c = 0; c < 3; ++c) {
      half got;
      got.setBits(out.volume[v * 4 + size_t(c)]);
      if (std::abs(double(float(got)) - want[c]) > std::ldexp(want[c], -10) + 1e-3 && ++bad <= 5)
        ADD_FAILURE() << "voxel (" << px << "," << py << "," << view << ") channel " << c << ": " << float(got)
                      << " vs " << want[c];
    }
    ++compared;
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(compared, size_t(3000));
  EXPECT_GT(lambda_max, 2.0) << "the far end should be minified by several levels";
}

}  // namespace
}  // namespace pmr
