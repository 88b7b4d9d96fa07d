// --sampling subpixel (cl/fine_subpixel.cl) against a direct per-subpixel evaluation: for random
// triangles and random display parameters (lens pitches and slants with many digits, offsets, reversed
// views, subpixel cells, view rasters larger and smaller than the display, tile shapes whose tiles cut
// display pixels), every subpixel's winning key and depth equal the C++ reference rasterizer evaluated
// at that one sample in that one view, bit for bit; its colour channel equals the double-precision
// shading reference at that sample within the half-float tolerance of test_shading.cpp; its alpha is
// the exact mean coverage. The display image does not depend on the tile shape. Trials alternate
// linear and angular camera spacing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include <Imath/half.h>

#include "pmr/rig.h"
#include "quality/sampling_quality.h"
#include "reference/reference.h"
#include "reference/shade_reference.h"
#include "test_util.h"

namespace pmr {
namespace {

using Imath::half;

struct SubpixelRender {
  std::vector<uint16_t> display;
  std::vector<uint32_t> key, count;
  std::vector<float> depth;
  std::vector<PmrMta> mtas;
};

SubpixelRender render_subpixels(const Scene& scene, const Rig& rig, const Display& d, const int* tile,
                                int samples = 1) {
  PipelineConfig pc;
  pc.samples = samples;
  pc.tile_x = tile[0], pc.tile_y = tile[1], pc.tile_v = tile[2];
  pc.sampling = Sampling::Subpixel;
  pc.shading = Shading::Lambert;  // compared with the Lambert reference
  pc.fuse_encode = true;          // no view volume: debug outputs per display subpixel
  pc.debug_outputs = true;
  Pipeline p(test::runtime(), pc);
  p.set_scene(scene);
  p.configure(rig, &d);
  p.render(rig);
  EXPECT_FALSE(p.has_volume());
  SubpixelRender r;
  p.read_display(r.display);
  p.read_debug(r.key, r.depth, r.count);
  r.mtas = p.read_mtas();
  return r;
}

// A decimal with `digits` fractional digits in [lo, hi).
std::string random_decimal(std::mt19937& rng, double lo, double hi, int digits) {
  std::uniform_real_distribution<double> u(lo, hi);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, u(rng));
  return buf;
}

TEST(SubpixelSampling, EverySubpixelEqualsDirectEvaluationAtItsSample) {
  std::mt19937 rng(20261123);
  const int tiles[][3] = {{16, 2, 16}, {4, 4, 4}, {8, 3, 5}, {3, 1, 2}, {32, 8, 1}};
  size_t covered_total = 0, straddles_seen = 0;
  for (int trial = 0; trial < 11; ++trial) {
    std::uniform_int_distribution<int> views_d(1, 40), vw(6, 90), vh(4, 60), dw(10, 130), dh(6, 80);
    Display d;
    d.width = dw(rng), d.height = dh(rng);
    d.lens_pitch = parse_rational(random_decimal(rng, 2.0, 24.0, 10), "L");
    d.tan_slant = parse_rational(random_decimal(rng, -0.4, 0.4, 12), "T");
    d.offset = parse_rational(random_decimal(rng, -30.0, 30.0, 9), "O");
    d.reversed = trial % 3 == 1;
    RigConfig rc;
    // one view; 700 views (over 512: the chunk capacity's other branch) with 64 px wide tiles
    rc.views = trial == 0 ? 1 : (trial == 10 ? 700 : views_d(rng));
    rc.angular_spacing = trial % 2 == 1 || trial == 10;  // both camera spacings
    rc.view_w = vw(rng), rc.view_h = vh(rng);
    if (trial == 4) {  // Looking Glass conventions: gen3 subpixel cells (the column map changes with the
                       // row class), the shader's 1 - fract phase, BGR subpixel order
      d.cell_rows = 2;
      d.cell_offsets.clear();
      for (int k = 0; k < 12; ++k)
        d.cell_offsets.push_back(int64_t(std::uniform_int_distribution<int>(-300, 300)(rng)) * 10000000000000LL / 100);
      d.phase_sign = -1;
      d.subpixel_bgr = true;
    }
    if (trial == 5) rc.view_w = 3 * d.width, rc.view_h = 2 * d.height;  // views larger than the display
    const Rig rig = make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
    Scene scene = test::random_scene(150, 900u + unsigned(trial), trial % 2 == 0);
    if (trial == 7)  // huge triangles, clipped by near, far and the guard band (the paths for wide extents)
      for (int k = 0; k < 4; ++k)
        test::add_triangle(scene, {-5000.0f + k, -3000.0f, -1.0f + 0.3f * k}, {3500.0f, -2.0f - k, 3.5f},
                           {-3.0f, 4500.0f, -2.0f + k});
    const int wide_tile[3] = {64, 4, 8};
    const int* tile = trial == 10 ? wide_tile : tiles[trial % 5];
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + std::to_string(rc.views) + " views of " +
                 std::to_string(rc.view_w) + "x" + std::to_string(rc.view_h) + ", display " + std::to_string(d.width) +
                 "x" + std::to_string(d.height) + ", tile " + std::to_string(tile[0]) + "x" + std::to_string(tile[1]) +
                 "x" + std::to_string(tile[2]) + ", " + test::spacing_name(rc.angular_spacing));
    const SubpixelRender got = render_subpixels(scene, rig, d, tile);

    const PmrParams P = test::params_for(rig);
    std::vector<PmrVertex> verts;
    for (const auto& p : scene.positions) verts.push_back(ref::transform_vertex(P, &p.x));
    const std::vector<int> view_of = test::table_view_indices(d, rc.views);
    const ref::SubpixelResult want =
        ref::rasterize_subpixels(P, ref::clip_triangles(P, scene, verts), view_of, d.width, d.height);
    ASSERT_EQ(got.key.size(), want.key.size());
    size_t key_bad = 0, depth_bad = 0, colour_bad = 0, alpha_bad = 0;
    std::multimap<uint32_t, const PmrMta*> by_key;
    for (const PmrMta& m : got.mtas) by_key.emplace(m.key, &m);
    const glm::dvec3 light = rig.light_world();
    for (size_t at = 0; at < want.key.size(); ++at) {
      if (got.key[at] != want.key[at] && ++key_bad <= 5)
        ADD_FAILURE() << "subpixel " << at << ": key " << got.key[at] << ", reference " << want.key[at];
      if (std::memcmp(&got.depth[at], &want.depth[at], sizeof(float)) != 0 && ++depth_bad <= 5)
        ADD_FAILURE() << "subpixel " << at << ": depth " << got.depth[at] << ", reference " << want.depth[at];
      half value;
      value.setBits(got.display[(at / 3) * 4 + at % 3]);
      if (want.key[at] == PMR_NO_KEY) {
        if (value.bits() != 0 && ++colour_bad <= 5)
          ADD_FAILURE() << "background subpixel " << at << " is " << float(value);
        continue;
      }
      ++covered_total;
      const int view = view_of[at];
      const PmrMta* m = nullptr;
      auto range = by_key.equal_range(want.key[at]);
      for (auto it = range.first; it != range.second; ++it)
        if (view >= it->second->view_lo && view <= it->second->view_hi) m = it->second;
      if (!m) {
        ADD_FAILURE() << "no MTA for key " << want.key[at];
        continue;
      }
      const glm::dvec3 b = ref::source_barycentrics_at(*m, want.x[at], want.y[at], P.view_coord[view]);
      const double c = ref::shade(scene, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, light)[int(at % 3)];
      if (std::abs(double(float(value)) - c) > std::ldexp(std::abs(c), -10) + 1e-4 && ++colour_bad <= 5)
        ADD_FAILURE() << "subpixel " << at << ": " << float(value) << ", reference " << c;
    }
    // alpha: the mean coverage of the pixel's three subpixels, computed as the encoder does
    for (size_t px = 0; px < size_t(d.width) * d.height; ++px) {
      const half a[3] = {half(want.key[3 * px] != PMR_NO_KEY ? 1.0f : 0.0f),
                         half(want.key[3 * px + 1] != PMR_NO_KEY ? 1.0f : 0.0f),
                         half(want.key[3 * px + 2] != PMR_NO_KEY ? 1.0f : 0.0f)};
      const half alpha((float(a[0]) + float(a[1]) + float(a[2])) / 3.0f);
      if (got.display[px * 4 + 3] != alpha.bits() && ++alpha_bad <= 5)
        ADD_FAILURE() << "display pixel " << px << ": alpha bits " << got.display[px * 4 + 3] << ", want "
                      << alpha.bits();
      const int a0 = int(a[0]), a1 = int(a[1]), a2 = int(a[2]);
      straddles_seen += (a0 + a1 + a2) % 3 != 0;
    }
    EXPECT_EQ(key_bad + depth_bad + colour_bad + alpha_bad, 0u);

    // the same image from another tile shape (other chunks, other straddling pixels)
    const int* other = tiles[(trial + 2) % 5];
    EXPECT_EQ(render_subpixels(scene, rig, d, other).display, got.display)
        << "tile " << other[0] << "x" << other[1] << "x" << other[2] << " gives another image";
  }
  EXPECT_GT(covered_total, 10000u) << "too few covered subpixels for the test to mean much";
  EXPECT_GT(straddles_seen, 100u) << "too few partly covered display pixels";
}

