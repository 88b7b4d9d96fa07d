// A frame's files on disk: their names (from the options) and whether they make a complete frame.
// Shared by the sequence job (--resume) and `pmr verify`.
#pragma once
#include <string>
#include <vector>

#include "cli/options.h"
#include "pmr/printable.h"  // printable_text, for names read from sidecars
#include "pmr/quilt.h"

namespace pmr {

// Every file of a frame; empty = not requested.
struct FramePaths {
  std::string sidecar, encoded, views, quilt, encoded_png, center_png, quilt_png;
  std::vector<std::string> images() const;  // the non-empty ones besides the sidecar
};

FramePaths frame_paths(const RenderOptions& o, long frame, const QuiltLayout& quilt, double aspect);

// "" when the frame is whole (the sidecar parses as a JSON object, every EXR is complete, every PNG
// decodes), else what is wrong with it, e.g. "frame_0003.exr is missing", "frame_0003.exr is truncated
// or unreadable".
std::string frame_problem(const std::string& sidecar, const std::vector<std::string>& images);

std::string read_text_file(const std::string& path);

// Throws a UsageError naming --name when a file of these frames would have a name longer than the file
// system takes (max_output_file_name: its temporary name must fit too), so that a long --name fails
// before anything is rendered or created.
void check_frame_file_names(const RenderOptions& o, const std::vector<long>& frames, const QuiltLayout& quilt,
                            double aspect);

}  // namespace pmr
