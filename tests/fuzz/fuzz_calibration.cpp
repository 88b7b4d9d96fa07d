// libFuzzer target: a Looking Glass calibration file (--display-config visual.json) as `pmr render`
// takes it: read and checked, mapped onto the display and the rig the panel's model recommends, then
// the encoder's parameters and tables computed from it (what a render does before the first frame).
// Anything but a pmr::Error escaping is a finding.
#include <cstdint>

#include "cli/options.h"
#include "fuzz/fuzz_util.h"
#include "pmr/error.h"
#include "pmr/rig.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pmr::fuzz::folder() + "/visual.json";
  pmr::fuzz::write_file(path, data, size);
  try {
    pmr::RenderOptions o = pmr::parse_render_options({"--display-config", path});
    pmr::finalize_render_options(o);
    const PmrEncodeParams p =
        pmr::make_encode_params(o.job.display, o.job.rig.views, o.job.rig.view_w, o.job.rig.view_h);
    std::vector<PmrEncodeColumn> columns;
    std::vector<PmrEncodeRow> rows;
    pmr::make_encode_tables(o.job.display, p, columns, rows);
    const glm::dvec3 lo(-1.0), hi(1.0);
    pmr::make_rig(o.job.rig, o.job.display, lo, hi);
  } catch (const pmr::Error&) {
    // a clear one-line refusal
  }
  return 0;
}