// The pattern of S samples per pixel (DESIGN section 3b, Direct3D's, in 1/16 pixel) scaled to a display
// pixel's footprint in the view, (W / W_d, H / H_d) view pixels, and rounded to the raster's fixed point.
void scaled_pattern(int S, const Rig& rig, const Display& d, PmrParams& P) {
  static const int four[] = PMR_SAMPLE_PATTERN_4, eight[] = PMR_SAMPLE_PATTERN_8, sixteen[] = PMR_SAMPLE_PATTERN_16;
  const int* pattern = S == 4 ? four : S == 8 ? eight : sixteen;
  P.samples = uint32_t(S);
  for (int t = 0; t < S; ++t) {
    P.sample_x[t] = int32_t(std::lround(pattern[2 * t] / 16.0 * rig.view_w / d.width * PMR_X_ONE));
    P.sample_y[t] = int32_t(std::lround(pattern[2 * t + 1] / 16.0 * rig.view_h / d.height * PMR_Y_ONE));
  }
}

// Subpixel `at`'s expected colour channel and coverage with S samples: each distinct winner (by key) of
// its samples shaded once in double precision at its shading point (the subpixel's own sample where the
// triangle covers it, else the truncated mean of the samples it covers), weighted by its share.
std::pair<double, double> resolved_subpixel(const Scene& scene, const PmrParams& P,
                                            const std::vector<ref::ClippedTriangle>& clipped,
                                            const std::vector<PmrMta>& mtas, const ref::SubpixelResult& want, int view,
                                            size_t at, const glm::dvec3& light) {
  const size_t S = P.samples;
  double colour = 0.0, alpha = 0.0;
  for (size_t t = 0; t < S; ++t) {
    const uint32_t key = want.key[at * S + t];
    bool first = key != PMR_NO_KEY;
    for (size_t u = 0; u < t; ++u) first = first && want.key[at * S + u] != key;
    if (!first) continue;
    const int won = int(std::count(want.key.begin() + long(at * S), want.key.begin() + long(at * S + S), key));
    const ref::ClippedTriangle* c = nullptr;
    for (const ref::ClippedTriangle& k : clipped) c = k.key == key ? &k : c;
    const PmrMta* m = nullptr;
    for (const PmrMta& k : mtas) m = k.key == key && view >= k.view_lo && view <= k.view_hi ? &k : m;
    if (!c || !m) ADD_FAILURE() << "no triangle for key " << key;
    if (!c || !m) continue;
    const ref::ViewTriangle tri = ref::view_triangle(*c, P.view_coord[view]);
    int64_t X = want.x[at], Y = want.y[at];
    if (!ref::covers(tri, X, Y)) {
      int64_t sx = 0, sy = 0, n = 0;
      for (size_t u = 0; u < S; ++u)
        if (ref::covers(tri, X + P.sample_x[u], Y + P.sample_y[u])) sx += P.sample_x[u], sy += P.sample_y[u], ++n;
      X += sx / n, Y += sy / n;
    }
    const glm::dvec3 b = ref::source_barycentrics_at(*m, X, Y, P.view_coord[view]);
    const double weight = double(won) / double(S);
    colour += weight * ref::shade(scene, m->tri, b, (m->flags & PMR_MTA_BACK) != 0, light)[int(at % 3)];
    alpha += weight;
  }
  return {colour, alpha};
}

