// libFuzzer target: the glTF / GLB loader with its images (pmr info SCENE, and what render and bench
// load before any OpenCL work). The input is the scene file; its folder also holds tex.png and buf.bin,
// which a .gltf may name by URI (seeds from pmr_fuzz_seeds do). Anything but a pmr::Error escaping the
// loader is a finding: main() would report it as an internal error (or run out of memory).
#include <cstdint>

#include "fuzz/fuzz_util.h"
#include "gltf_builder.h"
#include "pmr/error.h"
#include "pmr/input_files.h"
#include "pmr/scene.h"

namespace {

const std::string& scene_path() {
  static const std::string path = [] {
    const std::string dir = pmr::fuzz::folder();
    std::vector<uint8_t> rgba(4 * 4 * 4);
    for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = uint8_t(i * 37);
    const std::vector<uint8_t> png = pmr::test::make_png(4, 4, 6, 8, rgba);
    pmr::fuzz::write_file(dir + "/tex.png", png.data(), png.size());
    std::vector<uint8_t> bin(256);
    for (size_t i = 0; i < bin.size(); ++i) bin[i] = uint8_t(i);
    pmr::fuzz::write_file(dir + "/buf.bin", bin.data(), bin.size());
    return dir + "/scene.gltf";  // the loader tells GLB from glTF by the magic, not the name
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = scene_path();
  pmr::fuzz::write_file(path, data, size);
  const pmr::InputLimits limits = pmr::fuzz::small_limits();
  try {
    // the material variant by name or by index, as --variant takes it (the input's first byte picks)
    const char* variants[] = {"", "#0", "#1", "Blue", "1"};
    const pmr::Scene scene = pmr::load_scene(path, limits, size ? variants[data[0] % 5] : "");
    glm::dvec3 lo, hi;
    pmr::scene_bounds(scene, lo, hi);
  } catch (const pmr::Error&) {
    // a clear one-line refusal: what pmr does with a bad file
  }
  return 0;
}
