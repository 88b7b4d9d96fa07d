// alphaMode BLEND (DESIGN section 4c step 3): layers composited with premultiplied "over" far to near,
// against the double-precision reference (tests/reference/blend_reference.h); bytes independent of the
// triangles' order; the rule beyond eight fragments per sample; BLEND seen through glass, and not twice
// in front of it; every rendering path drawing the same layers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pbr_support.h"
#include "reference/blend_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

using test::add_material;
using test::quad;
using test::unlit;

using Layer = ref::BlendFragment;

PmrMaterial blended(glm::vec3 c, float alpha) {
  PmrMaterial m = unlit(c);
  m.alpha_mode = PMR_ALPHA_BLEND;
  m.base_color[3] = alpha;
  return m;
}

// Exact premultiplied "over", far to near (no rule: every fragment exact).
glm::dvec4 over(const std::vector<Layer>& far_to_near, const glm::dvec4& behind) {
  return ref::composite_blend(far_to_near, behind, far_to_near.size());
}

PipelineConfig pbr_config(int samples = 1) {
  PipelineConfig pc;
  pc.tile_x = 4, pc.tile_y = 4, pc.tile_v = 4;
  pc.shading = Shading::Pbr;
  pc.samples = samples;
  return pc;
}

// 8 views of 64x32 framing the unit box, and a display of 120x60 for the encoded paths.
Rig layer_rig(Display& d) {
  d.width = 120, d.height = 60;
  RigConfig rc;
  rc.views = 8, rc.view_w = 64, rc.view_h = 32;
  return make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
}

// Every voxel of a volume against one expected RGBA, within 2e-3 relative + 1e-3 (halves and float
// compositing).
void expect_every_voxel(const std::vector<uint16_t>& volume, const glm::dvec4& want, const std::string& what) {
  size_t bad = 0;
  for (size_t v = 0; v < volume.size() / 4; ++v)
    for (int c = 0; c < 4; ++c) {
      const double got = test::half_value(volume[v * 4 + size_t(c)]);
      if (std::abs(got - want[c]) <= 2e-3 * want[c] + 1e-3) continue;
      if (++bad <= 5)
        ADD_FAILURE() << what << ": voxel " << v << " channel " << c << " is " << got << ", want " << want[c];
    }
  EXPECT_EQ(bad, size_t(0)) << what;
}

const std::vector<Layer> kThree = {{{0.9, 0.1, 0.1}, 0.5}, {{0.1, 0.8, 0.2}, 0.3}, {{0.2, 0.3, 0.9}, 0.6}};
constexpr float kThreeZ[3] = {-0.2f, 0.0f, 0.2f};  // far to near
const glm::dvec3 kWall(0.5, 0.45, 0.4);

// The three layers covering every view, over a wall or over nothing; added nearest first, so that the
// file's order is the reverse of depth order.
Scene three_layers(bool wall) {
  Scene s = test::empty_scene(true);
  for (int k = 2; k >= 0; --k)
    quad(s, -9.0f, -9.0f, 9.0f, 9.0f, kThreeZ[k],
         add_material(s, blended(glm::vec3(kThree[size_t(k)].colour), float(kThree[size_t(k)].alpha))));
  if (wall) quad(s, -9.0f, -9.0f, 9.0f, 9.0f, -0.5f, add_material(s, unlit(glm::vec3(kWall))));
  return s;
}

TEST(Blend, ThreeLayersCompositeToTheAnalyticOverInEveryView) {
  Display d;
  const Rig rig = layer_rig(d);
  for (bool wall : {true, false}) {
    const glm::dvec4 want = over(kThree, wall ? glm::dvec4(kWall, 1.0) : glm::dvec4(0.0));
    for (int samples : {1, 4}) {
      const test::Rendered out = test::render_with(three_layers(wall), rig, pbr_config(samples));
      expect_every_voxel(
          out.volume, want,
          std::string(wall ? "over the wall" : "over nothing") + ", " + std::to_string(samples) + " spp");
    }
  }
}

// The fused path gives way to the volume path for BLEND scenes (the same bytes); subpixel sampling and the
// baselines composite the same layers.
TEST(Blend, EveryPathComposites) {
  Display d;
  const Rig rig = layer_rig(d);
  const Scene s = three_layers(true);
  const glm::dvec4 want = over(kThree, glm::dvec4(kWall, 1.0));
  PipelineConfig pc = pbr_config();
  pc.fuse_encode = false;
  const test::EncodedRender unfused = test::render_encoded(s, rig, d, pc);
  pc.fuse_encode = true;
  const test::EncodedRender fused = test::render_encoded(s, rig, d, pc);
  EXPECT_FALSE(fused.fused) << "BLEND frames are rendered by the volume path";
  ASSERT_EQ(fused.image, unfused.image);
  for (size_t p = 0; p < unfused.image.size() / 4; ++p)
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(test::half_value(unfused.image[p * 4 + size_t(c)]), want[c], 2e-3 * want[c] + 1e-3) << p;
  pc.sampling = Sampling::Subpixel;
  for (int samples : {1, 4}) {
    pc.samples = samples;
    const test::EncodedRender subpixel = test::render_encoded(s, rig, d, pc);
    for (size_t p = 0; p < subpixel.image.size() / 4; ++p)
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(test::half_value(subpixel.image[p * 4 + size_t(c)]), want[c], 2e-3 * want[c] + 1e-3)
            << "subpixel sampling, " << samples << " spp, display pixel " << p << " channel " << c;
  }
  for (Method method : {Method::Multipass, Method::Duplicate}) {
    PipelineConfig mc = pbr_config();
    mc.method = method;
    expect_every_voxel(test::render_with(s, rig, mc).volume, want, to_string(method));
  }
}