// With S = 4, 8 and 16 samples per pixel: every sample of every subpixel (the pattern scaled to a display
// pixel's footprint around the subpixel's own sample) has the reference's key and depth, bit for bit;
// each subpixel's colour channel is the box mean of its winners shaded at their shading points (within
// the half-float tolerance above) and its alpha the covered fraction, exactly; other tile shapes give the
// same image.
TEST(SubpixelSampling, SamplesPerPixelEqualDirectEvaluation) {
  std::mt19937 rng(20261203);
  const int counts[] = {4, 8, 16}, tiles[][3] = {{16, 2, 16}, {5, 3, 3}, {8, 4, 2}};
  size_t partial = 0;
  for (int trial = 0; trial < 3; ++trial) {
    const int S = counts[trial];
    Display d;
    d.width = 37 + 11 * trial, d.height = 23 + 5 * trial;
    d.lens_pitch = parse_rational(random_decimal(rng, 3.0, 12.0, 10), "L");
    d.tan_slant = parse_rational(random_decimal(rng, -0.3, 0.3, 12), "T");
    d.offset = parse_rational(random_decimal(rng, -10.0, 10.0, 9), "O");
    RigConfig rc;
    rc.views = 7 + 6 * trial, rc.view_w = 29 + 9 * trial, rc.view_h = 17 + 4 * trial;
    rc.angular_spacing = trial == 1;
    const Rig rig = make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
    const Scene scene = test::random_scene(80, 950u + unsigned(trial), trial != 1);
    SCOPED_TRACE(std::to_string(S) + " samples");
    const SubpixelRender got = render_subpixels(scene, rig, d, tiles[trial], S);
    PmrParams P = test::params_for(rig);
    scaled_pattern(S, rig, d, P);
    std::vector<PmrVertex> verts;
    for (const auto& p : scene.positions) verts.push_back(ref::transform_vertex(P, &p.x));
    const auto clipped = ref::clip_triangles(P, scene, verts);
    const std::vector<int> view_of = test::table_view_indices(d, rc.views);
    const ref::SubpixelResult want = ref::rasterize_subpixels(P, clipped, view_of, d.width, d.height);
    ASSERT_EQ(got.key.size(), want.key.size());
    size_t bad = 0;
    for (size_t k = 0; k < want.key.size(); ++k)
      if ((got.key[k] != want.key[k] || std::memcmp(&got.depth[k], &want.depth[k], 4) != 0) && ++bad <= 5)
        ADD_FAILURE() << "subpixel " << k / S << " sample " << k % S << ": key " << got.key[k] << " depth "
                      << got.depth[k] << ", reference " << want.key[k] << " " << want.depth[k];
    std::vector<half> sub_alpha(want.x.size());
    for (size_t at = 0; at < want.x.size(); ++at) {
      const auto [c, a] = resolved_subpixel(scene, P, clipped, got.mtas, want, view_of[at], at, rig.light_world());
      half value;
      value.setBits(got.display[(at / 3) * 4 + at % 3]);
      if (std::abs(double(float(value)) - c) > std::ldexp(std::abs(c), -10) + 1e-4 && ++bad <= 5)
        ADD_FAILURE() << "subpixel " << at << ": " << float(value) << ", reference " << c;
      sub_alpha[at] = half(float(a));
      partial += a > 0.0 && a < 1.0;
    }
    for (size_t px = 0; px < size_t(d.width) * d.height; ++px) {
      const half alpha((float(sub_alpha[3 * px]) + float(sub_alpha[3 * px + 1]) + float(sub_alpha[3 * px + 2])) / 3.0f);
      if (got.display[px * 4 + 3] != alpha.bits() && ++bad <= 5)
        ADD_FAILURE() << "display pixel " << px << ": alpha " << got.display[px * 4 + 3] << ", want " << alpha.bits();
    }
    EXPECT_EQ(bad, 0u);
    EXPECT_EQ(render_subpixels(scene, rig, d, tiles[(trial + 1) % 3], S).display, got.display) << "another tile shape";
  }
  EXPECT_GT(partial, 300u) << "too few partly covered subpixels for the test to mean much";
}

