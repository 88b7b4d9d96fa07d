#!/usr/bin/env bash
# Integration test of the Blender add-on blender/pmr_lightfield (docs/BLENDER.md).
#
# Installs Debian's blender if missing, builds build/pmr if missing (or uses $PMR), then runs
# tests/blender/test_addon.py in a headless Blender with a temporary user scripts and config folder
# (the user's own Blender set-up is not touched): the add-on is installed from a zip and enabled, a
# small scene (active camera, sun, point light, keyframed cube, ground) is rendered as a 3-frame quilt
# sequence through the add-on's operator, and the script checks the files, the quilt layout, that
# the active camera was used, the point light's brightness against Cycles, the whole scene under an HDRI
# world against Cycles (mean |sRGB difference|), the shadow catcher, that a camera named "1" and
# the pattern shot_%0d reach pmr as they are (pmr alone names the files), and that Blender reads the
# quilt sequence frame by frame. Then, under Xvfb (xvfb is installed with blender when missing),
# tests/blender/test_modal.py drives the interactive path in a Blender with a window: the modal
# operator with its progress, the quilt shown in an Image Editor, and cancelling a render.
# Prints PASSED or FAILED; everything it wrote is removed.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

log() { echo "test-blender: $*" >&2; }
fail() { log "FAILED: $*"; exit 1; }

missing=()
command -v blender >/dev/null || missing+=(blender)
command -v xvfb-run >/dev/null || missing+=(xvfb xauth)
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    log "installing ${missing[*]}"
    apt-get update -q >/dev/null
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}" >/dev/null
  elif ! command -v blender >/dev/null; then
    fail "blender is missing; run as root to install it (apt-get install blender)"
  fi
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

# run_blender NAME ARGS...: Blender with private user folders and its own work folder; blender exits
# 0 even when a --python script fails, so the script's last line (PASSED or FAILED) decides.
# Returns 1 on failure, so that both tests run and each failure is listed.
run_blender() {
  local name=$1 work="$TMP/$1"
  shift
  mkdir -p "$work/scripts" "$work/config"
  set +e
  BLENDER_USER_SCRIPTS="$work/scripts" BLENDER_USER_CONFIG="$work/config" \
    timeout 150 "$@" -- --pmr "$PMR" --work "$work" > "$work/blender.log" 2>&1
  local status=$?
  set -e
  grep -E '^test-blender: ' "$work/blender.log" | grep -v ': PASSED$' >&2 || true
  if [ $status -ne 0 ] || ! grep -q '^test-blender: PASSED' "$work/blender.log"; then
    grep -q '^test-blender: FAILED' "$work/blender.log" || {
      tail -30 "$work/blender.log" >&2
      log "$name: blender exited with status $status before the test finished"
    }
    return 1
  fi
}

failed=()
run_blender headless blender -b --factory-startup --python "$ROOT/tests/blender/test_addon.py" ||
  failed+=(headless)
if command -v xvfb-run >/dev/null; then
  run_blender interactive xvfb-run -a blender --factory-startup \
    --python "$ROOT/tests/blender/test_modal.py" || failed+=(interactive)
else
  log "skipping the interactive test: xvfb-run is missing (apt-get install xvfb xauth, as root)"
fi
[ ${#failed[@]} -eq 0 ] || fail "${failed[*]} (the lines above say why)"
log "PASSED"
