#!/usr/bin/env bash
# Integration test of the Blender add-on blender/pmr_lightfield (docs/BLENDER.md).
#
# Installs Debian's blender if missing, builds build/pmr if missing (or uses $PMR), then runs
# tests/blender/test_addon.py in a headless Blender with a temporary user scripts and config folder
# (the user's own Blender set-up is not touched): the add-on is installed from a zip and enabled, a
# small scene (active camera, sun, point light, keyframed cube, ground) is rendered as a 3-frame quilt
# sequence through the add-on's operator, and the script checks the files, the quilt layout, that
# the active camera was used, the point light's brightness against Cycles, and that Blender reads the
# quilt sequence frame by frame. Prints PASSED or FAILED; everything it wrote is removed.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

log() { echo "test-blender: $*" >&2; }
fail() { log "FAILED: $*"; exit 1; }

if ! command -v blender >/dev/null; then
  [ "$(id -u)" -eq 0 ] || fail "blender is missing; run as root to install it (apt-get install blender)"
  log "installing blender"
  apt-get update -q >/dev/null
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q blender >/dev/null
fi

PMR=${PMR:-$ROOT/build/pmr}
if [ ! -x "$PMR" ]; then
  log "building pmr"
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build --target pmr -j2 >/dev/null
  PMR=$ROOT/build/pmr
fi
PMR=$(cd "$(dirname "$PMR")" && pwd)/$(basename "$PMR")

TMP=$(mktemp -d /tmp/pmr-blender-XXXXXX)
trap 'rm -rf "$TMP"' EXIT
mkdir -p "$TMP/scripts" "$TMP/config"

# blender exits 0 even when a --python script fails: the script's own last line says PASSED or FAILED
set +e
BLENDER_USER_SCRIPTS="$TMP/scripts" BLENDER_USER_CONFIG="$TMP/config" \
  timeout 300 blender -b --factory-startup --python "$ROOT/tests/blender/test_addon.py" \
  -- --pmr "$PMR" --work "$TMP" > "$TMP/blender.log" 2>&1
status=$?
set -e
grep -E '^test-blender: ' "$TMP/blender.log" >&2 || true
if [ $status -ne 0 ] || ! tail -1 "$TMP/blender.log" | grep -q '^test-blender: PASSED'; then
  grep -q '^test-blender: FAILED' "$TMP/blender.log" || {
    tail -30 "$TMP/blender.log" >&2
    fail "blender exited with status $status before the test finished"
  }
  exit 1
fi