// The fill rule at samples lying exactly on edges: a grid mesh on the focal plane (the same in every
// view) whose vertices sit on sample positions, so that its horizontal and vertical edges pass through
// whole rows and columns of samples. Neighbouring triangles are coplanar: a sample owned by both (or by
// neither) would show in the keys. Sizes are chosen so that the samples are exact in fixed point: with
// W / W_d = 3/2 sample x = (2s + 1) / 4 px, with H / H_d = 2 sample y = 2i + 1 px.
TEST(SubpixelSampling, SamplesOnEdgesFollowTheTopLeftRule) {
  Display d;
  d.width = 64, d.height = 32;
  RigConfig rc;
  rc.views = 8, rc.view_w = 96, rc.view_h = 64;
  const Rig rig = make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
  Scene scene = test::empty_scene(false);
  // grid lines through sample columns s = 9c + 4 and sample rows i = 4r + 2
  auto corner = [&](int c, int r) {
    return test::focal_point(rig, (2.0 * (9 * c + 4) + 1.0) / 4.0, 2.0 * (4 * r + 2) + 1.0);
  };
  for (int r = 0; r + 1 < 7; ++r)
    for (int c = 0; c + 1 < 20; ++c) {
      const glm::vec3 a = corner(c, r), b = corner(c + 1, r), e = corner(c + 1, r + 1), f = corner(c, r + 1);
      // counter-clockwise seen from the camera (raster y points down), the first vertex rotated so
      // that each of the kernel's three edges meets every kind of edge (top, left, right, bottom)
      const glm::vec3 t[2][3] = {{a, f, (r + c) % 2 ? b : e}, {(r + c) % 2 ? f : a, e, b}};
      for (int k = 0; k < 2; ++k) {
        const int rot = (c + 2 * r + k) % 3;
        test::add_triangle(scene, t[k][rot], t[k][(rot + 1) % 3], t[k][(rot + 2) % 3]);
      }
    }
  const PmrParams P = test::params_for(rig);
  std::vector<PmrVertex> verts;
  for (const auto& p : scene.positions) verts.push_back(ref::transform_vertex(P, &p.x));
  const auto clipped = ref::clip_triangles(P, scene, verts);
  const std::vector<int> view_of = test::table_view_indices(d, rc.views);
  const ref::SubpixelResult want = ref::rasterize_subpixels(P, clipped, view_of, d.width, d.height);
  // how many samples lie exactly on an edge of some triangle (the point of this test)
  size_t on_edge = 0;
  for (size_t at = 0; at < want.key.size(); ++at)
    for (const ref::ClippedTriangle& c : clipped) {
      const int64_t v = view_of[at];
      const int ea[3] = {1, 2, 0}, eb[3] = {2, 0, 1};
      for (int k = 0; k < 3; ++k) {
        const int64_t xa = int64_t(c.v[ea[k]].x0) + v * c.v[ea[k]].dx, xb = int64_t(c.v[eb[k]].x0) + v * c.v[eb[k]].dx;
        const int64_t ya = c.v[ea[k]].y, yb = c.v[eb[k]].y;
        const bool between = std::min(ya, yb) <= want.y[at] && want.y[at] <= std::max(ya, yb) &&
                             std::min(xa, xb) <= want.x[at] && want.x[at] <= std::max(xa, xb);
        on_edge += between && (yb - ya) * (want.x[at] - xa) - (xb - xa) * (want.y[at] - ya) == 0;
      }
    }
  EXPECT_GT(on_edge, 1000u) << "the grid's edges should pass through many samples";
  const int tiles[2][3] = {{16, 2, 16}, {5, 3, 3}};
  for (const auto& tile : tiles) {
    const SubpixelRender got = render_subpixels(scene, rig, d, tile);
    size_t bad = 0, covered = 0;
    for (size_t at = 0; at < want.key.size(); ++at) {
      covered += want.key[at] != PMR_NO_KEY;
      if (got.key[at] != want.key[at] && ++bad <= 5)
        ADD_FAILURE() << "subpixel " << at << " (sample " << want.x[at] << ", " << want.y[at] << "): key "
                      << got.key[at] << ", reference " << want.key[at];
    }
    EXPECT_EQ(bad, 0u);
    EXPECT_GT(covered, 3000u);
  }
}

