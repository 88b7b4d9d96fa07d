// Shading (DESIGN section 4) of the fine raster against a double-precision reference, with a
// tolerance from the output format: half floats keep 11 significant bits (relative error 2^-11),
// float interpolation adds well under 1e-5, so |got - want| <= 2^-10 |want| + 1e-4.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <map>

#include "pmr/output.h"
#include "reference/shade_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

// These tests compare with the Lambert reference (tests/reference/shade_reference.cpp).
PipelineConfig lambert() {
  PipelineConfig pc;
  pc.tile_x = pc.tile_y = pc.tile_v = 4;
  pc.shading = Shading::Lambert;
  return pc;
}

SceneTexture checker(int w, int h, int mode_s, int mode_t, bool alpha_holes) {
  SceneTexture t;
  t.width = w, t.height = h, t.wrap_s = mode_s, t.wrap_t = mode_t;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool on = (x + y) % 2 == 0;
      t.rgba.push_back(uint8_t(on ? 230 : 40 + 10 * x));
      t.rgba.push_back(uint8_t(on ? 200 : 90));
      t.rgba.push_back(uint8_t(30 + 50 * y % 256));
      t.rgba.push_back(uint8_t(alpha_holes ? (on ? 255 : 0) : 255));
    }
  return t;
}

// Compares every covered voxel's colour with the reference shading of its winning triangle.
// Returns the number of voxels compared.
size_t compare_shading(const Scene& s, const Rig& rig, const test::Rendered& out) {
  std::multimap<uint32_t, PmrMta> by_key;
  for (const PmrMta& m : out.mtas) by_key.emplace(m.key, m);
  const glm::dvec3 light = rig.light_world();
  size_t compared = 0, bad = 0;
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  for (size_t v = 0; v < out.key.size(); ++v) {
    half got[4];
    for (int c = 0; c < 4; ++c) got[c].setBits(out.volume[v * 4 + size_t(c)]);
    if (out.key[v] == PMR_NO_KEY) {
      for (int c = 0; c < 4; ++c) EXPECT_EQ(float(got[c]), 0.0f) << "background voxel " << v;
      continue;
    }
    const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
    const PmrMta* m = nullptr;
    auto range = by_key.equal_range(out.key[v]);
    for (auto it = range.first; it != range.second; ++it)
      if (view >= it->second.view_lo && view <= it->second.view_hi) m = &it->second;
    if (!m) {
      ADD_FAILURE() << "no MTA for key " << out.key[v];
      continue;
    }
    const glm::dvec3 b = ref::source_barycentrics(*m, px, py, view);
    const glm::dvec4 want = ref::shade(s, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, light);
    for (int c = 0; c < 4; ++c) {
      const double tol = std::ldexp(std::abs(want[c]), -10) + 1e-4;
      if (std::abs(double(float(got[c])) - want[c]) > tol && ++bad <= 5)
        ADD_FAILURE() << "voxel (" << px << "," << py << "," << view << ") channel " << c << ": " << float(got[c])
                      << " vs " << want[c];
    }
    ++compared;
  }
  EXPECT_EQ(bad, 0u);
  return compared;
}

TEST(Shading, TexturedVertexColouredLitMatchesReference) {
  const Rig rig = test::small_rig(6, 64, 40);
  Scene s = test::empty_scene(true);
  s.textures.push_back(checker(4, 3, PMR_WRAP_REPEAT, PMR_WRAP_MIRROR, false));
  test::base_colour_texture(s, 0, 0);
  s.materials[0].base_color[0] = 0.9f, s.materials[0].base_color[2] = 0.7f;
  // a tilted quad with distinct vertex colours, curved normals, UVs spanning several repeats
  test::add_triangle(s, {-1.2f, -0.9f, 0.4f}, {1.1f, -0.8f, -0.6f}, {1.0f, 0.9f, -0.2f});
  test::add_triangle(s, {-1.2f, -0.9f, 0.4f}, {1.0f, 0.9f, -0.2f}, {-1.1f, 1.0f, 0.5f});
  const float uv[6][2] = {{-0.3f, 1.7f}, {2.4f, 1.5f}, {2.2f, -1.1f}, {-0.3f, 1.7f}, {2.2f, -1.1f}, {-0.5f, -0.9f}};
  const float col[6][4] = {{1, 0.2f, 0.2f, 1}, {0.2f, 1, 0.2f, 1}, {0.2f, 0.2f, 1, 1},
                           {1, 0.2f, 0.2f, 1}, {0.2f, 0.2f, 1, 1}, {1, 1, 1, 1}};
  // a back-facing triangle (clockwise from the camera) behind, double-sided, without normals, at uv (0, 0)
  test::add_triangle(s, {-1.0f, -1.0f, -0.9f}, {-0.2f, 0.6f, -0.9f}, {0.8f, -0.9f, -0.8f});
  s.triangles.back().has_normals = 0;
  for (int k = 0; k < 6; ++k) {
    PmrVertexAttr& a = s.attributes[size_t(k)];
    test::texcoord(s, 0, size_t(k)) = glm::vec2(uv[k][0], uv[k][1]);
    for (int c = 0; c < 4; ++c) a.color[c] = col[k][c];
    const glm::vec3 n = glm::normalize(glm::vec3(0.4f * (k % 3) - 0.4f, 0.3f * (k % 2), 1.0f));
    a.normal[0] = n.x, a.normal[1] = n.y, a.normal[2] = n.z;
  }
  const test::Rendered out = test::render_with(s, rig, lambert());
  EXPECT_GT(compare_shading(s, rig, out), size_t(2000));
  size_t back = 0;
  for (const PmrMta& m : out.mtas) back += (m.flags & PMR_MTA_BACK) != 0;
  EXPECT_GT(back, 0u) << "the scene should contain a back face";
}

