#!/usr/bin/env bash
# pmr's center view of a scene against Cycles drawing the same camera, lights and environment with
# direct light only (max bounces 0: what pmr computes), as docs/SHADING.md ("Against Cycles") states it.
#
# usage: scripts/compare-cycles.sh [SCENE.glb] [PMR OPTIONS...]
#   SCENE   default data/default_scene.glb; the options go to `pmr render` (default: --environment
#           uniform, the default light). Renders 9 views of 400x300 with pmr (build/pmr, or $PMR) and
#           the center view with Cycles (128 samples; blender from Debian, installed when missing as
#           root), and prints the mean |sRGB difference| over the pixels both cover. BOUNCES (default 0)
#           sets Cycles' max bounces: 0 is what pmr computes, more adds the indirect light pmr leaves out.
#           Not part of CI.
set -euo pipefail
cd "$(dirname "$0")/.."
SCENE=${1:-data/default_scene.glb}
shift || true
[ $# -gt 0 ] || set -- --environment uniform
PMR=${PMR:-build/pmr}
[ -x "$PMR" ] || { echo "compare-cycles: $PMR not found: build it with scripts/setup.sh build" >&2; exit 1; }
if ! command -v blender > /dev/null; then
  [ "$(id -u)" -eq 0 ] || { echo "compare-cycles: blender is missing (apt-get install blender)" >&2; exit 1; }
  apt-get update -q > /dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q blender > /dev/null
fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$PMR" render "$SCENE" --views 9 --view-size 400x300 --write views --preview --quiet --out "$WORK/pmr" "$@"
blender -b --factory-startup --python tests/blender/compare_cycles.py -- --scene "$SCENE" --pmr-dir "$WORK/pmr" \
  --work "$WORK" --bounces "${BOUNCES:-0}" 2>&1 | grep -E "^compare-cycles|Error" || { echo "compare-cycles: Blender failed" >&2; exit 1; }
