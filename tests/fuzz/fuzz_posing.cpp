// libFuzzer target: posing (docs/SECURITY.md, "Posing"). The input is a glTF / GLB scene; it is loaded,
// its animations all selected, framed (FrameRenderer: both posing budgets, then every pose of the
// framing) and posed at a few frames inside and outside its keys. The posing budgets are far below
// the defaults, so that an input they accept stays fast; an input that makes one pose or the framing
// run long despite its counted work is a finding (libFuzzer's -timeout), as is anything but a
// pmr::Error escaping.
#include <cstdint>

#include "fuzz/fuzz_util.h"
#include "pmr/error.h"
#include "pmr/input_files.h"
#include "pmr/rig.h"
#include "pmr/scene.h"
#include "sequence/frame_renderer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pmr::fuzz::folder() + "/scene.gltf";
  pmr::fuzz::write_file(path, data, size);
  pmr::InputLimits limits = pmr::fuzz::small_limits();
  // posing is the point here: smaller images and geometry, so more poses per second
  limits.texture_pixels = uint64_t(1) << 16;
  limits.vertex_data = uint64_t(16) << 20;
  limits.animation_data = uint64_t(4) << 20;
  limits.pose_work = uint64_t(1) << 20;
  limits.framing_work = uint64_t(1) << 24;
  try {
    const pmr::Scene scene = pmr::load_scene(path, limits);
    pmr::SequenceChoice choice;
    choice.animation = "all";
    const pmr::SequenceSpec spec = pmr::resolve_sequence(scene, choice, limits);
    pmr::RigConfig rig;
    rig.views = 2;
    rig.view_w = 16;
    rig.view_h = 8;
    const pmr::FrameRenderer renderer(scene, spec, rig, pmr::Display(), nullptr);
    pmr::Scene posed;
    for (long f : {0L, 1L, 7L, 100000L}) {
      pmr::PoseRequest r;
      r.time = double(f) / spec.fps;
      r.animation = spec.animation;
      pmr::pose_scene(scene, r, posed);
    }
  } catch (const pmr::Error&) {
    // a clear one-line refusal
  }
  return 0;
}
