// libFuzzer target: a lock file planted in an output folder (docs/SECURITY.md, "Output folders"). The
// input is the text of a lock of the run's --name pattern and another configuration, held by another
// open file (as another process would hold it); the run's FolderGuard then reads it (bounded) and
// compares its configuration with its own. Refusing the run is a pmr::Error; anything else escaping
// is a finding.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>

#include "fuzz/fuzz_util.h"
#include "fuzz/sidecar_reference.h"
#include "pmr/error.h"
#include "sequence/folder_guard.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string expected = pmr::fuzz::reference_sidecar(0);
  const std::string dir = pmr::fuzz::folder() + "/out";
  std::filesystem::create_directories(dir);
  const std::string own = pmr::folder_lock_name("frame_####", expected);
  // the same pattern's prefix, another configuration's hash
  const std::string planted = dir + "/" + own.substr(0, own.size() - 16) + "0123456789abcdef";
  pmr::fuzz::write_file(planted, data, size);
  const int held = ::open(planted.c_str(), O_RDONLY | O_CLOEXEC);
  if (held < 0 || ::flock(held, LOCK_SH) != 0) std::abort();
  try {
    const pmr::FolderGuard guard(dir, "frame_####", {0, 1}, expected, false, true);
  } catch (const pmr::Error&) {
    // another configuration renders here: one clear line
  }
  ::close(held);
  ::unlink(planted.c_str());
  return 0;
}
