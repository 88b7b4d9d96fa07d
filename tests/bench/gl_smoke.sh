#!/usr/bin/env bash
# The ctest smoke test of pmr_gl_bench (not timed): a tiny rig of the bundled scene rendered by pmr and
# by the GL program, whose views must agree in coverage (alpha) on all but a few edge pixels. Exits 77
# (skipped) when no EGL display or OpenGL context can be made.
# Usage: tests/bench/gl_smoke.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene="$source/data/default_scene.glb"
"$build/pmr" render "$scene" --views 4 --view-size 96x48 --display 240x135 --shading lambert \
  --samples 1 --write encoded,views --out "$work/pmr" >/dev/null
status=0
"$build/pmr_gl_bench" "$scene" --sidecar "$work/pmr/frame_0000.json" --msaa 0 --frames 1 --no-mipmap \
  --out "$work/gl" || status=$?
[ "$status" = 0 ] || exit "$status"
# 'part P channel A: N of M values differ ...': at most 3% of a view's pixels differ in coverage (the
# comparison itself exits 1 whenever any bit differs, which rounding alone makes certain)
compared=$("$build/pmr_exr_compare" "$work/gl/gl_views.exr" "$work/pmr/frame_0000.views.exr" || true)
echo "$compared" |
  awk '$4 == "A:" { parts++; if ($5 > 0.03 * $7) { bad = 1; print "coverage differs: " $0 } }
       END { if (parts != 4) print "expected 4 views, read " parts; exit (bad || parts != 4) }'
