// Specular antialiasing (DESIGN section 3b): with trilinear filtering, roughness widens where the normal
// varies inside a pixel's footprint, by the normal map's spread (Toksvig, from its mips) and by the
// interpolated normal's analytic derivatives (the geometric term). Checked against a supersampled
// reference: the same scene rendered at 8 x 8 times the pixels (where highlights and bumps are resolved)
// and box-filtered down.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "pipeline/material_tables.h"
#include "pipeline/texture_mips.h"
#include "test_util.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A normal map of P x P texel bumps: height A sin(2 pi x / P) sin(2 pi y / P), its slopes at most `slope`,
// n = normalize(-dh/dx, -dh/dy, 1) encoded as (n + 1) / 2. side x side texels, side a multiple of P.
SceneTexture bump_map(int side, int period, double slope) {
  SceneTexture t;
  t.width = t.height = side;
  const double k = 2.0 * kPi / period;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const double sx = (x + 0.5) * k, sy = (y + 0.5) * k;
      const glm::dvec3 n =
          glm::normalize(glm::dvec3(-slope * std::cos(sx) * std::sin(sy), -slope * std::sin(sx) * std::cos(sy), 1.0));
      for (int c = 0; c < 3; ++c) t.rgba.push_back(uint8_t(std::lround((n[c] + 1.0) * 0.5 * 255.0)));
      t.rgba.push_back(255);
    }
  return t;
}

// A UV sphere of radius r around c: white metal of the given roughness, smooth normals, tangents along
// the longitude and TEXCOORD_0 (u around, v pole to pole) scaled by `repeats`; with a normal map
// (texture 0) when `bumps`.
Scene sphere(glm::vec3 c, float r, float roughness, bool bumps, glm::vec2 repeats) {
  Scene s = test::empty_scene();
  SceneMaterialInputs in;
  in.metallic = 1.0f, in.roughness = roughness;
  in.slots[kSlotBaseColor].srgb = in.slots[kSlotEmissive].srgb = true;
  if (bumps) {
    s.textures.push_back(bump_map(64, 16, 0.3));
    in.slots[kSlotNormal].texture = 0, in.slots[kSlotNormal].texcoord = 0;
  }
  s.material_inputs.push_back(in);
  const int stacks = 64, slices = 128;
  s.texcoords.resize(1);
  for (int i = 0; i <= stacks; ++i)
    for (int j = 0; j <= slices; ++j) {
      const double theta = kPi * i / stacks, phi = 2.0 * kPi * j / slices;
      const glm::dvec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      s.positions.push_back(c + r * glm::vec3(n));
      PmrVertexAttr a{};
      for (int k = 0; k < 3; ++k) a.normal[k] = float(n[k]);
      for (int k = 0; k < 4; ++k) a.color[k] = 1.0f;
      s.attributes.push_back(a);
      s.tangents.emplace_back(float(-std::sin(phi)), 0.0f, float(std::cos(phi)), 1.0f);
      s.texcoords[0].emplace_back(repeats.x * float(j) / slices, repeats.y * float(i) / stacks);
    }
  const auto at = [&](int i, int j) { return uint32_t(i * (slices + 1) + j); };
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const uint32_t q[4] = {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
      for (const std::array<uint32_t, 3>& tri : {std::array<uint32_t, 3>{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}) {
        PmrTriangle t{};
        t.v[0] = tri[0], t.v[1] = tri[1], t.v[2] = tri[2];
        const glm::vec3 a = s.positions[t.v[0]], b = s.positions[t.v[1]], d = s.positions[t.v[2]];
        glm::vec3 f = glm::cross(b - a, d - a);
        if (glm::length(f) < 1e-12f) continue;  // the poles' degenerate halves
        if (glm::dot(f, a + b + d - 3.0f * c) < 0.0f) std::swap(t.v[1], t.v[2]), f = -f;  // outward: front
        f = glm::normalize(f);
        for (int k = 0; k < 3; ++k) t.face_normal[k] = f[k];
        t.has_normals = 1;
        s.triangles.push_back(t);
      }
    }
  return s;
}

// Radiance (R + G + B) of each pixel of each view, the reference box-filtered by `down` x `down`.
std::vector<double> radiance(const test::Rendered& r, const Rig& rig, int down) {
  const int w = rig.view_w / down, h = rig.view_h / down;
  std::vector<double> out(size_t(rig.views) * size_t(w) * size_t(h), 0.0);
  for (int v = 0; v < rig.views; ++v)
    for (int y = 0; y < rig.view_h; ++y)
      for (int x = 0; x < rig.view_w; ++x) {
        const size_t voxel = (size_t(v) * size_t(rig.view_h) + size_t(y)) * size_t(rig.view_w) + size_t(x);
        double sum = 0.0;
        for (int c = 0; c < 3; ++c) sum += double(test::half_value(r.volume[voxel * 4 + size_t(c)]));
        out[(size_t(v) * size_t(h) + size_t(y / down)) * size_t(w) + size_t(x / down)] += sum / (down * down);
      }
  return out;
}

// Per view: the highlight's energy (the sum of its pixels) and its core (the brightest 3 x 3 mean).
struct Highlight {
  double energy = 0.0, core = 0.0;
};

std::vector<Highlight> highlights(const std::vector<double>& img, int views, int w, int h) {
  std::vector<Highlight> out(static_cast<size_t>(views));
  for (int v = 0; v < views; ++v) {
    const double* p = &img[size_t(v) * size_t(w) * size_t(h)];
    for (int i = 0; i < w * h; ++i) out[size_t(v)].energy += p[i];
    for (int y = 1; y + 1 < h; ++y)
      for (int x = 1; x + 1 < w; ++x) {
        double sum = 0.0;
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) sum += p[(y + j) * w + x + i];
        out[size_t(v)].core = std::max(out[size_t(v)].core, sum / 9.0);
      }
  }
  return out;
}

