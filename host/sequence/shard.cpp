#include "sequence/shard.h"

#include <cerrno>
#include <cstdlib>

#include "pmr/error.h"

namespace pmr {

namespace {

bool read_long(const char* text, long& out) {
  if (!text || !*text) return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (*end != '\0' || errno != 0) return false;
  out = v;
  return true;
}

long env_long(const ProcessEnvironment& env, const char* name, bool& present) {
  long v = 0;
  const char* text = env(name);
  present = read_long(text, v);
  if (text && *text && !present)
    throw Error(std::string("--shard auto: ") + name + "='" + text + "' is not a whole number");
  return v;
}

Shard checked(long index, long count, const std::string& source) {
  if (count < 1) throw Error(source + ": the array has no tasks");
  if (index < 0 || index >= count)
    throw Error(source + ": task " + std::to_string(index) + " is outside the array's " + std::to_string(count) +
                " task(s)");
  return Shard{index, count, source};
}

// index = (id - first) / step for an array first, first + step, ...
long position(long id, long first, long step, const std::string& source) {
  if (step < 1) throw Error(source + ": array step " + std::to_string(step) + " is not positive");
  if (id < first || (id - first) % step != 0)
    throw Error(source + ": task id " + std::to_string(id) + " is not on the array's range (first " +
                std::to_string(first) + ", step " + std::to_string(step) + ")");
  return (id - first) / step;
}

}  // namespace

Shard parse_shard(const std::string& text, long shard_count, long shard_first, const ProcessEnvironment& env) {
  if (text != "auto") {
    long k = 0, n = 0;
    const auto slash = text.find('/');
    if (slash == std::string::npos || !read_long(text.substr(0, slash).c_str(), k) ||
        !read_long(text.substr(slash + 1).c_str(), n) || n < 1 || k < 0 || k >= n)
      throw UsageError("invalid --shard '" + text + "': expected K/N with 0 <= K < N, or auto");
    return Shard{k, n, "--shard " + text};
  }
  bool has = false, h2 = false, h3 = false, h4 = false;
  auto with_count = [&](long index, long env_count, bool env_has, const std::string& source) {
    if (env_has && shard_count > 0 && shard_count != env_count)
      throw UsageError(source + ": --shard-count " + std::to_string(shard_count) + " disagrees with the array's " +
                       std::to_string(env_count) + " tasks");
    const long count = env_has ? env_count : shard_count;
    if (count < 1) throw UsageError(source + ": the task count is not in the environment: give --shard-count N");
    return checked(index, count, source);
  };
  // Slurm: SLURM_ARRAY_TASK_ID within MIN..MAX by STEP (COUNT when given)
  const long slurm_id = env_long(env, "SLURM_ARRAY_TASK_ID", has);
  if (has) {
    const std::string src = "Slurm array task " + std::to_string(slurm_id);
    const long lo = env_long(env, "SLURM_ARRAY_TASK_MIN", h2), hi = env_long(env, "SLURM_ARRAY_TASK_MAX", h3);
    bool hs = false, hc = false;
    const long step = env_long(env, "SLURM_ARRAY_TASK_STEP", hs), count = env_long(env, "SLURM_ARRAY_TASK_COUNT", hc);
    if (!h2) throw Error(src + ": SLURM_ARRAY_TASK_MIN is not set");
    const long st = hs ? step : 1;
    const long index = position(slurm_id, lo, st, src);
    if (hc) return with_count(index, count, true, src);
    if (!h3) throw Error(src + ": neither SLURM_ARRAY_TASK_COUNT nor SLURM_ARRAY_TASK_MAX is set");
    return with_count(index, (hi - lo) / st + 1, true, src);
  }
  // Kubernetes Indexed Job: JOB_COMPLETION_INDEX from 0; the count is not visible to the pod
  const long k8s = env_long(env, "JOB_COMPLETION_INDEX", has);
  if (has) return with_count(k8s, 0, false, "Kubernetes completion index " + std::to_string(k8s));
  // AWS Batch: index from 0 and the array size
  const long aws = env_long(env, "AWS_BATCH_JOB_ARRAY_INDEX", has);
  if (has) {
    const long size = env_long(env, "AWS_BATCH_JOB_ARRAY_SIZE", h2);
    return with_count(aws, size, h2, "AWS Batch array index " + std::to_string(aws));
  }
  // SGE / UGE: SGE_TASK_ID within FIRST..LAST by STEPSIZE ("undefined" outside an array job)
  const char* sge_text = env("SGE_TASK_ID");
  if (sge_text && *sge_text && std::string(sge_text) != "undefined") {
    const long id = env_long(env, "SGE_TASK_ID", has);
    const std::string src = "SGE task " + std::to_string(id);
    const long first = env_long(env, "SGE_TASK_FIRST", h2), last = env_long(env, "SGE_TASK_LAST", h3);
    const long step = env_long(env, "SGE_TASK_STEPSIZE", h4);
    if (!h2 || !h3) throw Error(src + ": SGE_TASK_FIRST or SGE_TASK_LAST is not set");
    const long st = h4 ? step : 1;
    return with_count(position(id, first, st, src), (last - first) / st + 1, true, src);
  }
  // LSF: LSB_JOBINDEX from 1 up to LSB_JOBINDEX_END (0 outside an array job)
  const long lsf = env_long(env, "LSB_JOBINDEX", has);
  if (has && lsf > 0) {
    const std::string src = "LSF job index " + std::to_string(lsf);
    const long end = env_long(env, "LSB_JOBINDEX_END", h2);
    bool hs = false;
    const long step = env_long(env, "LSB_JOBINDEX_STEP", hs);
    if (!h2) throw Error(src + ": LSB_JOBINDEX_END is not set");
    const long st = hs ? step : 1;
    // LSF does not tell where the array starts: 1 unless --shard-first says otherwise ("r[5-20]")
    const long first = shard_first > 0 ? shard_first : 1;
    return with_count(position(lsf, first, st, src + " (first index " + std::to_string(first) + ")"),
                      (end - first) / st + 1, true, src);
  }
  // PBS Pro (PBS_ARRAY_INDEX) / Torque (PBS_ARRAYID): neither tells the range
  for (const char* name : {"PBS_ARRAY_INDEX", "PBS_ARRAYID"}) {
    const long id = env_long(env, name, has);
    if (has) {
      const std::string src = std::string("PBS array index ") + std::to_string(id);
      return with_count(position(id, shard_first, 1, src + " (--shard-first " + std::to_string(shard_first) + ")"), 0,
                        false, src);
    }
  }
  throw UsageError(
      "--shard auto: no array job in the environment (none of SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX, "
      "AWS_BATCH_JOB_ARRAY_INDEX, SGE_TASK_ID, LSB_JOBINDEX, PBS_ARRAY_INDEX, PBS_ARRAYID is set)");
}

std::vector<long> shard_frames(const std::vector<long>& frames, const Shard& shard) {
  std::vector<long> out;
  for (size_t i = size_t(shard.index); i < frames.size(); i += size_t(shard.count)) out.push_back(frames[i]);
  return out;
}

}  // namespace pmr
