#include "pipeline/scene_buffers.h"

#include <algorithm>
#include <cmath>

#include "pipeline/material_tables.h"
#include "pipeline/pipeline.h"
#include "pipeline/texture_mips.h"
#include "pmr/error.h"
#include "shading/environment.h"
#include "shading/lights.h"
#include "shading/ltc.h"
#include "shading/sheen.h"

namespace pmr {

namespace {

std::vector<float> srgb_lut() {
  std::vector<float> lut(256);
  for (int c = 0; c < 256; ++c) lut[c] = float(srgb_to_linear(c / 255.0));
  return lut;
}

}  // namespace

SceneBuffers::SceneBuffers(const ClRuntime& rt, const PipelineConfig& config)
    : rt_(rt), mips_(config.texture_filter == TextureFilter::Trilinear), pbr_(config.shading == Shading::Pbr) {
  lut_ = rt.upload(srgb_lut(), "sRGB table");
  // the split-sum table (pbr only: computing it costs about 0.5 s of CPU once per process)
  static_assert(kEnvSplitSumSize == PMR_SPLIT_SUM_N, "the kernels' split-sum table size");
  const std::vector<float> none(2, 0.0f);
  split_sum_ = rt.upload(config.shading == Shading::Pbr ? split_sum_table() : none, "split-sum table");
  static_assert(kSheenAlbedoSize == PMR_SHEEN_ALBEDO_N, "the kernels' sheen albedo table size");
  sheen_albedo_ = rt.upload(config.shading == Shading::Pbr ? sheen_albedo_table() : none, "sheen albedo table");
  static_assert(kLtcSize == PMR_LTC_N && kLtcNodeFloats == PMR_LTC_NODE_FLOATS, "the kernels' LTC table size");
  ltc_ = rt.upload(config.shading == Shading::Pbr ? ltc_table() : none, "area lights' LTC table");
  upload_environment(config);
}

// The environment image's tables, uploaded once per pipeline (the Environment is prefiltered once per
// process and shared); without one, an empty header (level_count 0) selects the uniform default.
void SceneBuffers::upload_environment(const PipelineConfig& config) {
  const Environment* e = config.environment.get();
  if (e && config.shading != Shading::Pbr) throw Error("an environment image needs --shading pbr");
  if (e && e->tables().header.intensity != float(config.environment_intensity))
    throw InternalError("the environment's intensity differs from the configuration's");
  const std::vector<PmrEnvironment> header(1, e ? e->tables().header : PmrEnvironment{});
  const std::vector<float> no_data(4, 0.0f);
  const std::vector<float>& data = e ? e->tables().data : no_data;
  if (bytes_of(data) > rt_.max_alloc_bytes())
    throw Error("the environment's tables need " + std::to_string(bytes_of(data) >> 20) +
                " MiB, more than the device "
                "can allocate at once (" +
                std::to_string(rt_.max_alloc_bytes() >> 20) + " MiB): use a smaller image");
  env_ = rt_.upload(header, "environment header");
  env_data_ = rt_.upload(data, "environment tables");
}

namespace {

// `a`, then `b`.
template <class T>
std::vector<T> joined(const std::vector<T>& a, const std::vector<T>& b) {
  std::vector<T> out;
  out.reserve(a.size() + b.size());
  out.insert(out.end(), a.begin(), a.end());
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

// TEXCOORD set k of vertex v at k * vertices + v, for `added` more vertices (which sample no map) after
// the scene's.
std::vector<glm::vec2> texcoords_with(const std::vector<glm::vec2>& table, size_t vertices, size_t added) {
  if (added == 0 || vertices == 0 || table.size() < vertices) return table;
  std::vector<glm::vec2> out;
  for (size_t k = 0; k < table.size() / vertices; ++k) {
    out.insert(out.end(), table.begin() + ptrdiff_t(k * vertices), table.begin() + ptrdiff_t((k + 1) * vertices));
    out.resize(out.size() + added, glm::vec2(0.0f));
  }
  return out;
}

}  // namespace

void SceneBuffers::set_scene(const Scene& scene, const Scene* catcher) {
  const size_t total = scene.triangles.size() + (catcher ? catcher->triangles.size() : 0);
  if (total >= PMR_MAX_TRIANGLES)
    throw Error("the scene has " + std::to_string(total) + " triangles; at most " +
                std::to_string(PMR_MAX_TRIANGLES - 1) + " are supported");
  catcher_positions_.clear(), catcher_attributes_.clear(), catcher_triangles_.clear();
  MaterialTables tables = make_material_tables(scene, mips_);
  if (catcher) {
    catcher_positions_ = catcher->positions, catcher_attributes_ = catcher->attributes;
    for (PmrTriangle t : catcher->triangles) {
      for (uint32_t& v : t.v) v += uint32_t(scene.positions.size());
      t.material += uint32_t(tables.materials.size());
      catcher_triangles_.push_back(t);
    }
    tables.materials.insert(tables.materials.end(), catcher->materials.begin(), catcher->materials.end());
    tables.texcoords = texcoords_with(tables.texcoords, scene.positions.size(), catcher->positions.size());
  }
  num_vertices_ = uint32_t(scene.positions.size() + catcher_positions_.size());
  num_triangles_ = uint32_t(total);
  caster_triangles_ = uint32_t(scene.triangles.size());
  has_tangents_ = scene.tangents.size() == scene.positions.size() && !scene.positions.empty();
  transmissive_ = pbr_ && scene_transmissive(scene);
  translucent_casters_ = scene_transmissive(scene);
  blended_ = scene_blended(scene, pbr_) || !catcher_triangles_.empty();
  const std::vector<glm::vec4> no_tangents(1, glm::vec4(0.0f));
  scene_lights_ = scene.lights;
  set_bounds(scene.positions);
  positions_ = rt_.upload(joined(scene.positions, catcher_positions_), "vertex positions");
  attrs_ = rt_.upload(joined(scene.attributes, catcher_attributes_), "vertex attributes");
  tris_ = rt_.upload(joined(scene.triangles, catcher_triangles_), "triangles");
  materials_ = rt_.upload(tables.materials, "materials");
  textures_ = rt_.upload(tables.textures, "texture table", 16);
  texels_ = rt_.upload(tables.texels, "texels", 16);
  texcoords_ = rt_.upload(tables.texcoords, "texture coordinates");
  const std::vector<glm::vec4> catcher_tangents(catcher_positions_.size(), glm::vec4(0.0f));
  tangents_ = rt_.upload(has_tangents_ ? joined(scene.tangents, catcher_tangents) : no_tangents, "tangents");
}

void SceneBuffers::update_geometry(const Scene& posed) {
  if (posed.positions.size() + catcher_positions_.size() != num_vertices_ ||
      posed.triangles.size() != caster_triangles_ || posed.attributes.size() != posed.positions.size())
    throw InternalError("update_geometry: the posed scene does not match the scene given to set_scene");
  if (posed.triangles.empty()) return;
  set_bounds(posed.positions);
  if (catcher_triangles_.empty()) {
    rt_.write(positions_, posed.positions);
    rt_.write(attrs_, posed.attributes);
    rt_.write(tris_, posed.triangles);
  } else {
    rt_.write(positions_, joined(posed.positions, catcher_positions_));
    rt_.write(attrs_, joined(posed.attributes, catcher_attributes_));
    rt_.write(tris_, joined(posed.triangles, catcher_triangles_));
  }
  if (has_tangents_ && posed.tangents.size() == posed.positions.size()) {
    if (catcher_positions_.empty()) rt_.write(tangents_, posed.tangents);
    else
      rt_.write(tangents_, joined(posed.tangents, std::vector<glm::vec4>(catcher_positions_.size(), glm::vec4(0.0f))));
  }
}

void SceneBuffers::set_bounds(const std::vector<glm::vec3>& positions) {
  ++geometry_generation_;
  glm::vec3 lo(0.0f), hi(0.0f);
  if (!positions.empty()) lo = hi = positions[0];
  for (const glm::vec3& p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  bounds_lo_ = glm::dvec3(lo), bounds_hi_ = glm::dvec3(hi);
}

void SceneBuffers::upload_frame(const FrameDescription& frame, const ShadowPlacement& shadows) {
  std::vector<PmrLight> table;
  auto with_maps = [](PmrLight d, const ShadowSlot& slot) {
    if (slot.count > 0) d.shadow = slot.first, d.shadow_maps = slot.count, d.shadow_samples = slot.samples;
    return d;
  };
  for (size_t i = 0; i < frame.lights.size(); ++i)
    table.push_back(
        with_maps(device_light(frame.lights[i]), i < shadows.slots.size() ? shadows.slots[i] : ShadowSlot{}));
  // the environment's occlusion: an entry after the lights (PmrParams.env_occlusion), its maps alone
  if (shadows.occlusion.count > 0) {
    PmrLight occlusion{};
    occlusion.shadow = -1;
    table.push_back(with_maps(occlusion, shadows.occlusion));
  }
  table.resize(std::max<size_t>(table.size(), 1));  // no empty buffers
  rt_.rewrite(lights_, table, "lights");
  const Rig& rig = frame.rig;
  std::vector<glm::vec4> eyes(size_t(rig.views));
  for (int i = 0; i < rig.views; ++i) eyes[size_t(i)] = glm::vec4(glm::vec3(glm::inverse(rig.view_matrix(i))[3]), 1.0f);
  rt_.rewrite(eyes_, eyes, "camera positions");
}

cl_uint SceneBuffers::bind_shading(ClKernel& k, const ClBuffer& params, const ShadowBinding& shadows,
                                   const SourceBinding& source) const {
  const ClBuffer* inputs[] = {&params,       &tris_,      &attrs_,     &materials_, &textures_, &texels_,
                              &lut_,         &positions_, &eyes_,      &split_sum_, &ltc_,      &sheen_albedo_,
                              &texcoords_,   &tangents_,  &env_,       &env_data_,  &lights_,   shadows.maps,
                              shadows.depth, source.data, source.info, source.tiles};
  cl_uint i = 0;
  for (const ClBuffer* b : inputs) k.arg(i++, *b);
  return i;
}

size_t SceneBuffers::device_bytes() const {
  size_t total = 0;
  for (const ClBuffer* b : {&positions_, &attrs_, &tris_, &materials_, &textures_, &texels_, &texcoords_, &tangents_,
                            &lut_, &split_sum_, &ltc_, &sheen_albedo_, &env_, &env_data_, &lights_, &eyes_})
    total += b->size();
  return total;
}

}  // namespace pmr
