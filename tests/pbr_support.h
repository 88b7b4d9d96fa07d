// Helpers of the --shading pbr tests against the double-precision reference (tests/reference): the
// model's inputs at a voxel, the default light and uniform environment as the reference states them,
// the 1% + 1e-3 bound per channel, the checks of a material feature's voxels, and scenes of flat layers.
#pragma once
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "reference/pbr_reference.h"
#include "test_util.h"

namespace pmr::test {

// The model's inputs at source barycentrics b of triangle `tri` seen from view `view`, computed from the
// scene's material inputs (tests/reference/material_reference.h), for the reference.
ref::SurfacePoint surface_at(const Scene& s, const Rig& rig, uint32_t tri, const glm::dvec3& b, bool back, int view);

// The model's bound on one voxel of a render: 1% relative plus 1e-3 absolute per colour channel.
// Counts the channels outside it (reporting the first five) and the largest error as a fraction of it.
struct BoundCheck {
  size_t bad = 0;
  double worst = 0.0;
  void voxel(const Rendered& out, size_t v, const glm::dvec3& want, const std::string& what = "voxel");
};

// The defaults: one directional light toward the rig's light direction with E = 0.8 pi, a uniform
// environment of radiance 0.2 (I = P = 0.2) and the split-sum table the kernels are given.
std::vector<ref::PunctualLight> default_light(const Rig& rig);
ref::EnvironmentTerms uniform_environment(double radiance);

// The reference colour of every covered voxel of a render (volume index v), under `lights` and `env`
// (by default the default light and environment): the winning MTA found by its key and view, then the
// model at its barycentrics.
struct VoxelReference {
  const Scene& scene;
  const Rig& rig;
  const Rendered& out;
  std::multimap<uint32_t, PmrMta> by_key;
  std::vector<ref::PunctualLight> lights = default_light(rig);
  ref::EnvironmentTerms env = uniform_environment(0.2);

  VoxelReference(const Scene& s, const Rig& r, const Rendered& o);
  // The winner of voxel v (null if none matches its key and view).
  const PmrMta* mta(size_t v) const;
  glm::dvec3 colour(size_t v, const PmrMta& m) const;
};

// The rig of the highlight tests: N views of 160 x 100 over a 60 degree cone, framing [-1, 1]^3.
Rig highlight_rig(int views);
// The brightest covered pixel (green channel) of view `view` of the render, or of the reference when
// `reference` is given, outside a radius of `away` pixels around `avoid` (in the view's pixels).
glm::dvec2 brightest_pixel(const Rendered& out, const VoxelReference* reference, const Rig& rig, int view,
                           glm::dvec2 avoid = glm::dvec2(-1e9), double away = 0.0);

// The reference's light for a scene light, from its definition (colour, intensity, cone angles in
// double precision), not from the kernels' table; and a scene light of the given kind.
ref::PunctualLight reference_light(const SceneLight& l);
SceneLight make_light(SceneLightType type, const glm::dvec3& position, const glm::dvec3& direction, float intensity,
                      float range = 0.0f);

// --shading pbr with 4 x 4 x 4 tiles, `method` (multipass snapped to PMR's vertices, so that the two
// agree bit for bit), `filter` and `env` (null: the default), and one frame rendered with it.
PipelineConfig pbr_config(Method method = Method::Pmr, TextureFilter filter = TextureFilter::Bilinear,
                          const std::shared_ptr<const Environment>& env = nullptr);
Rendered render_pbr(const Scene& s, const Rig& rig, Method method = Method::Pmr,
                    TextureFilter filter = TextureFilter::Bilinear,
                    const std::shared_ptr<const Environment>& env = nullptr);
// An environment image of radiance 1 in every direction (an image: no default light).
std::shared_ptr<const Environment> white_environment();
// The environment terms the kernels must reproduce for an image: the host lookups of the very
// Environment they are given (which must outlive the terms).
ref::EnvironmentTerms image_environment(const Environment& e);
// A 64x32 sky: a gradient, a darker ground and one sun texel about 1000 times brighter (tests/
// environment_maps.h), seen in reflection by the default rig's camera on +Z.
std::shared_ptr<Environment> sky_environment(double rotation_deg, double intensity);
// A white rough dielectric (roughness 1, double-sided) square of side 2 at z = 0, facing the camera.
Scene white_rough_square();

// Appends a 16 x 16 texture whose texel (x, y) is f(x, y) (RGBA in [0, 1], rounded to 8 bits); its index.
int add_texture16(Scene& s, const std::function<glm::dvec4(int, int)>& f);

// A material feature against the reference: every covered voxel of `with.out` within the bound of
// `with`, and per material the voxels and those where `without` (the reference of the scene without
// the feature) is outside twice the bound, i.e. where a kernel ignoring the feature would fail.
struct FeatureCheck {
  BoundCheck check;
  std::map<uint32_t, size_t> voxels, changed;
};
FeatureCheck check_feature(const VoxelReference& with, const VoxelReference& without);
// The same for `s` lit by the environment image `env` alone (its lights and the default light off),
// rendered at 5 views of 80 x 40; `without` is s without the feature.
FeatureCheck check_feature_under(const Scene& s, const Scene& without, const std::shared_ptr<const Environment>& env);

// Four quads side by side (x from -1.3 to 1.3) with curved normals, TEXCOORD_0 and tangents (w
// alternating), the quad q drawn with material q + 1 of base colour bases[q] and the inputs `inputs(q,
// in)` sets (the sRGB flags set beforehand), lit by one point light. `s` may hold textures already.
void add_feature_quads(Scene& s, const std::array<glm::vec3, 4>& bases,
                       const std::function<void(int, SceneMaterialInputs&)>& inputs);

// A material feature's voxel test: `s` (its lights in `lights`) rendered; every voxel within the bound of
// the reference; materials 1..n each drawn on over 300 voxels; those with the feature (1..n-1) changed by
// it (`without`: the scene without it) on more than 1/divisor of their voxels, material n (without it) on
// none. Returns the largest error as a fraction of the bound.
double expect_feature_matches_reference(const Scene& s, const Scene& without,
                                        const std::vector<ref::PunctualLight>& lights, uint32_t n, size_t divisor);

// Every path draws `s` (pbr configuration `pc`) alike: multipass (snapped) equals PMR's volume bit for
// bit; at a 240 x 135 display the fused raster + encode equals the encoded volume, and subpixel
// sampling's image sum is within 5% of view sampling's. Over 1000 channels are lit; with `other` (the
// scene without some feature), its fused image differs from s's on more than a quarter of them.
void expect_paths_agree(const Scene& s, const Rig& rig, const PipelineConfig& pc, const Scene* other = nullptr);

// Every covered voxel of a render of a real model whose surface point passes `include` against the
// reference; `counted`: how many of those pass `count` too.
struct ModelCheck {
  BoundCheck check;
  size_t compared = 0, counted = 0;
};
using SurfaceTest = std::function<bool(const ref::SurfacePoint&)>;
ModelCheck check_model(const VoxelReference& reference, const SurfaceTest& include, const SurfaceTest& count);

// Scenes of flat layers: a rectangle [x0, x1] x [y0, y1] at depth z facing +Z (the camera) as two
// triangles; a material appended (its index returned); an unlit material of colour c (alpha 1).
void quad(Scene& s, float x0, float y0, float x1, float y1, float z, uint32_t material);
uint32_t add_material(Scene& s, const PmrMaterial& m);
PmrMaterial unlit(glm::vec3 c);

}  // namespace pmr::test