constexpr float kRadius = 0.8f;

// views of 2 side x side pixels framing the sphere (radius kRadius around the origin)
Rig framed_rig(int views, int side) {
  RigConfig rc;
  rc.views = views;
  rc.view_w = 2 * side, rc.view_h = side;  // about square pixels
  rc.zoom = 1.3;
  return make_rig(rc, Display{}, glm::dvec3(-kRadius), glm::dvec3(kRadius));
}

PipelineConfig metal_only(int samples) {
  PipelineConfig pc;
  pc.samples = samples;
  pc.texture_filter = TextureFilter::Trilinear;
  pc.environment_intensity = 0.0;  // the default light alone: the image is its highlight
  return pc;
}

struct SphereCase {
  float roughness;
  bool bumps;
  glm::vec2 repeats;
};

// The sphere in 3 views of 64 x 32 (its radius 13.5 pixels) at S = 1 and 4 against the same views 8 x 8
// times finer, box-filtered: the highlights' energy and core in each view within the bounds (relative).
void expect_highlights_match(const SphereCase& sc, double energy_bound, double core_bound) {
  const int views = 3, side = 32, scale = 8;
  const Rig coarse = framed_rig(views, side), fine = framed_rig(views, side * scale);
  const Scene scene = sphere(glm::vec3(0.0f), kRadius, sc.roughness, sc.bumps, sc.repeats);
  const std::vector<Highlight> ref =
      highlights(radiance(test::render_with(scene, fine, metal_only(1)), fine, scale), views, 2 * side, side);
  for (int samples : {1, 4}) {
    const std::vector<Highlight> got =
        highlights(radiance(test::render_with(scene, coarse, metal_only(samples)), coarse, 1), views, 2 * side, side);
    for (int v = 0; v < views; ++v)
      std::printf("[ specular ] S %d view %d: energy %.3f of the reference's, core %.3f\n", samples, v,
                  got[size_t(v)].energy / ref[size_t(v)].energy, got[size_t(v)].core / ref[size_t(v)].core);
    for (int v = 0; v < views; ++v) {
      ASSERT_GT(ref[size_t(v)].core, 1.0) << "the reference shows a highlight";
      EXPECT_NEAR(got[size_t(v)].energy / ref[size_t(v)].energy, 1.0, energy_bound)
          << "S " << samples << " view " << v << ": energy " << got[size_t(v)].energy << " reference "
          << ref[size_t(v)].energy;
      EXPECT_NEAR(got[size_t(v)].core / ref[size_t(v)].core, 1.0, core_bound)
          << "S " << samples << " view " << v << ": core " << got[size_t(v)].core << " reference "
          << ref[size_t(v)].core;
    }
  }
}

}  // namespace

