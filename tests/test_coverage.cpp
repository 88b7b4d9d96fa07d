// Coverage properties of the whole pipeline: watertightness, the fill rule on exact pixel-center
// hits, clipping (near plane, guard band, huge triangles), tile bins, and determinism, for linear and
// angular camera spacing.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "reference/reference.h"
#include "test_util.h"

namespace pmr {
namespace {

// Compares every voxel's key, depth and count with the reference; returns the covered voxel count.
size_t expect_matches_reference(const Scene& scene, const Rig& rig, const test::Rendered& out, int samples = 1) {
  PmrParams P = test::params_for(rig);
  set_sample_pattern(samples, P);
  const ref::RasterResult r = ref::render(P, scene);
  size_t covered = 0, mismatches = 0;
  for (size_t v = 0; v < r.key.size(); ++v) {
    const bool same =
        out.count[v] == r.count[v] && out.key[v] == r.key[v] && (r.key[v] == PMR_NO_KEY || out.depth[v] == r.depth[v]);
    if (!same && ++mismatches <= 5)
      ADD_FAILURE() << "voxel " << v << ": key " << out.key[v] << " vs " << r.key[v] << ", count " << out.count[v]
                    << " vs " << r.count[v];
    covered += r.key[v] != PMR_NO_KEY;
  }
  EXPECT_EQ(mismatches, 0u);
  return covered;
}

// A mesh of G x G cells of shared-edge triangles covering the whole screen in every view (its border
// vertices two cells beyond it), inner vertices jittered by up to `jitter` cells and, but for every third,
// off the focal plane by up to `depth` focal lengths (0: exact in every view), the whole grid shifted by
// `offset` pixels (half a pixel puts the vertices of a grid of whole-pixel cells on pixel centers).
Scene grid_mesh(const Rig& rig, int G, double jitter_cells, double depth_range, uint32_t seed, double offset = 0.0) {
  Scene s = test::empty_scene();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-jitter_cells, jitter_cells), depth(-depth_range, depth_range);
  std::vector<uint32_t> grid((G + 1) * (G + 1));
  for (int j = 0; j <= G; ++j)
    for (int i = 0; i <= G; ++i) {
      // raster position of the vertex in the center view, beyond the screen at the border
      const bool inner = i > 0 && i < G && j > 0 && j < G;
      const double x = (i - 2.0 + (inner && jitter_cells > 0 ? jitter(rng) : 0.0)) * rig.view_w / (G - 4.0) + offset;
      const double y = (j - 2.0 + (inner && jitter_cells > 0 ? jitter(rng) : 0.0)) * rig.view_h / (G - 4.0) + offset;
      glm::vec3 p = test::focal_point(rig, x, y);
      const double dz = (i + j) % 3 == 0 || depth_range == 0 ? 0.0 : depth(rng) * rig.focal;
      p.x *= float((rig.focal + dz) / rig.focal);  // along the ray through the camera at (0,0,D)...
      p.y *= float((rig.focal + dz) / rig.focal);
      p.z = float(-dz);  // ...keeps the centre-view raster position
      grid[j * (G + 1) + i] = uint32_t(s.positions.size());
      s.positions.push_back(p);
      PmrVertexAttr a{};
      a.normal[2] = 1.0f;
      for (int k = 0; k < 4; ++k) a.color[k] = 1.0f;
      s.attributes.push_back(a);
    }
  for (int j = 0; j < G; ++j)
    for (int i = 0; i < G; ++i) {
      const uint32_t a = grid[j * (G + 1) + i], b = grid[j * (G + 1) + i + 1];
      const uint32_t c = grid[(j + 1) * (G + 1) + i], d = grid[(j + 1) * (G + 1) + i + 1];
      // raster y grows downwards, world y upwards: (a, c, b) is counter-clockwise in the world
      PmrTriangle t{};
      t.has_normals = 1;
      if ((i + j) % 2) {
        t.v[0] = a, t.v[1] = c, t.v[2] = b;
        s.triangles.push_back(t);
        t.v[0] = b, t.v[1] = c, t.v[2] = d;
        s.triangles.push_back(t);
      } else {
        t.v[0] = a, t.v[1] = c, t.v[2] = d;
        s.triangles.push_back(t);
        t.v[0] = a, t.v[1] = d, t.v[2] = b;
        s.triangles.push_back(t);
      }
    }
  return s;
}

// Every sample of every voxel covered exactly once, every pixel of alpha 1 (no seam along shared edges),
// and the reference's result.
void expect_watertight(const Scene& s, const Rig& rig, const PipelineConfig& pc, const std::string& what) {
  SCOPED_TRACE(what + ", N = " + std::to_string(rig.views) + ", S = " + std::to_string(pc.samples));
  const test::Rendered out = test::render_with(s, rig, pc);
  size_t bad = 0, seams = 0;
  for (size_t v = 0; v < out.count.size(); ++v) bad += out.count[v] != 1;
  for (size_t v = 0; v < out.volume.size(); v += 4) seams += out.volume[v + 3] != 0x3c00;  // alpha 1
  EXPECT_EQ(bad, 0u) << "samples not covered exactly once";
  EXPECT_EQ(seams, 0u) << "pixels whose samples' coverage does not sum to 1";
  expect_matches_reference(s, rig, out, pc.samples);
}

// Cells of about 10 pixels at varying depths, for 1, 4 and 16 samples per pixel.
TEST(Coverage, WatertightMeshCoversEveryVoxelExactlyOnce) {
  for (bool angular : test::kSpacings)
    for (int views : {1, 7, 96}) {
      const Rig rig = test::small_rig(views, 61, 37, angular);
      const Scene s = grid_mesh(rig, 10, 0.15, 0.008, 7);
      for (int samples : {1, 4, 16}) {
        if (samples == 16 && views != 7) continue;  // (time)
        PipelineConfig pc;
        pc.tile_x = pc.tile_y = pc.tile_v = 4;
        pc.samples = samples;
        expect_watertight(s, rig, pc, test::spacing_name(angular));
      }
    }
}

// Cells of one to two pixels in the default tiles, where the fine raster's small-triangle path takes
// most queue entries: jittered at varying depths, and unjittered on the focal plane in cells of 2 x 2
// pixels with every vertex on a pixel center and every edge through pixel centers (the top-left rule
// decides each of those samples).
TEST(Coverage, TinyTrianglesCoverEveryVoxelExactlyOnce) {
  for (bool angular : test::kSpacings) {
    const Rig rig = test::small_rig(24, 40, 40, angular);
    PipelineConfig pc;  // the default tiles
    for (int samples : {1, 4}) {
      pc.samples = samples;
      expect_watertight(grid_mesh(rig, 30, 0.2, 0.002, 11), rig, pc,
                        std::string("jittered, ") + test::spacing_name(angular));
      expect_watertight(grid_mesh(rig, 24, 0.0, 0.0, 0, 0.5), rig, pc,
                        std::string("on pixel centers, ") + test::spacing_name(angular));
    }
  }
}

// Triangles whose vertices and edges pass exactly through pixel centers (focal plane: zero disparity,
// so the positions are exact in every view): horizontal and vertical edges, shared edges, a fan
// around a pixel center, sub-pixel and degenerate triangles.
TEST(Coverage, FillRuleOnPixelCentersMatchesReference) {
  for (bool angular : test::kSpacings) {
    SCOPED_TRACE(test::spacing_name(angular));
    const Rig rig = test::small_rig(5, 32, 16, angular);
    Scene s = test::empty_scene();
    auto P = [&](double x, double y) { return test::focal_point(rig, x, y); };
    // a square split along its diagonal, corners on pixel centers
    s.positions.clear();
    test::add_triangle(s, P(2.5, 2.5), P(2.5, 8.5), P(8.5, 8.5));
    test::add_triangle(s, P(2.5, 2.5), P(8.5, 8.5), P(8.5, 2.5));
    // a fan of 6 triangles around the pixel center (16.5, 8.5)
    const double cx = 16.5, cy = 8.5;
    const double ring[6][2] = {{4, 0}, {2, 3}, {-2, 3}, {-4, 0}, {-2, -3}, {2, -3}};
    for (int k = 0; k < 6; ++k) {
      const auto& a = ring[k];
      const auto& b = ring[(k + 1) % 6];
      // counter-clockwise in the world = clockwise in raster (y down): center, b, a
      test::add_triangle(s, P(cx, cy), P(cx + b[0], cy + b[1]), P(cx + a[0], cy + a[1]));
    }
    // thin and sub-pixel triangles on pixel-center rows
    test::add_triangle(s, P(24.5, 3.5), P(24.5, 3.5 + 1e-3), P(30.5, 3.5));
    test::add_triangle(s, P(25.2, 10.1), P(25.4, 10.9), P(25.9, 10.3));
    test::add_triangle(s, P(26.5, 12.5), P(26.5, 12.5), P(29.5, 14.5));  // degenerate
    const test::Rendered out = test::render(s, rig);
    const size_t covered = expect_matches_reference(s, rig, out);
    EXPECT_GT(covered, 5u * 60u);
    // the shared diagonal and the fan's spokes are owned by exactly one triangle
    for (size_t v = 0; v < out.count.size(); ++v) EXPECT_LE(out.count[v], 1u) << "voxel " << v;
    // the fan covers its center pixel
    for (int i = 0; i < 5; ++i) EXPECT_EQ(out.count[(size_t(i) * 16 + 8) * 32 + 16], 1u);
  }
}

// Near-plane crossing, behind-the-camera and guard-band-sized triangles against the reference.
TEST(Coverage, ClippedTrianglesMatchReference) {
  for (bool angular : test::kSpacings)
    for (int views : {1, 8, 96}) {
      SCOPED_TRACE(test::spacing_name(angular));
      const Rig rig = test::small_rig(views, 40, 24, angular);
      Scene s = test::empty_scene(true);
      const float D = float(rig.focal);
      // a floor from behind the camera to beyond the far plane
      test::add_triangle(s, {-50, -1, D + 30}, {50, -1, D + 30}, {0, -1, -D - 40});
      // a huge wall far larger than the guard band, slightly tilted
      test::add_triangle(s, {-1e5f, -1e5f, -0.5f}, {1e5f, -1e5f, -0.2f}, {0, 1e5f, 0.1f});
      // crossing the near plane diagonally
      test::add_triangle(s, {-0.5f, 0.2f, D + 1.0f}, {0.7f, -0.3f, -0.5f}, {0.6f, 0.8f, 0.0f});
      const test::Rendered out = test::render(s, rig);
      const size_t covered = expect_matches_reference(s, rig, out);
      // the huge wall alone covers every voxel
      EXPECT_EQ(covered, out.key.size()) << "N = " << views;
      EXPECT_GT(out.mtas.size(), 3u) << "clipping should have produced fans";
    }
}

// Every tile that holds a covered voxel has the covering MTA in its queue.
TEST(Coverage, TileBinsContainEveryCoveredVoxel) {
  const Scene scene = test::random_scene(50, 99, true);
  for (bool angular : test::kSpacings)
    for (auto tile : {std::array<int, 3>{4, 4, 4}, std::array<int, 3>{8, 2, 3}, std::array<int, 3>{1, 1, 1}}) {
      SCOPED_TRACE(test::spacing_name(angular));
      const Rig rig = test::small_rig(9, 37, 21, angular);
      PipelineConfig pc;
      pc.tile_x = tile[0], pc.tile_y = tile[1], pc.tile_v = tile[2];
      pc.debug_outputs = true;
      Pipeline p(test::runtime(), pc);
      p.set_scene(scene);
      p.configure(rig, nullptr);
      p.render(rig);
      const std::vector<PmrMta> mtas = p.read_mtas();
      std::vector<uint32_t> offsets, queue;
      p.read_tile_queues(offsets, queue);
      const PmrParams P = test::params_for(rig, tile[0], tile[1], tile[2]);
      size_t checked = 0;
      for (uint32_t id = 0; id < mtas.size(); ++id) {
        // reference coverage of this MTA alone, view by view
        ref::ClippedTriangle c;
        for (int k = 0; k < 3; ++k) {
          c.v[k].x0 = mtas[id].x0[k], c.v[k].dx = mtas[id].dx[k], c.v[k].y = mtas[id].y[k];
          c.v[k].z = mtas[id].z[k];
        }
        c.double_sided = true;
        const ref::RasterResult r = ref::rasterize(P, {c});
        for (size_t v = 0; v < r.count.size(); ++v) {
          if (!r.count[v]) continue;
          const int view = int(v / (size_t(rig.view_w) * rig.view_h));
          if (view < mtas[id].view_lo || view > mtas[id].view_hi) continue;
          const int px = int(v % rig.view_w), py = int((v / rig.view_w) % rig.view_h);
          const uint32_t tile_id =
              (uint32_t(view / tile[2]) * P.tiles_y + uint32_t(py / tile[1])) * P.tiles_x + uint32_t(px / tile[0]);
          bool found = false;
          for (uint32_t q = offsets[tile_id]; q < offsets[tile_id + 1] && !found; ++q) found = queue[q] == id;
          ASSERT_TRUE(found) << "MTA " << id << " missing from tile " << tile_id;
          ++checked;
        }
      }
      EXPECT_GT(checked, 300u);
    }
}

// Identical bytes across runs and across tile / work-group shapes.
TEST(Coverage, DeterministicAcrossRunsAndTileSizes) {
  Scene scene = test::random_scene(300, 5, true);
  // coplanar duplicates force depth ties, resolved by key
  for (int i = 0; i < 40; ++i) {
    PmrTriangle t = scene.triangles[size_t(i)];
    scene.triangles.push_back(t);
  }
  for (bool angular : test::kSpacings) {
    SCOPED_TRACE(test::spacing_name(angular));
    const Rig rig = test::small_rig(12, 45, 27, angular);
    const test::Rendered a = test::render(scene, rig, 4, 4, 4);
    const test::Rendered b = test::render(scene, rig, 4, 4, 4);
    const test::Rendered c = test::render(scene, rig, 8, 2, 3);
    const test::Rendered d = test::render(scene, rig, 1, 1, 1);
    const test::Rendered e = test::render(scene, rig, 16, 2, 16);  // the default tile
    EXPECT_TRUE(a.volume == e.volume);
    EXPECT_TRUE(a.volume == b.volume);
    EXPECT_TRUE(a.volume == c.volume);
    EXPECT_TRUE(a.volume == d.volume);
    EXPECT_TRUE(a.key == c.key && a.key == d.key);
    size_t nonempty = 0;
    for (uint32_t k : a.key) nonempty += k != PMR_NO_KEY;
    EXPECT_GT(nonempty, a.key.size() / 10);
  }
}

}  // namespace
}  // namespace pmr
