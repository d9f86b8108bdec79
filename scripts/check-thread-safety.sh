#!/usr/bin/env bash
# Clang's thread-safety analysis over the code whose locks carry annotations (server/service:
# DEFORM_GUARDED_BY, DEFORM_REQUIRES, ... from server/service/base/thread_annotations.h), with every
# warning an error. Exits non-zero, the findings printed, when a guarded member is touched without
# its lock, a *Locked helper is called without it, or any other Clang warning appears there.
#
# Builds in its own directory (build-tsa, or $DEFORM_TSA_BUILD_DIR) with clang++ and
# -DDEFORM_THREAD_SAFETY_ANALYSIS=ON, which adds -Wthread-safety to our targets only (the
# generated protobuf code gets none), where -Werror is on in every build. Only the object files
# of the annotated targets are compiled (no linking, no tests, no core libraries), without
# optimization: the analysis runs in the front end. Installs what is missing
# (scripts/packages/build.txt and checks.txt: clang); ccache makes reruns fast (durations:
# docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/ccache-env.sh
source scripts/ccache-env.sh
start=$(date +%s)
BUILD_DIR="${DEFORM_TSA_BUILD_DIR:-build-tsa}"
# The targets whose sources carry annotations.
ANNOTATED_TARGETS=(deform_service_base deform_service_metrics deform_service_access
  deform_service_workers deform_service_registry deform_service_transport deform_service_messages
  deform_service_context deform_service_load deform_service_deform deform_service_contact
  deform_service_rpc)

scripts/install-deps.sh scripts/packages/build.txt scripts/packages/checks.txt

# The analysis itself must be on: a member touched without its lock has to fail to compile.
canary_log=$(mktemp)
trap 'rm -f "$canary_log"' EXIT
if clang++ -std=c++17 -fsyntax-only -Wthread-safety -Werror -Iserver -x c++ - \
  >"$canary_log" 2>&1 <<'CANARY'; then
#include "service/base/annotated_mutex.h"
class Counter {
 public:
  void Increment() { ++count_; }  // no lock: must be reported
 private:
  deform::service::Mutex mutex_;
  int count_ DEFORM_GUARDED_BY(mutex_) = 0;
};
CANARY
  echo "check-thread-safety: clang++ accepted an unlocked access to a guarded member;" \
    "the analysis is not working" >&2
  exit 1
fi
grep -q "requires holding mutex" "$canary_log" || {
  cat "$canary_log" >&2
  exit 1
}

mkdir -p "$BUILD_DIR"
LAUNCHER=()
if command -v ccache >/dev/null 2>&1; then LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
# CMAKE_BUILD_TYPE=None: no optimization and no debug information, the fastest compile.
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_COMPILER=clang++ \
  "${LAUNCHER[@]}" -DDEFORM_THREAD_SAFETY_ANALYSIS=ON -DDEFORM_BUILD_TESTS=OFF \
  -DDEFORM_BUILD_BENCHMARKS=OFF >"$BUILD_DIR/configure.log" 2>&1 || {
  cat "$BUILD_DIR/configure.log" >&2
  exit 1
}

objects=()
for target in "${ANNOTATED_TARGETS[@]}"; do
  mapfile -t target_objects < <(ninja -C "$BUILD_DIR" -t targets all |
    sed -n "s|^\(.*/CMakeFiles/${target}\.dir/.*\.o\): .*|\1|p")
  if [ ${#target_objects[@]} -eq 0 ]; then
    echo "check-thread-safety: no object files found for target ${target}" >&2
    exit 1
  fi
  if ! grep -F "/${target}.dir/" "$BUILD_DIR/compile_commands.json" |
    grep -- "-Wthread-safety" >/dev/null; then
    echo "check-thread-safety: ${target} is not compiled with -Wthread-safety" >&2
    exit 1
  fi
  objects+=("${target_objects[@]}")
done

if ! ninja -C "$BUILD_DIR" -k 0 -j "$(nproc)" "${objects[@]}"; then
  echo "check-thread-safety: FAILED (the errors above; -Wthread-safety -Werror)" >&2
  exit 1
fi
echo "check-thread-safety: ${#objects[@]} files of ${ANNOTATED_TARGETS[*]} clean under" \
  "-Wthread-safety -Werror after $(($(date +%s) - start)) s"
