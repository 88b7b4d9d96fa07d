#!/usr/bin/env bash
# Fuzzes the readers of files from strangers (docs/SECURITY.md) with libFuzzer, AddressSanitizer and
# UndefinedBehaviorSanitizer: the glTF/GLB loader with its images, the environment image reader, the
# Looking Glass calibration reader, the sidecar reader, a planted lock file and posing (tests/fuzz).
# Usage: scripts/fuzz.sh SECONDS [TARGET...]   (TARGET: gltf environment calibration sidecar lock posing; default all)
#   Installs clang-14 and its runtime if missing, builds the targets in build-fuzz/ (-DPMR_FUZZ=ON), runs
#   every input of tests/fuzz/regressions/TARGET once, then fuzzes each target for SECONDS (0: only the
#   regression inputs). The corpus grows in build-fuzz/fuzz-corpus/TARGET, seeded with the crafted
#   inputs of pmr_fuzz_seeds and the small models of ../shared/gltf (PMR_GLTF_DIR) when present.
#   Crashes, leaks, timeouts and inputs over the memory limit are kept in build-fuzz/fuzz-crashes/TARGET;
#   the exit status is 1 when there is any (a fixed one then goes to tests/fuzz/regressions/TARGET).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ] || ! [[ "$1" =~ ^[0-9]+$ ]]; then
  echo "usage: scripts/fuzz.sh SECONDS [gltf|environment|calibration|sidecar|lock|posing ...]" >&2
  exit 2
fi
SECONDS_EACH=$1
TARGETS=("${@:2}")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(gltf environment calibration sidecar lock posing)
for t in "${TARGETS[@]}"; do
  case "$t" in gltf|environment|calibration|sidecar|lock|posing) ;; *) echo "fuzz.sh: unknown target '$t'" >&2; exit 2 ;; esac
done

# the project's libraries, and clang with its sanitizer and libFuzzer runtimes
PMR_SETUP_PACKAGES_ONLY=1 PMR_SETUP_EXTRA_PACKAGES="clang-14 libclang-rt-14-dev" bash scripts/setup.sh

BUILD=build-fuzz
# -O1 and line tables only: the sanitizers' usual setting, and a build several times faster than -O2 -g
# (assertions stay on)
cmake -S . -B "$BUILD" -DPMR_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=Fuzz \
  -DCMAKE_CXX_FLAGS_FUZZ="-O1 -gline-tables-only" >/dev/null
cmake --build "$BUILD" -j "$(nproc)" --target pmr_fuzz_seeds "${TARGETS[@]/#/pmr_fuzz_}" >/dev/null

# Seeds: regenerated each run (the corpus keeps what the fuzzer found).
rm -rf "$BUILD/fuzz-seeds"
"$BUILD/tests/fuzz/pmr_fuzz_seeds" "$BUILD/fuzz-seeds"
GLTF_DIR=${PMR_GLTF_DIR:-../shared/gltf}
if [ -d "$GLTF_DIR" ]; then
  find "$GLTF_DIR" -type f \( \( -name '*.glb' -size -256k \) -o \( -name '*.gltf' -size -64k \) \) |
    while read -r f; do
      for t in gltf posing; do
        cp "$f" "$BUILD/fuzz-seeds/$t/corpus_$(basename "$(dirname "$(dirname "$f")")")_$(basename "$f")"
      done
    done
else
  echo "fuzz: $GLTF_DIR not found: the glTF target starts from the crafted seeds only"
fi

# The sanitizers stop at the first error of any kind; libFuzzer's limits: 2 GB of memory per process
# and per allocation (inputs the budgets allow stay far below), 60 s per input.
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
LIMITS=(-rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=60)
failed=()
for t in "${TARGETS[@]}"; do
  bin="$BUILD/tests/fuzz/pmr_fuzz_$t"
  regressions=(tests/fuzz/regressions/"$t"/*)
  if [ -e "${regressions[0]}" ]; then
    echo "fuzz: $t: ${#regressions[@]} regression input(s)"
    # regression inputs are small files: no one allocation over 256 MB (some found a memory bomb)
    if ! "$bin" "${LIMITS[@]}" -malloc_limit_mb=256 "${regressions[@]}" >"$BUILD/fuzz-$t-regressions.log" 2>&1; then
      echo "fuzz: $t: a regression input fails again (log: $BUILD/fuzz-$t-regressions.log)" >&2
      failed+=("$t")
      continue
    fi
  fi
  [ "$SECONDS_EACH" -eq 0 ] && continue
  mkdir -p "$BUILD/fuzz-corpus/$t" "$BUILD/fuzz-crashes/$t"
  echo "fuzz: $t: ${SECONDS_EACH}s"
  # the sidecar reader's findings were large inputs (deep nesting, many keys): room for them, and a
  # short timeout so that a slow parse is a finding
  more=()
  [ "$t" = sidecar ] && more=(-max_len=4194304 -timeout=5)
  if ! "$bin" "${LIMITS[@]}" "${more[@]}" -max_total_time="$SECONDS_EACH" -close_fd_mask=3 -print_final_stats=1 \
       -dict=tests/fuzz/"$(case $t in lock) echo sidecar ;; posing) echo gltf ;; *) echo "$t" ;; esac)".dict -artifact_prefix="$BUILD/fuzz-crashes/$t/" \
       "$BUILD/fuzz-corpus/$t" "$BUILD/fuzz-seeds/$t" >"$BUILD/fuzz-$t.log" 2>&1; then
    echo "fuzz: $t: found a problem (log: $BUILD/fuzz-$t.log; inputs: $BUILD/fuzz-crashes/$t/)" >&2
    failed+=("$t")
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$BUILD/fuzz-$t.log" | sed "s/^/fuzz: $t: /" || true
  echo "fuzz: $t: corpus $(find "$BUILD/fuzz-corpus/$t" -type f | wc -l) inputs"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: problems in: ${failed[*]} (reproduce: $BUILD/tests/fuzz/pmr_fuzz_TARGET INPUT)" >&2
  exit 1
fi
echo "fuzz: no problems found"
