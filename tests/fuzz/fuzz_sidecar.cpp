// libFuzzer target: the sidecar JSON that `pmr verify` and `pmr render --resume` read back from an
// output folder. The input is frame 0's sidecar, beside a sidecar pmr wrote for frame 1; the folder is
// verified (`pmr verify DIR --frames 0:1`), and the input goes through what --resume and the folder
// scan do with a sidecar (configuration comparison both ways, provenance, view matrices stripped).
// Anything but a pmr::Error escaping is a finding.
#include <cstdint>

#include <nlohmann/json.hpp>

#include "cli/verify_command.h"
#include "fuzz/fuzz_util.h"
#include "fuzz/sidecar_reference.h"
#include "pmr/error.h"
#include "pmr/json_text.h"
#include "output/sidecar.h"
#include "pmr/output.h"
#include "sequence/folder_guard.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& dir = pmr::fuzz::folder();
  static const std::string reference = [&] {
    const std::string text = pmr::fuzz::reference_sidecar(1);
    pmr::fuzz::write_file(dir + "/frame_0001.json", text);
    return text;
  }();
  pmr::fuzz::write_file(dir + "/frame_0000.json", data, size);
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    pmr::run_verify({dir, "--frames", "0:1"});
  } catch (const pmr::Error&) {
    // a clear one-line refusal
  }
  // existing (read from the folder) against expected: what --resume compares
  pmr::sidecar_config_difference(text, reference);
  pmr::sidecar_provenance(text);
  pmr::sidecar_config_difference(pmr::without_view_matrices(text), pmr::without_view_matrices(reference));
  // pmr verify compares the other frames with the folder's reference frame, a sidecar that parsed
  if (pmr::parse_json_text(text).is_object()) {
    pmr::sidecar_config_difference(reference, text);
    pmr::sidecar_config_difference(text, text, /*ignore_scene_derived=*/true);
  }
  return 0;
}