// The quality measure on small configurations: against --sampling view with 4x finer views
// (nearest), subpixel sampling has a lower RMSE and fewer differing subpixels than --sampling view at
// the standard size, with or without bilinear sampling. Display and views in the paper-8k proportions
// (7.5 display pixels per view pixel across, ~8.4 down), on the bundled scene and on real models.
TEST(SubpixelSampling, CloserToAFinerReferenceThanViewSampling) {
  std::vector<std::string> scenes = {std::string(PMR_SOURCE_DIR) + "/data/default_scene.glb"};
  if (test::corpus_dir().empty())
    std::printf("[  NOTE    ] ../shared/gltf is absent: the real-model cases are skipped\n");
  else
    for (const char* m : {"Duck/glTF-Binary/Duck.glb", "Avocado/glTF/Avocado.gltf"})
      scenes.push_back(test::corpus_dir() + "/" + m);
  Display d;
  d.width = 480, d.height = 270;
  RigConfig rc;
  rc.views = 12, rc.view_w = 64, rc.view_h = 32;
  for (const std::string& path : scenes) {
    SCOPED_TRACE(path);
    const Scene scene = load_scene(path);
    const std::vector<SamplingQualityRow> rows = sampling_quality(test::runtime(), scene, rc, d, 4);
    ASSERT_EQ(rows.size(), 4u);
    const SamplingQualityRow &sub = rows[1], &view = rows[2], &bilinear = rows[3];
    EXPECT_EQ(rows[0].view_w, 4 * rc.view_w);
    EXPECT_GT(view.error.rmse, 0.0) << "the standard views should differ from the finer reference";
    EXPECT_LT(sub.error.rmse, 0.75 * view.error.rmse);
    EXPECT_LT(sub.error.rmse, 0.75 * bilinear.error.rmse);
    EXPECT_LT(sub.error.differing, view.error.differing);
    EXPECT_LT(sub.error.differing, bilinear.error.differing);
  }
}

