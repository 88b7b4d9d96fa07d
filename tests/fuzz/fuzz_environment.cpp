// libFuzzer target: the environment image reader (--environment FILE.hdr or FILE.exr). The input is
// written as env.exr when it starts with OpenEXR's magic number, else as env.hdr (the reader picks the
// format by the extension). Anything but a pmr::Error escaping the reader is a finding.
#include <cstdint>
#include <cstring>

#include "fuzz/fuzz_util.h"
#include "pmr/error.h"
#include "shading/environment.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const unsigned char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  const bool exr = size >= 4 && std::memcmp(data, kExrMagic, 4) == 0;
  const std::string path = pmr::fuzz::folder() + (exr ? "/env.exr" : "/env.hdr");
  pmr::fuzz::write_file(path, data, size);
  try {
    pmr::load_environment_image(path);
  } catch (const pmr::Error&) {
    // a clear one-line refusal
  }
  return 0;
}
