#!/usr/bin/env bash
# Set-up to result: installs what is missing, builds, and runs the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh build
cd build
exec ctest --output-on-failure -j "$(nproc)" "$@"
