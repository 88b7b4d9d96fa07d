// --resume: which frames of a job are complete and kept, and which are rendered (again).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "sequence/frame_files.h"

namespace pmr {

struct ResumePlan {
  std::vector<long> todo;          // the frames to render, in job order
  long kept = 0;                   // complete frames of this scene and configuration
  std::vector<std::string> notes;  // one line each, for stderr: frames of another scene, other versions
};

// Without `resume` every frame is rendered. With it, a frame is kept when all its files are present
// and whole (frame_problem) and its sidecar shows this scene (the checksums of the scene file and of
// every file it read) and this configuration (`expected(frame, paths)`: the sidecar this run would
// write) and this frame (its sidecar's frame number: a --name without a frame field names every
// frame alike). A frame from another scene, or whose sidecar records no checksum, is rendered again, whatever
// the scene changed (framing bounds too). A different configuration throws pmr::Error unless
// `overwrite`, which renders such frames again. A program version change alone renders nothing again
// (pixels are meant to be stable across versions): it is only noted.
ResumePlan plan_resume(const std::vector<long>& frames, bool resume, bool overwrite,
                       const std::function<FramePaths(long)>& paths,
                       const std::function<std::string(long, const FramePaths&)>& expected);

}  // namespace pmr
