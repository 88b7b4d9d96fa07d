#!/usr/bin/env bash
# The benchmark corpus against OpenGL (docs/PERFORMANCE.md): every glTF model under DIR with at least
# MIN_TRIANGLES triangles (`pmr info`), and the synthetic scenes, each timed by gl_compare.sh (pmr and
# pmr_gl_bench alternated, the same shading on both sides). Prints gl_compare's table, then per sample
# count the geometric mean and the worst of the GL/pmr ratios, the real models and the synthetic scenes
# apart (a synthetic scene shaped by us is easier than a scan).
# Usage: tests/bench/corpus.sh [DIR]   (default: ../shared/gltf beside the project)
# Environment: as gl_compare.sh (BUILD, PRESET, SHADING, SAMPLES, FRAMES, ROUNDS), and
#   MIN_TRIANGLES (10000), SYNTHETIC ("--synthetic 100000;--objects 1000000": pmr bench scene options,
#   ';'-separated; empty for none), MODELS (a regex the model paths must match, to run a part).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
DIR=$(realpath "${1:-$root/../shared/gltf}")
BUILD=$(realpath "${BUILD:-$root/build}")
MIN_TRIANGLES=${MIN_TRIANGLES:-10000}
SYNTHETIC=${SYNTHETIC-"--synthetic 100000;--objects 1000000"}
MODELS=${MODELS:-.}
[ -d "$DIR" ] || { echo "corpus: no folder $DIR" >&2; exit 2; }
[ -x "$BUILD/pmr" ] || { echo "corpus: $BUILD/pmr missing: cmake --build build" >&2; exit 2; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

real=()
while IFS= read -r f; do
  # a model pmr cannot read (bad or unsupported input) is left out
  n=$( ("$BUILD/pmr" info "$f" 2>/dev/null || true) | sed -n 's/^triangles: \([0-9]*\).*/\1/p')
  if [ -n "$n" ] && [ "$n" -ge "$MIN_TRIANGLES" ]; then real+=("$f"); fi
done < <(find "$DIR" \( -name '*.gltf' -o -name '*.glb' \) | grep -E "$MODELS" | sort)
synthetic=()
IFS=';' read -r -a kinds <<< "$SYNTHETIC"
for k in "${kinds[@]}"; do
  [ -n "$k" ] || continue
  out="$WORK/synthetic_$(echo "$k" | tr -cd 'a-z0-9').glb"
  # shellcheck disable=SC2086
  "$BUILD/pmr" bench $k --save-scene "$out" >/dev/null
  synthetic+=("$out")
done
echo "# corpus: ${#real[@]} real model(s) with >= $MIN_TRIANGLES triangles from $DIR; ${#synthetic[@]} synthetic"

# summary GROUP < table: per sample count, the geometric mean and the worst GL/pmr ratio
summary() {
  awk -v group="$1" '$1 !~ /^#/ && $2 ~ /^[0-9]+$/ {
      n[$2]++; s[$2] += log($NF); if (!($2 in w) || $NF < w[$2]) { w[$2] = $NF; wn[$2] = $1 } }
    END { for (k in n) printf "# %s, %s spp: geometric mean %.2fx over %d, worst %.2fx (%s)\n",
                                group, k, exp(s[k] / n[k]), n[k], w[k], wn[k] }'
}
for group in real synthetic; do
  if [ "$group" = real ]; then scenes=("${real[@]}"); else scenes=("${synthetic[@]}"); fi
  [ ${#scenes[@]} -gt 0 ] || continue
  BUILD="$BUILD" "$here/gl_compare.sh" "${scenes[@]}" | tee "$WORK/$group.txt"
  summary "$group" < "$WORK/$group.txt"
done
