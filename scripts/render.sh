#!/usr/bin/env bash
# Set-up to result: installs what is missing, builds, and renders the bundled default scene at the
# paper configuration (96 views of 1024x512 -> 7680x4320) to OUT_DIR/frame_0000.exr (default: out).
# Extra arguments go to `pmr render`. Builds only the renderer; scripts/test.sh builds the tests too.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh build pmr
exec build/pmr render --out "${OUT_DIR:-out}" --verbose "$@"