TEST(SpecularAntialiasing, NormalChainAveragesUnitNormalsAndKeepsTheirSpread) {
  // two normals tilted +-0.5 rad in x: their mean is (0, 0, cos 0.5), |n| = cos 0.5
  std::vector<uint8_t> rgba;
  double tilt[2][3];
  for (int x = 0; x < 2; ++x) {
    const double n[3] = {x == 0 ? -std::sin(0.5) : std::sin(0.5), 0.0, std::cos(0.5)};
    for (int c = 0; c < 3; ++c) rgba.push_back(uint8_t(std::lround((n[c] + 1.0) * 127.5)));
    rgba.push_back(255);
    double len = 0.0;
    for (int c = 0; c < 3; ++c)
      tilt[x][c] = 2.0 * rgba[size_t(4 * x + c)] / 255.0 - 1.0, len += tilt[x][c] * tilt[x][c];
    for (int c = 0; c < 3; ++c) tilt[x][c] /= std::sqrt(len);
  }
  const std::vector<uint8_t> mip = build_mips(rgba.data(), 2, 1, MipKind::Normal);
  ASSERT_EQ(mip.size(), 4u);
  double mean[3], len = 0.0;
  for (int c = 0; c < 3; ++c) mean[c] = 0.5 * (tilt[0][c] + tilt[1][c]), len += mean[c] * mean[c];
  len = std::sqrt(len);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mip[size_t(c)], (mean[c] + 1.0) * 127.5, 0.51) << "channel " << c;
  const double increment = 2.0 * (1.0 - len) / len;  // Toksvig's, about 0.28
  EXPECT_NEAR(mip[3], 255.0 * std::sqrt(increment), 0.51);
  EXPECT_NEAR(toksvig_increment(1.0), 0.0, 0.0);
  EXPECT_EQ(toksvig_increment(0.0), 1.0) << "opposite normals: as rough as can be";
  // a flat map keeps no spread at any level
  const std::vector<uint8_t> flat = {128, 128, 255, 255, 128, 128, 255, 255, 128, 128, 255, 255, 128, 128, 255, 255};
  EXPECT_EQ(build_mips(flat.data(), 2, 2, MipKind::Normal), (std::vector<uint8_t>{128, 128, 255, 0}));
}

TEST(SpecularAntialiasing, ANormalMapGetsItsOwnChainWithAZeroSpreadAtLevelZero) {
  Scene s = sphere(glm::vec3(0.0f), 1.0f, 0.5f, true, glm::vec2(1.0f));
  s.material_inputs[0].slots[kSlotOcclusion].texture = 0;  // the same image as a data map too
  const MaterialTables t = make_material_tables(s, true);
  ASSERT_EQ(t.textures.size(), 2u);
  EXPECT_EQ(t.materials[0].maps[PMR_MAP_OCCLUSION].texture, 0);
  EXPECT_EQ(t.materials[0].maps[PMR_MAP_NORMAL].texture, 1);
  EXPECT_EQ(t.texels[3], 255) << "the data chain's level 0 is the image";
  EXPECT_EQ(t.texels[size_t(t.textures[1].offset) * 4 + 3], 0) << "the normal chain's level 0: unit normals";
  const MaterialTables none = make_material_tables(s, false);
  ASSERT_EQ(none.textures.size(), 1u) << "without mips one entry serves both";
  EXPECT_EQ(none.materials[0].maps[PMR_MAP_NORMAL].texture, 0);
}

// A smooth metal sphere with a highlight narrower than a pixel's change of normal (alpha = 0.17^2 = 0.029
// rad against 1 / 13.5 rad per pixel): one sample per pixel hits or misses its peak, so the energy
// follows the highlight's phase on the pixel grid; the geometric term widens it to about a pixel. 8 x 8
// times finer the highlight spans 3 pixels. Measured (S = 1 and 4, three views): energy 0.98-1.09 and
// core 0.78-0.89 of the reference's; without the geometric term energy 0.56-1.55 and core 0.54-1.60.
TEST(SpecularAntialiasing, GeometricTermKeepsASmallHighlightsEnergy) {
  expect_highlights_match({0.17f, false, glm::vec2(1.0f)}, 0.2, 0.3);
}

// The sphere bumpy and rougher: a normal map of slopes up to 0.3 with bumps 16 texels apart, about two
// bumps per pixel (level 3 or so), which the mips average away. Toksvig's widening keeps the highlight
// about as spread out (its peak as low) as the reference's, which resolves every bump. The energy is
// the same either way (a sphere sums its highlight over every normal direction); the core is what
// tells. Measured: core 1.31-1.33 of the reference's with Toksvig, 1.86-1.98 without.
TEST(SpecularAntialiasing, ToksvigKeepsABumpyHighlightAsSpreadAsTheReference) {
  expect_highlights_match({0.48f, true, glm::vec2(9.0f, 4.5f)}, 0.15, 0.4);
}

}  // namespace pmr
