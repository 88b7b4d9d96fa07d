// The program's version, as `pmr --version` prints it and every sidecar and EXR header records it:
// the project version from CMakeLists.txt, then "+g<commit>" from git describe at build time (with
// "-dirty" when the tree had uncommitted changes).
#pragma once

namespace pmr {

const char* program_version();

}  // namespace pmr
