// A frame's files on disk: their names (from the options) and whether they make a complete frame.
// Shared by the sequence job (--resume) and `pmr verify`.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "output/sidecar.h"
#include "pmr/printable.h"  // printable_text, for names read from sidecars
#include "pmr/quilt.h"

namespace pmr {

// Which files a sequence writes per frame, and where: DIR/STEM.json (the sidecar), STEM.exr (encoded),
// STEM.views.exr, the quilt STEM_qsCxRaA.exr (a sequence's: quilt_file_stem), and with `preview` the PNGs beside them (docs/OUTPUTS.md).
struct FrameProducts {
  std::string out_dir = "out";
  std::string name = "frame_%04d";  // --name pattern (frame_names.h)
  bool sequence = false;            // a sequence's names: the quilt's frame number last (quilt_file_stem)
  bool encoded = true, views = false, quilt = false;
  bool depth = false;  // a Z channel in the views and quilt EXRs
  // Z where nothing was drawn (--depth-empty): +infinity by default, as DESIGN section 6 says; Cycles
  // writes 1e10, which keeps compositing arithmetic (0 x Z) finite
  float depth_empty = std::numeric_limits<float>::infinity();
  bool preview = false;  // PNG previews of the encoded image, the center view and the quilt
};

// Every file of a frame; empty = not requested.
struct FramePaths {
  std::string sidecar, encoded, views, quilt, encoded_png, center_png, quilt_png;
  std::vector<std::string> images() const;  // the non-empty ones besides the sidecar
};

FramePaths frame_paths(const FrameProducts& o, long frame, const QuiltLayout& quilt, double aspect);

// How the quilts of the folder's frames (sidecars under o.name's pattern) are named: as a sequence's
// (frame_qs8x6a0.75_0012.exr) or as stills' (frame_0012_qs8x6a0.75.exr), so that a frame re-rendered
// alone into a sequence's folder keeps the sequence's names. None: no such frame with a quilt of this
// layout, or the folder is missing; Mixed: both kinds. At most kMaxFolderSidecars sidecars are read.
enum class FolderNames { None, Still, Sequence, Mixed };
constexpr size_t kMaxFolderSidecars = 100000;
FolderNames folder_quilt_names(const FrameProducts& o, const QuiltLayout& quilt, double aspect);

// "" when the frame is whole, else what is wrong with it, e.g. "frame_0003.exr is missing". Whole: the
// sidecar (written last) parses as a JSON object, and every image is the file the sidecar records
// (its size and checksum: output_checksums) with an intact EXR chunk table, without decoding a pixel.
// With `deep`, or for an image its sidecar records no checksum of (written by an older pmr), every
// pixel is decoded as well.
std::string frame_problem(const std::string& sidecar, const std::vector<std::string>& images, bool deep = false);

// A sidecar is a few kB; one larger than kMaxSidecarBytes (output/sidecar.h: pmr writes none) is not
// read (read_sidecar_text returns "").
std::string read_sidecar_text(const std::string& path);

// Throws a UsageError naming --name when a file of these frames would have a name longer than the file
// system takes (max_output_file_name: its temporary name must fit too), so that a long --name fails
// before anything is rendered or created.
void check_frame_file_names(const FrameProducts& o, const std::vector<long>& frames, const QuiltLayout& quilt,
                            double aspect);

}  // namespace pmr
