// A frame's files on disk: their names (from the options) and whether they make a complete frame.
// Shared by the sequence job (--resume) and `pmr verify`.
#pragma once
#include <string>
#include <vector>

#include "pmr/printable.h"  // printable_text, for names read from sidecars
#include "pmr/quilt.h"

namespace pmr {

// Which files a sequence writes per frame, and where: DIR/STEM.json (the sidecar), STEM.exr (encoded),
// STEM.views.exr, the quilt STEM_qsCxRaA.exr, and with `preview` the PNGs beside them (docs/OUTPUTS.md).
struct FrameProducts {
  std::string out_dir = "out";
  std::string name = "frame_%04d";  // --name pattern (frame_names.h)
  bool encoded = true, views = false, quilt = false;
  bool depth = false;               // a Z channel in the views and quilt EXRs
  bool preview = false;             // PNG previews of the encoded image, the center view and the quilt
};

// Every file of a frame; empty = not requested.
struct FramePaths {
  std::string sidecar, encoded, views, quilt, encoded_png, center_png, quilt_png;
  std::vector<std::string> images() const;  // the non-empty ones besides the sidecar
};

FramePaths frame_paths(const FrameProducts& o, long frame, const QuiltLayout& quilt, double aspect);

// "" when the frame is whole (the sidecar parses as a JSON object, every EXR is complete, every PNG
// decodes), else what is wrong with it, e.g. "frame_0003.exr is missing", "frame_0003.exr is truncated
// or unreadable".
std::string frame_problem(const std::string& sidecar, const std::vector<std::string>& images);

std::string read_text_file(const std::string& path);

}  // namespace pmr
