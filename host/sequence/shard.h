// Splitting a sequence over a scheduler's array tasks (`--shard K/N`, `--shard auto`).
//
// The split is interleaved: task K renders the frames at positions K, K + N, K + 2N, ... of the
// requested list. Expensive frames come in runs (a character entering, a busy part of a turntable);
// contiguous blocks would hand a whole run to one task, interleaving spreads every run over all
// tasks, so the tasks finish together. Which task renders a frame never changes the frame's bytes.
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace pmr {

struct Shard {
  long index = 0, count = 1;  // this task's share: 0 <= index < count
  std::string source;         // where it came from, for messages ("--shard 2/4", "Slurm array task 7")
};

// The process environment: a variable's value by name, or null (std::getenv in pmr, a map in tests).
using ProcessEnvironment = std::function<const char*(const char*)>;

// "K/N", or "auto": the array index and size of the scheduler whose variables are set (Slurm,
// Kubernetes Indexed Jobs, AWS Batch, PBS Pro / Torque, SGE / UGE, LSF). shard_count (> 0 when given
// by --shard-count) supplies the count where the environment has none (Kubernetes, PBS) and must
// agree with it elsewhere; shard_first (--shard-first) is the first array index where the environment
// does not say it (PBS: default 0; LSF: default 1). Throws pmr::Error with one line when nothing fits.
Shard parse_shard(const std::string& text, long shard_count, long shard_first, const ProcessEnvironment& env);

// The frames of `frames` (in their order) that belong to the shard.
std::vector<long> shard_frames(const std::vector<long>& frames, const Shard& shard);

}  // namespace pmr