// Random BLEND and opaque triangles: the file's order reversed, and other tile sizes, give the same bytes
// (visibility and layers are a total order on depth and key; no two fragments here share a depth).
TEST(Blend, TheTrianglesOrderDoesNotChangeTheBytes) {
  Display d;
  const Rig rig = layer_rig(d);
  Scene s = test::random_scene(400, 7, true);
  const glm::vec3 colours[4] = {{0.9f, 0.2f, 0.1f}, {0.1f, 0.7f, 0.3f}, {0.2f, 0.3f, 0.9f}, {0.8f, 0.8f, 0.2f}};
  for (int k = 0; k < 4; ++k) add_material(s, blended(colours[k], 0.2f + 0.2f * float(k)));
  for (size_t t = 0; t < s.triangles.size(); ++t) s.triangles[t].material = uint32_t(t % 5);  // 0: opaque
  Scene reversed = s;
  std::reverse(reversed.triangles.begin(), reversed.triangles.end());
  Scene opaque = s;
  for (PmrMaterial& m : opaque.materials) m.alpha_mode = PMR_ALPHA_OPAQUE;
  for (Shading shading : {Shading::Lambert, Shading::Pbr})
    for (int samples : {1, 4}) {
      PipelineConfig pc = pbr_config(samples);
      pc.shading = shading;
      const std::string what = to_string(shading) + std::string(", ") + std::to_string(samples) + " spp";
      const test::Rendered a = test::render_with(s, rig, pc), b = test::render_with(reversed, rig, pc);
      ASSERT_EQ(a.volume, b.volume) << what << ": reversed order";
      pc.tile_x = 8, pc.tile_y = 2, pc.tile_v = 8;
      ASSERT_EQ(test::render_with(s, rig, pc).volume, a.volume) << what << ": another tile size";
      // and the layers are there: many voxels differ from the scene drawn opaque
      const test::Rendered o = test::render_with(opaque, rig, pc);
      size_t differ = 0;
      for (size_t i = 0; i < a.volume.size(); ++i) differ += a.volume[i] != o.volume[i];
      EXPECT_GT(differ, a.volume.size() / 20) << what;
    }
  PipelineConfig pc = pbr_config();
  pc.sampling = Sampling::Subpixel;
  pc.fuse_encode = true;
  EXPECT_EQ(test::render_encoded(s, rig, d, pc).image, test::render_encoded(reversed, rig, d, pc).image)
      << "subpixel sampling, reversed order";
}

// Twelve layers over a wall: the nearest eight composite exactly, the farthest four form one layer
// directly behind them, A = 1 - prod(1 - a), colour (sum a c / sum a) A; every sample is counted.
TEST(Blend, BeyondEightLayersTheRestFormOneLayer) {
  Display d;
  const Rig rig = layer_rig(d);
  Scene s = test::empty_scene(true);
  std::vector<Layer> layers;  // far to near
  for (int k = 0; k < 12; ++k) {
    // the far four strong and unlike each other (their order matters to "over", not to the rule), the
    // near eight faint, so that the far ones show
    const glm::dvec3 far[4] = {{0.9, 0.1, 0.1}, {0.1, 0.9, 0.1}, {0.1, 0.1, 0.9}, {0.9, 0.9, 0.1}};
    const Layer l = k < 4 ? Layer{far[k], k % 2 ? 0.3 : 0.8} : Layer{{0.1 + 0.07 * k, 0.5, k % 2 ? 0.6 : 0.3}, 0.1};
    layers.push_back(l);
    quad(s, -9.0f, -9.0f, 9.0f, 9.0f, -0.45f + 0.07f * float(k),
         add_material(s, blended(glm::vec3(l.colour), float(l.alpha))));
  }
  quad(s, -9.0f, -9.0f, 9.0f, 9.0f, -0.5f, add_material(s, unlit(glm::vec3(kWall))));
  const glm::dvec4 want = ref::composite_blend(layers, glm::dvec4(kWall, 1.0)),
                   exact = over(layers, glm::dvec4(kWall, 1.0));
  ASSERT_GT(std::abs(want.r - exact.r) + std::abs(want.g - exact.g) + std::abs(want.b - exact.b), 0.02)
      << "the rule and exact compositing must differ here, or the test shows nothing";
  Pipeline p(test::runtime(), pbr_config());
  p.set_scene(s);
  p.configure(rig, nullptr);
  const StageTimes times = p.render(rig);
  std::vector<uint16_t> volume;
  p.read_volume(volume);
  expect_every_voxel(volume, want, "twelve layers");
  EXPECT_EQ(times.blend_beyond, uint32_t(rig.views * rig.view_w * rig.view_h)) << "every sample is counted";
}