// With a product that needs the views (--write views), the views are rendered on their grids as with
// --sampling view, and the display image is the same as without them.
TEST(SubpixelSampling, ViewsStillRenderedOnTheirGridsWhenAsked) {
  const Scene scene = test::random_scene(80, 4242u, true);
  Display d;
  d.width = 96, d.height = 54;
  RigConfig rc;
  rc.views = 9, rc.view_w = 40, rc.view_h = 24;
  const Rig rig = make_rig(rc, d, glm::dvec3(-1.0), glm::dvec3(1.0));
  auto render = [&](Sampling sampling, bool fuse, std::vector<uint16_t>* volume) {
    PipelineConfig pc;
    pc.sampling = sampling;
    pc.fuse_encode = fuse;
    test::EncodedRender r = test::render_encoded(scene, rig, d, pc);
    EXPECT_EQ(r.has_volume, volume != nullptr);
    if (volume) volume->swap(r.volume);
    return r.image;
  };
  std::vector<uint16_t> views_sub, views_view;
  const std::vector<uint16_t> alone = render(Sampling::Subpixel, true, nullptr);
  const std::vector<uint16_t> with_views = render(Sampling::Subpixel, false, &views_sub);
  render(Sampling::View, false, &views_view);
  EXPECT_EQ(with_views, alone);
  EXPECT_EQ(views_sub, views_view);
  size_t drawn = 0;
  for (size_t i = 3; i < alone.size(); i += 4) drawn += alone[i] != 0;
  EXPECT_GT(drawn, alone.size() / 40);
}

