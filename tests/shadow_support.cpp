#include "shadow_support.h"

#include <cmath>
#include <cstring>

#include "pbr_support.h"
#include "pipeline/pipeline.h"
#include "pipeline/shadow_sizes.h"
#include "shading/lights.h"
#include "test_util.h"

namespace pmr::test {

// A quad of two triangles with corners a, b, c, d (counter-clockwise seen from the front).
void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  add_triangle(s, a, b, c);
  add_triangle(s, a, c, d);
}

// The box [lo, hi], its faces outward.
void add_box(Scene& s, glm::vec3 lo, glm::vec3 hi) {
  const glm::vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  add_quad(s, p[4], p[5], p[6], p[7]);  // +z
  add_quad(s, p[1], p[0], p[3], p[2]);  // -z
  add_quad(s, p[5], p[1], p[2], p[6]);  // +x
  add_quad(s, p[0], p[4], p[7], p[3]);  // -x
  add_quad(s, p[3], p[7], p[6], p[2]);  // +y
  add_quad(s, p[0], p[1], p[5], p[4]);  // -y
}

// A sphere of radius r about c, `rings` x 2 `rings` facets, outward.
void add_sphere(Scene& s, glm::vec3 c, float r, int rings) {
  auto at = [&](int i, int j) {
    const double th = M_PI * i / rings, ph = M_PI * j / rings;
    return c + r * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < 2 * rings; ++j) {
      if (i > 0) add_triangle(s, at(i, j), at(i + 1, j), at(i, j + 1));
      if (i + 1 < rings) add_triangle(s, at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
    }
}

ShadowMaps render_maps(const Scene& s, const std::shared_ptr<const Environment>& env, double uniform_intensity) {
  PipelineConfig pc;
  pc.shading = Shading::Pbr;
  pc.shadows = true;
  pc.environment = env, pc.environment_intensity = env ? env->tables().header.intensity : uniform_intensity;
  Pipeline p(runtime(), pc);
  p.set_scene(s);
  const Rig rig = small_rig(2, 32, 16);
  p.configure(rig, nullptr);
  p.render(rig);
  ShadowMaps out;
  p.read_shadow_maps(out.maps, out.depth);
  return out;
}

// cl/lights.h's shadow_visibility_lanes of the scene's one light at each receiver (tests/probes/shadow_probe.cl).
std::vector<float> probe(const ShadowMaps& m, const SceneLight& light, const std::vector<Receiver>& at) {
  const ClRuntime& rt = runtime();
  const ClProgram program = rt.build_program({"shadow_probe.cl"}, "-cl-std=CL1.2", &test_kernel_sources());
  PmrLight d = device_light(light);
  d.shadow = 0, d.shadow_maps = int(m.maps.size()), d.shadow_samples = shadow_samples(light);
  std::vector<float> in;
  for (const Receiver& r : at)
    for (const glm::dvec3& v : {r.p, r.n}) in.insert(in.end(), {float(v.x), float(v.y), float(v.z)});
  std::vector<uint32_t> bits(m.depth.size());
  std::memcpy(bits.data(), m.depth.data(), bits.size() * 4);
  std::vector<float> out(at.size());
  ClKernel k(program, "shadow_probe");
  ClBuffer maps = rt.upload(m.maps, "maps"), depth = rt.upload(bits, "depth"),
           l = rt.upload(std::vector<PmrLight>{d}, "light");
  ClBuffer a = rt.upload(in, "probe in"), b = rt.buffer(out.size() * 4, "probe out");
  k.args(maps, depth, l, a, b, cl_uint(at.size()));
  clReleaseEvent(rt.launch(k, at.size(), 64));
  rt.read(b, out.data(), out.size() * 4);
  return out;
}

std::vector<glm::vec2> probe_environment(const ShadowMaps& m, int directions, const std::vector<Receiver>& at,
                                         const std::vector<glm::dvec3>& reflected, float sharpness) {
  const ClRuntime& rt = runtime();
  const ClProgram program = rt.build_program({"shadow_probe.cl"}, "-cl-std=CL1.2", &test_kernel_sources());
  PmrLight occ{};
  occ.shadow = int(m.maps.size()) - directions, occ.shadow_maps = occ.shadow_samples = directions;
  std::vector<float> in;
  for (size_t i = 0; i < at.size(); ++i)
    for (const glm::dvec3& v : {at[i].p, at[i].n, reflected[i]})
      in.insert(in.end(), {float(v.x), float(v.y), float(v.z)});
  std::vector<uint32_t> bits(m.depth.size());
  std::memcpy(bits.data(), m.depth.data(), bits.size() * 4);
  std::vector<glm::vec2> out(at.size());
  ClKernel k(program, "environment_occlusion_probe");
  ClBuffer maps = rt.upload(m.maps, "maps"), depth = rt.upload(bits, "depth"),
           l = rt.upload(std::vector<PmrLight>{occ}, "occlusion");
  ClBuffer a = rt.upload(in, "probe in"), b = rt.buffer(out.size() * 8, "probe out");
  k.args(maps, depth, l, a, b, cl_uint(at.size()), sharpness);
  clReleaseEvent(rt.launch(k, at.size(), 64));
  rt.read(b, out.data(), out.size() * 8);
  return out;
}

}  // namespace pmr::test
