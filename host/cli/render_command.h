// `pmr render`: load, set up, render one frame, write the data products.
#pragma once
#include <string>
#include <vector>

namespace pmr {

// Runs `pmr render` with the arguments after "render". Returns the process exit status; throws
// pmr::Error on failure (the caller prints it).
int run_render(const std::vector<std::string>& args);
// Locates the bundled default scene (PMR_DATA_DIR, next to the executable, or the source tree).
std::string default_scene_path();

}  // namespace pmr