TEST(SubpixelSampling, CommandLine) {
  const std::string out = test::temp_dir("subpixel_cli");
  test::expect_usage_error(test::run("render --sampling pixel --out " + out), "unknown sampling 'pixel'");
  test::expect_usage_error(test::run("render --sampling subpixel --bilinear --out " + out), "--bilinear");
  test::expect_usage_error(test::run("render --sampling subpixel --method multipass --out " + out), "--method pmr");
  test::expect_usage_error(test::run("render --sampling subpixel --blend-views --out " + out), "--blend-views");
  EXPECT_EQ(test::count_entries(out), 0u) << "nothing written on bad options";
  test::expect_usage_error(test::run("bench --sampling subpixel --method multipass --views 2"), "--method pmr");
  test::expect_usage_error(test::run("bench --sampling view,subpixel --bilinear --views 2"), "--bilinear");
  // without the encoded image there is nothing to sample per subpixel: a warning, the views as usual
  const std::string views_only = test::temp_dir("subpixel_views_only");
  const test::CliRun v = test::run(
      "render --sampling subpixel --write views --views 4 --view-size 32x16 --display 96x54 --out " + views_only);
  ASSERT_EQ(v.status, 0) << v.output;
  EXPECT_NE(v.output.find("warning: --sampling subpixel samples the encoded image"), std::string::npos) << v.output;
  EXPECT_TRUE(test::exists(views_only + "/frame_0000.views.exr"));
  const std::string small = " --views 6 --view-size 48x24 --display 160x90 --out " + out;
  const test::CliRun r = test::run("render --sampling subpixel --write encoded,views" + small);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(test::exists(out + "/frame_0000.exr"));
  EXPECT_TRUE(test::exists(out + "/frame_0000.views.exr"));
  EXPECT_NE(test::read_file(out + "/frame_0000.json").find("\"sampling\": \"subpixel\""), std::string::npos);
  // angular camera spacing (a Looking Glass preset's) renders subpixel sampling with PMR
  const std::string lg = test::temp_dir("subpixel_angular");
  const test::CliRun a = test::run(
      "render --sampling subpixel --preset lg-portrait --views 6 --view-size 42x56 "
      "--display 153x204 --out " +
      lg);
  ASSERT_EQ(a.status, 0) << a.output;
  const std::string sidecar = test::read_file(lg + "/frame_0000.json");
  EXPECT_NE(sidecar.find("\"sampling\": \"subpixel\""), std::string::npos);
  EXPECT_NE(sidecar.find("\"camera_spacing\": \"angular\""), std::string::npos);
  EXPECT_NE(sidecar.find("\"method\": \"pmr\""), std::string::npos);
  // lg-portrait defaults to subpixel sampling; options that need the views turn the default (not an
  // explicit --sampling subpixel) back to view sampling, with one line of notice
  const std::string lg_small = " --preset lg-portrait --views 6 --view-size 42x56 --display 153x204 --out ";
  const test::CliRun def = test::run("render" + lg_small + lg + "/default");
  ASSERT_EQ(def.status, 0) << def.output;
  EXPECT_NE(test::read_file(lg + "/default/frame_0000.json").find("\"sampling\": \"subpixel\""), std::string::npos);
  for (const std::string opt : {"--bilinear", "--blend-views", "--method multipass"}) {
    const std::string dir = lg + "/fallback" + std::to_string(opt.size());
    const test::CliRun f = test::run("render " + opt + lg_small + dir);
    ASSERT_EQ(f.status, 0) << f.output;
    EXPECT_NE(f.output.find("warning: " + opt + " samples the rendered views: --sampling view instead"),
              std::string::npos)
        << f.output;
    EXPECT_NE(test::read_file(dir + "/frame_0000.json").find("\"sampling\": \"view\""), std::string::npos) << opt;
    test::expect_usage_error(test::run("render --sampling subpixel " + opt + lg_small + dir + "x"),
                             opt == "--method multipass" ? "--method pmr" : opt);
  }
  // pmr bench --preset measures the preset as a user gets it: angular spacing, subpixel sampling
  const test::CliRun b =
      test::run("bench --preset lg-portrait --views 2 --view-size 42x56 --frames 1 --no-check --method pmr");
  ASSERT_EQ(b.status, 0) << b.output;
  EXPECT_NE(b.output.find("pmr        subpixel"), std::string::npos) << b.output;
  EXPECT_EQ(b.output.find("pmr        view"), std::string::npos) << b.output;
  // --resume keeps frames of the same sampling and refuses another
  EXPECT_EQ(test::run("render --sampling subpixel --write encoded,views --resume" + small).status, 0);
  test::expect_one_error_line(test::run("render --write encoded,views --resume" + small), "sampling differs");
}

