#!/usr/bin/env bash
# Antialiasing error, pmr against OpenGL (docs/ANTIALIASING.md, "Against OpenGL"): for each scene, the
# views of one rig rendered by pmr (`pmr quality --samples 1,4`: against its 64-sample reference) and
# by pmr_gl_bench on Mesa llvmpipe without MSAA and with MSAA 4x and mipmaps, against GL's own
# 64-sample reference (the views 4x as wide and tall at MSAA 4x, box-filtered: pmr_view_quality).
# The same error measure on both sides; each renderer against its own reference, so that the two
# shaders' small differences are not counted as error.
# Usage: tests/bench/gl_quality.sh [SCENE...]   (default: the bundled scene)
# Environment: BUILD (build), VIEWS (8), SIZE (256x128), SHADING (pbr)
set -euo pipefail
scenes=()
for a in "$@"; do scenes+=("$(realpath "$a")"); done  # named from the caller's folder
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
VIEWS=${VIEWS:-8}
SIZE=${SIZE:-256x128}
SHADING=${SHADING:-pbr}
[ ${#scenes[@]} -gt 0 ] || scenes=(data/default_scene.glb)
for exe in pmr pmr_gl_bench pmr_view_quality; do
  [ -x "$BUILD/$exe" ] || { echo "gl_quality: $BUILD/$exe missing: cmake --build $BUILD --target $exe" >&2; exit 2; }
done
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
w=${SIZE%x*} h=${SIZE#*x}
rig=(--views "$VIEWS" --shading "$SHADING")
[ "$SHADING" = pbr ] && rig+=(--environment uniform)  # the environment pmr_gl_bench draws
for scene in "${scenes[@]}"; do
  name=$(basename "$scene")
  echo "== $name: $VIEWS views of $SIZE, $SHADING"
  "$BUILD/pmr" quality "$scene" "${rig[@]}" --view-size "$SIZE" --samples 1,4 | sed 's/^/pmr: /'
  "$BUILD/pmr" render "$scene" "${rig[@]}" --view-size "$SIZE" --write views -q --out "$WORK/base"
  "$BUILD/pmr" render "$scene" "${rig[@]}" --view-size "$((4 * w))x$((4 * h))" --write views -q --out "$WORK/fine"
  "$BUILD/pmr_gl_bench" "$scene" --sidecar "$WORK/fine/frame_0000.json" --msaa 4 --frames 1 --out "$WORK/gl_ref" >/dev/null
  for msaa in 0 4; do
    "$BUILD/pmr_gl_bench" "$scene" --sidecar "$WORK/base/frame_0000.json" --msaa "$msaa" --frames 1 \
      --out "$WORK/gl_msaa$msaa" >/dev/null
  done
  "$BUILD/pmr_view_quality" "$WORK/gl_ref/gl_views.exr" "$WORK/gl_msaa0/gl_views.exr" "$WORK/gl_msaa4/gl_views.exr" |
    sed "s|$WORK/||; s/^/gl:  /"
done