// A BLEND layer between a wall and a thin pane of glass shows through the glass: what the pane shows
// changes by its transmission (1 - F, about 0.96 at normal incidence; 0.85 to 1 allowed) times what the
// layer changes behind it.
TEST(Blend, ALayerBehindGlassShowsThroughIt) {
  Display d;
  const Rig rig = layer_rig(d);
  const glm::dvec3 wall(0.2, 0.2, 0.8);
  const Layer red = {{0.9, 0.1, 0.1}, 0.5};
  Scene without = test::empty_scene(true);
  quad(without, -9.0f, -9.0f, 9.0f, 9.0f, -0.5f, add_material(without, unlit(glm::vec3(wall))));
  PmrMaterial pane = default_material();
  pane.metallic = 0.0f, pane.roughness = 0.0f, pane.transmission = 1.0f;
  quad(without, -0.6f, -0.5f, 0.6f, 0.5f, 0.3f, add_material(without, pane));
  Scene with = without;
  quad(with, -9.0f, -9.0f, 9.0f, 9.0f, -0.1f, add_material(with, blended(glm::vec3(red.colour), float(red.alpha))));
  const test::Rendered a = test::render_with(without, rig, pbr_config()),
                       b = test::render_with(with, rig, pbr_config());
  const glm::dvec3 change = glm::dvec3(over({red}, glm::dvec4(wall, 1.0))) - wall;
  size_t checked = 0;
  for (int v = 0; v < rig.views; ++v)
    for (int y = 12; y < 20; ++y)
      for (int x = 26; x < 38; ++x) {  // the middle of the view: behind the pane in every view
        const size_t i = (size_t(v) * size_t(rig.view_h) + size_t(y)) * size_t(rig.view_w) + size_t(x);
        for (int c : {0, 2}) {
          const double got =
              test::half_value(b.volume[i * 4 + size_t(c)]) - test::half_value(a.volume[i * 4 + size_t(c)]);
          EXPECT_GE(got / change[c], 0.85) << "view " << v << " (" << x << ", " << y << ") channel " << c;
          EXPECT_LE(got / change[c], 1.0) << "view " << v << " (" << x << ", " << y << ") channel " << c;
        }
        ++checked;
      }
  EXPECT_EQ(checked, size_t(8 * 8 * 12));
}

// A BLEND layer in front of the pane is composited over it once: the transmission source holds only the
// BLEND fragments behind the glass, so the pane shows exactly a c + (1 - a) x what it shows without it.
TEST(Blend, ALayerInFrontOfGlassIsNotSeenThroughItAgain) {
  Display d;
  const Rig rig = layer_rig(d);
  const Layer red = {{0.9, 0.1, 0.1}, 0.5};
  Scene without = test::empty_scene(true);
  quad(without, -9.0f, -9.0f, 9.0f, 9.0f, -0.5f, add_material(without, unlit({0.2f, 0.2f, 0.8f})));
  PmrMaterial pane = default_material();
  pane.metallic = 0.0f, pane.roughness = 0.0f, pane.transmission = 1.0f;
  quad(without, -0.6f, -0.5f, 0.6f, 0.5f, 0.3f, add_material(without, pane));
  Scene with = without;
  quad(with, -9.0f, -9.0f, 9.0f, 9.0f, 0.5f, add_material(with, blended(glm::vec3(red.colour), float(red.alpha))));
  const test::Rendered a = test::render_with(without, rig, pbr_config()),
                       b = test::render_with(with, rig, pbr_config());
  // the middle of each view, behind the pane, a pixel or more from its edges: the source is read there
  // at the refracted point's projection, whose rounding reaches a neighbour pixel by a few percent,
  // and where no glass is in front the source holds every BLEND layer
  for (int v = 0; v < rig.views; ++v)
    for (int y = 13; y < 19; ++y)
      for (int x = 30; x < 35; ++x) {
        const size_t i = (size_t(v) * size_t(rig.view_h) + size_t(y)) * size_t(rig.view_w) + size_t(x);
        for (int c = 0; c < 3; ++c) {
          const double before = test::half_value(a.volume[i * 4 + size_t(c)]);
          const double want = red.colour[c] * red.alpha + (1.0 - red.alpha) * before;
          ASSERT_NEAR(test::half_value(b.volume[i * 4 + size_t(c)]), want, 2e-3 * want + 1e-3)
              << "view " << v << " (" << x << ", " << y << ") channel " << c << ", without the layer " << before;
        }
      }
}

}  // namespace
}  // namespace pmr