// alphaMode MASK: texels with alpha 0 let the triangle behind show through.
TEST(Shading, AlphaMaskDiscardsBelowCutoff) {
  const Rig rig = test::small_rig(3, 48, 32);
  Scene s = test::empty_scene(false);
  PmrMaterial mask = s.materials[0];
  mask.alpha_mode = PMR_ALPHA_MASK;
  mask.alpha_cutoff = 0.5f;
  s.materials.push_back(mask);
  s.textures.push_back(checker(2, 2, PMR_WRAP_REPEAT, PMR_WRAP_REPEAT, true));
  test::base_colour_texture(s, 1, 0);
  // background quad (material 0) and a masked quad in front (material 1), UVs 0..3
  test::add_triangle(s, {-6, -3, -0.5f}, {6, -3, -0.5f}, {6, 3, -0.5f});
  test::add_triangle(s, {-6, -3, -0.5f}, {6, 3, -0.5f}, {-6, 3, -0.5f});
  test::add_triangle(s, {-6, -3, 0.5f}, {6, -3, 0.5f}, {6, 3, 0.5f}, 1);
  test::add_triangle(s, {-6, -3, 0.5f}, {6, 3, 0.5f}, {-6, 3, 0.5f}, 1);
  const float uv[6][2] = {{0, 4}, {8, 4}, {8, 0}, {0, 4}, {8, 0}, {0, 0}};
  for (int k = 0; k < 6; ++k) test::texcoord(s, 0, size_t(6 + k)) = glm::vec2(uv[k][0], uv[k][1]);
  const test::Rendered out = test::render_with(s, rig, lambert());
  std::multimap<uint32_t, PmrMta> by_key;
  for (const PmrMta& m : out.mtas) by_key.emplace(m.key, m);
  const size_t W = size_t(rig.view_w), H = size_t(rig.view_h);
  size_t front = 0, behind = 0, checked = 0;
  for (size_t v = 0; v < out.key.size(); ++v) {
    const uint32_t tri = out.key[v] >> PMR_KEY_SUB_BITS;
    ASSERT_NE(out.key[v], PMR_NO_KEY) << "the background quad covers everything";
    const int px = int(v % W), py = int((v / W) % H), view = int(v / (W * H));
    // what the masked quad's alpha is at this voxel (its MTA covers the screen like the background)
    for (auto& kv : by_key) {
      const PmrMta& m = kv.second;
      if (m.tri < 2 || view < m.view_lo || view > m.view_hi) continue;
      const glm::dvec3 b = ref::source_barycentrics(m, px, py, view);
      if (b.x < 0 || b.y < 0 || b.z < 0) continue;  // not this half of the quad
      const double alpha = ref::base_color(s, m.tri, b).w;
      if (std::abs(alpha - 0.5) < 1e-3) break;  // on the cutoff: float and double may disagree
      ++checked;
      EXPECT_EQ(tri >= 2, alpha >= 0.5) << "voxel (" << px << "," << py << "," << view << ") alpha " << alpha;
      break;
    }
    (tri >= 2 ? front : behind)++;
  }
  EXPECT_GT(checked, out.key.size() / 2);
  EXPECT_GT(front, out.key.size() / 4);
  EXPECT_GT(behind, out.key.size() / 4);
  compare_shading(s, rig, out);
}

}  // namespace
}  // namespace pmr

namespace pmr {
namespace {

// Colours are halves: a value beyond the largest finite half (65504) saturates there instead of
// becoming infinite (which would turn any blend, e.g. --bilinear, into NaN). Exposure 2^30 pushes every
// lit voxel of the bundled scene far beyond it, in both shading models and every path that shades.
TEST(Shading, BrightColoursSaturateAtTheLargestHalf) {
  const std::string out = test::temp_dir("saturate");
  // one sample: every lit pixel wholly covered (an edge pixel's coverage scales its colour below 65504)
  const std::string small =
      " -q --views 4 --view-size 48x24 --display 96x54 --frames 0 --exposure 30 --samples 1 --out " + out;
  for (const std::string& variant : {std::string("pbr_views --shading pbr --write views"),
                                     std::string("lambert_views --shading lambert --write views"),
                                     std::string("pbr_fused --shading pbr --write encoded"),
                                     std::string("pbr_subpixel --shading pbr --write encoded --sampling subpixel"),
                                     std::string("pbr_bilinear --shading pbr --write encoded --bilinear")}) {
    const std::string name = variant.substr(0, variant.find(' '));
    SCOPED_TRACE(name);
    ASSERT_EQ(test::run("render" + small + " --name " + name + variant.substr(variant.find(' '))).status, 0);
    std::vector<uint16_t> px;
    int w = 0, h = 0;
    if (variant.find("--write views") != std::string::npos)
      read_views_exr_part(out + "/" + name + ".views.exr", 1, w, h, px);
    else read_rgba_exr(out + "/" + name + ".exr", w, h, px);
    ASSERT_FALSE(px.empty());
    size_t saturated = 0;
    for (size_t i = 0; i < px.size(); ++i) {
      if (i % 4 == 3) continue;
      const uint16_t magnitude = px[i] & 0x7fffu;
      ASSERT_LT(magnitude, 0x7c00u) << "an infinite or NaN half at value " << i;
      saturated += magnitude == 0x7bffu;  // 65504
    }
    EXPECT_GT(saturated, px.size() / 40) << "the lit voxels should all saturate";
  }
}

}  // namespace
}  // namespace pmr
