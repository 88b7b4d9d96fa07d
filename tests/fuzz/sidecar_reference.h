// A sidecar as `pmr render` writes it, for the sidecar fuzz target (the reference frame beside the
// fuzzed one) and for its seeds.
#pragma once
#include <string>

#include "output/sidecar.h"
#include "pmr/output.h"
#include "pmr/rig.h"

namespace pmr::fuzz {

// The sidecar of frame `frame` of a render of a unit cube's bounds (paper-8k, 24 fps) with 3 views of
// 64x32 (few view matrices: a small file the fuzzer mutates quickly).
inline std::string reference_sidecar(int frame) {
  const Display display;
  RigConfig config;
  config.views = 3;
  config.view_w = 64;
  config.view_h = 32;
  const Rig rig = make_rig(config, display, glm::dvec3(-1.0), glm::dvec3(1.0));
  SidecarInfo info;
  info.scene = "scene.glb";
  info.frame = frame;
  info.render.shading = Shading::Lambert;
  info.time = frame / info.sequence.fps;
  info.has_bounds = true;
  info.bounds_lo = glm::dvec3(-1.0);
  info.bounds_hi = glm::dvec3(1.0);
  info.compression = ExrCompression::Zip;
  char stem[32];
  std::snprintf(stem, sizeof stem, "frame_%04d", frame);
  info.outputs = {{"encoded", std::string(stem) + ".exr"}};
  info.scene_checksum = "0123456789abcdef";
  return sidecar_json(rig, display, info);
}

}  // namespace pmr::fuzz