// With a view raster of 3 W_d x H_d every subpixel's sample is exactly the center of view pixel
// (3j + k, i): subpixel sampling must then give view sampling's image, alphaMode MASK (alpha tested at the
// sample through a texture with holes) and double-sided triangles included, bit for bit: both paths
// evaluate the one depth formula (cl/common.h DepthPlane), so even surfaces within rounding of each other
// resolve alike.
TEST(SubpixelSampling, EqualsViewSamplingWhereSamplesArePixelCenters) {
  Scene scene = test::random_scene(200, 31337u, true);
  SceneTexture holes;
  holes.width = 2, holes.height = 2, holes.wrap_s = holes.wrap_t = PMR_WRAP_REPEAT;
  holes.rgba = {200, 60, 30, 255, 10, 10, 10, 0, 10, 10, 10, 0, 30, 90, 220, 255};
  scene.textures.push_back(holes);
  PmrMaterial mask = scene.materials[0];
  mask.alpha_mode = PMR_ALPHA_MASK;
  mask.alpha_cutoff = 0.5f;
  scene.materials.push_back(mask);
  test::base_colour_texture(scene, uint32_t(scene.materials.size() - 1), 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uv(0.0f, 3.0f);
  for (size_t t = 0; t < scene.triangles.size(); t += 2)
    scene.triangles[t].material = uint32_t(scene.materials.size() - 1);
  // z-fighting: coplanar copies anchored at another vertex (their depths differ from the originals' by
  // rounding alone), in another material, so that which surface wins shows in the colour
  const size_t originals = scene.triangles.size();
  for (size_t t = 0; t < originals; t += 3) {
    PmrTriangle copy = scene.triangles[t];
    copy.v[0] = scene.triangles[t].v[1], copy.v[1] = scene.triangles[t].v[2], copy.v[2] = scene.triangles[t].v[0];
    copy.material = (copy.material + 1) % uint32_t(scene.materials.size());
    scene.triangles.push_back(copy);
  }
  for (size_t v = 0; v < scene.positions.size(); ++v) {
    const float u = uv(rng);
    test::texcoord(scene, 0, v) = glm::vec2(u, uv(rng));
  }
  Display d;
  const Rig rig = test::subpixel_display_rig(d);
  auto render = [&](Sampling sampling) {
    PipelineConfig pc;
    pc.sampling = sampling;
    pc.fuse_encode = true;
    return test::render_encoded(scene, rig, d, pc).image;
  };
  const std::vector<uint16_t> sub = render(Sampling::Subpixel), view = render(Sampling::View);
  ASSERT_EQ(sub.size(), view.size());
  size_t differ = 0, drawn = 0, holes_seen = 0;
  for (size_t px = 0; px < sub.size() / 4; ++px) {
    bool same = true;
    for (int c = 0; c < 4; ++c) same = same && sub[px * 4 + size_t(c)] == view[px * 4 + size_t(c)];
    differ += !same;
    drawn += view[px * 4 + 3] != 0;
    holes_seen += view[px * 4 + 3] != 0 && view[px * 4 + 3] != half(1.0f).bits();
  }
  EXPECT_EQ(differ, 0u) << differ << " of " << sub.size() / 4 << " display pixels differ";
  EXPECT_GT(drawn, sub.size() / 4 / 4);
  EXPECT_GT(holes_seen, 10u) << "partly covered pixels (edges, mask holes) should occur";
}

TEST(SubpixelSampling, ImageDifferenceCountsColourChannelsOnly) {
  // two pixels: alpha differs everywhere (ignored), one colour channel by 0.5, one by 2^-9 (under the
  // differing threshold)
  const std::vector<uint16_t> a = {half(0.5f).bits(), 0, half(0.25f).bits(), half(1.0f).bits(), 0, 0, 0, 0};
  const std::vector<uint16_t> b = {half(0.0f).bits(), 0, half(0.25f + 1.0f / 512).bits(), 0, 0, 0, 0,
                                   half(1.0f).bits()};
  const ImageDifference d = compare_display_images(a, b);
  EXPECT_NEAR(d.rmse, std::sqrt((0.25 + 1.0 / (512.0 * 512.0)) / 6.0), 1e-9);
  EXPECT_NEAR(d.rmse_shown, d.rmse, 1e-12) << "values within [0, 1] are shown as they are";
  EXPECT_DOUBLE_EQ(d.differing, 1.0 / 6.0);
}

// rmse_shown compares what a panel shows: values clamped to [0, 1], so a highlight of 10^4 or an
// infinite half counts as 1.
TEST(SubpixelSampling, ShownDifferenceClampsToTheDisplayRange) {
  const uint16_t inf = 0x7c00u;
  const std::vector<uint16_t> a = {half(1.0e4f).bits(), inf, half(-2.0f).bits(), 0, half(0.5f).bits(), 0, 0, 0};
  const std::vector<uint16_t> b = {
      half(0.0f).bits(), half(1.0f).bits(), half(0.0f).bits(), 0, half(2.0f).bits(), 0, 0, 0};
  const ImageDifference d = compare_display_images(a, b);
  EXPECT_NEAR(d.rmse_shown, std::sqrt((1.0 + 0.25) / 6.0), 1e-12);
  EXPECT_TRUE(std::isinf(d.rmse)) << "the linear RMSE keeps the infinite value";
}

}  // namespace
}  // namespace pmr
