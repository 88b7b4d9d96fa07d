// One output folder, one configuration (docs/SEQUENCES.md, "One folder, one configuration").
//
// Before the long work, `pmr render` makes sure that its run will not leave the folder holding frames of
// two configurations:
//   1. Running processes. Each run holds a shared flock on a per-configuration lock file in the folder,
//      ".pmr-lock-<P>-<C>" (P: a hash of the --name pattern, C: a hash of the configuration; the file
//      holds the run's expected sidecar). Shards of one job have the same configuration, so they share
//      one lock and run together. A lock file of the same pattern that some live process holds and
//      whose sidecar shows another configuration (sidecar_config_difference) refuses the run; lock files
//      nobody holds are stale (a process killed with SIGKILL) and removed.
//   2. Finished frames. Every sidecar in the folder whose name the --name pattern produces (any frame
//      number) is compared with this run's expected sidecar, except the frames of this job: those are
//      rewritten (or, with --resume, checked frame by frame by the sequence job). "This job" is the
//      whole --frames list, every shard's share included: the shards of an array job share one
//      configuration and together rewrite every frame of the list. A frame of another configuration
//      outside the list refuses the run; with --overwrite the run goes on and warns once with their
//      count.
// Lock files start with a dot and do not end in ".json": --name patterns cannot produce them (stems
// are never hidden), so --resume, `pmr verify` and the sidecar scan never see them.
#pragma once
#include <atomic>
#include <string>
#include <vector>

namespace pmr {

class FolderGuard {
 public:
  // dir: the output folder (it exists); pattern: --name; job_frames: every frame of the job (before
  // sharding, any order); expected: this run's sidecar text for some frame (only its configuration
  // part matters, which is the same for every frame); overwrite: warn instead of refusing finished
  // frames of another configuration; quiet: print warnings only. Throws pmr::Error with one line when
  // the run must not go on (nothing is left behind then).
  FolderGuard(const std::string& dir, const std::string& pattern, const std::vector<long>& job_frames,
              const std::string& expected, bool overwrite, bool quiet = false);
  // Releases the lock; removes the lock file unless another process still holds it.
  ~FolderGuard();
  FolderGuard(const FolderGuard&) = delete;
  FolderGuard& operator=(const FolderGuard&) = delete;

  const std::string& lock_path() const { return lock_path_; }

 private:
  void release();
  static void release_at_exit(FolderGuard* guard);

  std::string lock_path_;
  int fd_ = -1;
  std::atomic<FolderGuard*>* live_ = nullptr;  // the exit handler's pointer to this guard
};

// The lock file's name (no folder) for a --name pattern and an expected sidecar text.
std::string folder_lock_name(const std::string& pattern, const std::string& expected);

// The sidecar text without its top-level "views" member (the per-view matrices: derived from the rig,
// camera and framing, which sidecar_config_difference compares, and not compared themselves), when it
// is laid out as sidecar_json writes it; else unchanged. The folder scan compares these.
std::string without_view_matrices(const std::string& sidecar);

// The frame number when `file_name` is "<stem>.json" for a stem the pattern makes, else -1.
long sidecar_frame(const std::string& pattern, const std::string& file_name);

}  // namespace pmr
