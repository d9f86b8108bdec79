#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer, then the service tests
# (in-process servers, the hostile-client tests and the deformd they start) under
# ThreadSanitizer. Exits non-zero on any failing test or sanitizer report.
#
#   ASan+UBSan: build-asan ($DEFORM_ASAN_BUILD_DIR, shared with scripts/run-fuzz.sh:
#               scripts/sanitizers/asan-build.sh), every test target and deformd, then ctest
#               (all tests: none is skipped; tests on the large shared meshes run as they are).
#               Leaks: scripts/sanitizers/lsan.supp lists OpenMesh's one-time registry only.
#   TSan:       build-tsan ($DEFORM_TSAN_BUILD_DIR), deform_service_tests,
#               deform_hostile_client_tests and deformd, run directly. gRPC and protobuf come
#               from Debian uninstrumented: TSan cannot see their internal synchronisation, so
#               scripts/sanitizers/tsan.supp suppresses reports inside their code only (each
#               entry says why); races in our code are never suppressed.
#
# clang++ (scripts/packages/checks.txt) with ccache when installed, -O1 and line tables. Sanitizer
# reports stop the run at the first one (halt_on_error) so a report fails the test that caused it.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
# shellcheck source=scripts/sanitizers/asan-build.sh
source scripts/sanitizers/asan-build.sh
ASAN_DIR="$DEFORM_ASAN_BUILD_DIR"
TSAN_DIR="${DEFORM_TSAN_BUILD_DIR:-build-tsan}"
only="${1:-all}"  # all, asan or tsan

scripts/install-deps.sh scripts/packages/build.txt scripts/packages/checks.txt
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

configure_tsan_build() {  # DIR
  cmake -S . -B "$1" -G Ninja -DCMAKE_CXX_COMPILER=clang++ "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DDEFORM_BUILD_BENCHMARKS=OFF >/dev/null
}

if [ "$only" = all ] || [ "$only" = asan ]; then
  configure_asan_build "$ASAN_DIR"
  cmake --build "$ASAN_DIR" --parallel "$(nproc)"
  echo "check-sanitizers: ASan+UBSan build done after $(($(date +%s) - start)) s"
  (export_sanitizer_options &&
    ctest --test-dir "$ASAN_DIR" --output-on-failure --parallel "$(nproc)" --timeout 1200)
  echo "check-sanitizers: ASan+UBSan suite passed after $(($(date +%s) - start)) s"
fi

if [ "$only" = all ] || [ "$only" = tsan ]; then
  tsan_start=$(date +%s)
  configure_tsan_build "$TSAN_DIR"
  cmake --build "$TSAN_DIR" --parallel "$(nproc)" \
    --target deform_service_tests deform_hostile_client_tests deformd
  echo "check-sanitizers: TSan build done after $(($(date +%s) - tsan_start)) s"
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/scripts/sanitizers/tsan.supp"
  for program in deform_service_tests deform_hostile_client_tests; do
    "$TSAN_DIR/tests/$program" --gtest_brief=1
  done
  echo "check-sanitizers: TSan service tests passed after $(($(date +%s) - tsan_start)) s"
fi
echo "check-sanitizers: PASSED in $(($(date +%s) - start)) s"
