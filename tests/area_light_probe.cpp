#include "area_light_probe.h"

#include "shading/ltc.h"
#include "test_util.h"

namespace pmr::test {

std::vector<AreaProbeResult> probe_area_lights(const std::vector<PmrLight>& lights,
                                               const std::vector<AreaProbePoint>& at) {
  const ClRuntime& rt = runtime();
  static const ClProgram program = rt.build_program({"area_light_probe.cl"}, "-cl-std=CL1.2", &test_kernel_sources());
  std::vector<float> in;
  for (const AreaProbePoint& q : at) {
    in.push_back(float(q.light));
    for (const glm::dvec3& v : {q.p, q.n, q.v}) in.insert(in.end(), {float(v.x), float(v.y), float(v.z)});
    in.insert(in.end(), {float(q.r), float(q.coat_r)});
  }
  std::vector<float> out(at.size() * 8);
  ClKernel k(program, "area_light_probe");
  ClBuffer table = rt.upload(ltc_table(), "ltc"), l = rt.upload(lights, "lights");
  ClBuffer a = rt.upload(in, "probe in"), b = rt.buffer(out.size() * 4, "probe out");
  k.args(table, l, a, b, cl_uint(at.size()));
  clReleaseEvent(rt.launch(k, (at.size() + 7) / 8, 64));  // SW = 8 points an item
  rt.read(b, out.data(), out.size() * 4);
  std::vector<AreaProbeResult> r(at.size());
  for (size_t i = 0; i < at.size(); ++i) {
    const float* o = &out[8 * i];
    r[i] = {glm::dvec3(o[0], o[1], o[2]), o[3], o[4], o[5], o[6], o[7]};
  }
  return r;
}

}  // namespace pmr::test
