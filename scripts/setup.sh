#!/usr/bin/env bash
# Installs (idempotently) the Debian packages the project needs, then configures and builds it.
# Usage: scripts/setup.sh [BUILD_DIR [TARGET...]]   (default: build, every target)
# TARGET names CMake targets to build instead of all of them (render.sh builds only pmr).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build}
TARGETS=("${@:2}")

PACKAGES=(
  g++ cmake make pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers clinfo
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenexr-dev openexr libopencolorio-dev libpng-dev libxxhash-dev libdeflate-dev libisal-dev
  libgtest-dev
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri  # pmr_gl_bench (tests/bench/gl_multiview.cpp) only
  python3 python3-matplotlib
)
# more packages for one script's own needs (scripts/fuzz.sh: clang), installed the same way
read -r -a EXTRA <<< "${PMR_SETUP_EXTRA_PACKAGES:-}"
PACKAGES+=("${EXTRA[@]}")
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
fi
# scripts/fuzz.sh needs the packages only (it builds with clang in its own folder)
[ "${PMR_SETUP_PACKAGES_ONLY:-0}" = 1 ] && exit 0

# PMR_WERROR=ON (set by .ci/run): warnings in pmr's own sources fail the build
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPMR_WERROR="${PMR_WERROR:-OFF}" >/dev/null
if [ ${#TARGETS[@]} -gt 0 ]; then
  cmake --build "$BUILD_DIR" -j "$(nproc)" --target "${TARGETS[@]}"
else
  cmake --build "$BUILD_DIR" -j "$(nproc)"
fi
