#!/usr/bin/env bash
# pmr against OpenGL on the same CPU (docs/PERFORMANCE.md, "Against OpenGL (Mesa llvmpipe)"): for each
# scene and sample count, pmr renders the frame once for its sidecar (the cameras and display the GL
# program reuses), then `pmr bench` and pmr_gl_bench time it alternately, ROUNDS times each, and the
# medians and their ratio are printed. The same shading on both sides (SHADING: lambert, or pbr with
# the uniform environment); pmr --samples 1 against GL without MSAA, --samples 4 against MSAA 4x.
# Usage: tests/bench/gl_compare.sh [SCENE...]   (default: the bundled scene)
# Environment: BUILD (build), PRESET (paper-8k), SHADING (lambert), SAMPLES ("1 4"), FRAMES (3), ROUNDS (2),
#              GL_ARGS (more pmr_gl_bench options, e.g. "--encoder float"), KEEP (a folder: keep the frames)
set -euo pipefail
scenes=()
for a in "$@"; do scenes+=("$(realpath "$a")"); done  # named from the caller's folder
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
PRESET=${PRESET:-paper-8k}
SHADING=${SHADING:-lambert}
SAMPLES=${SAMPLES:-"1 4"}
FRAMES=${FRAMES:-3}
ROUNDS=${ROUNDS:-2}
GL_ARGS=${GL_ARGS:-}
shading=(--shading "$SHADING")  # pbr: the uniform environment, the one pmr_gl_bench draws
[ "$SHADING" = pbr ] && shading+=(--environment uniform)
[ ${#scenes[@]} -gt 0 ] || scenes=(data/default_scene.glb)
for exe in pmr pmr_gl_bench; do
  [ -x "$BUILD/$exe" ] || { echo "gl_compare: $BUILD/$exe missing: cmake --build $BUILD --target $exe" >&2; exit 2; }
done
WORK=${KEEP:-$(mktemp -d)}
[ -n "${KEEP:-}" ] || trap 'rm -rf "$WORK"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "# $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores (load $(cut -d' ' -f1-3 /proc/loadavg)); preset $PRESET; $SHADING; $FRAMES frames x $ROUNDS rounds"
printf "%-28s %3s %5s %10s %10s %10s %10s %10s %7s\n" scene spp msaa pmr_ms gl_ms gl_views gl_interl gl_readbk gl/pmr
for scene in "${scenes[@]}"; do
  name=$(basename "$scene")
  for s in $SAMPLES; do
    msaa=$([ "$s" = 1 ] && echo 0 || echo "$s")
    out="$WORK/${name%.*}_s$s"
    "$BUILD/pmr" render "$scene" --preset "$PRESET" "${shading[@]}" --samples "$s" --out "$out" >/dev/null 2>&1
    : > "$out/pmr.txt"; : > "$out/gl.txt"
    for _ in $(seq "$ROUNDS"); do
      "$BUILD/pmr" bench "$scene" --preset "$PRESET" --method pmr "${shading[@]}" --samples "$s" \
        --frames "$FRAMES" --no-check | awk '$1 == "pmr" { print $7 }' >> "$out/pmr.txt"
      # shellcheck disable=SC2086
      "$BUILD/pmr_gl_bench" "$scene" --sidecar "$out/frame_0000.json" --msaa "$msaa" --frames "$FRAMES" $GL_ARGS |
        awk '$1 == "GL_MS_PER_FRAME" { print $2, $3, $4, $5 }' >> "$out/gl.txt"
    done
    pmr_ms=$(median < "$out/pmr.txt")
    gl=()
    for c in 1 2 3 4; do gl+=("$(awk -v c=$c '{ print $c }' "$out/gl.txt" | median)"); done
    printf "%-28s %3s %5s %10.1f %10.1f %10.1f %10.1f %10.1f %7.2f\n" "$name" "$s" "$msaa" "$pmr_ms" "${gl[0]}" \
      "${gl[1]}" "${gl[2]}" "${gl[3]}" "$(awk -v a="${gl[0]}" -v b="$pmr_ms" 'BEGIN { print a / b }')"
  done
done
