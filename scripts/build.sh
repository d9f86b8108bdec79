#!/usr/bin/env bash
# Configures and builds the project in Release into build/ (or $DEFORM_BUILD_DIR).
# Extra arguments go to cmake's configure step, e.g. -DDEFORM_BUILD_BENCHMARKS=OFF. Compiles through
# ccache when it is installed (scripts/packages/build.txt lists it), so rebuilds and CI reruns on
# the same machine are fast.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/ccache-env.sh
source scripts/ccache-env.sh
BUILD_DIR="${DEFORM_BUILD_DIR:-build}"
GENERATOR=()
if command -v ninja >/dev/null 2>&1; then GENERATOR=(-G Ninja); fi
LAUNCHER=()
if command -v ccache >/dev/null 2>&1; then LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  cmake -S . -B "$BUILD_DIR" "${GENERATOR[@]}" "${LAUNCHER[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
elif [ $# -gt 0 ]; then
  cmake -S . -B "$BUILD_DIR" "$@"
fi
cmake --build "$BUILD_DIR" --parallel "$(nproc)"
