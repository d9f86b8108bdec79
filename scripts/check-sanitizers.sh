#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer, then the service tests
# whose threads meet through our own synchronization under ThreadSanitizer. Exits non-zero on any
# failing test or sanitizer report. Run by .ci/run after scripts/run-fuzz.sh.
#
#   ASan+UBSan: build-asan ($DEFORM_ASAN_BUILD_DIR, shared with scripts/run-fuzz.sh:
#               scripts/sanitizers/asan-build.sh), everything ctest runs (the test programs,
#               deformd and the clients the process tests start, the C API, the Python stubs, the
#               viewer's files; no benchmarks), then ctest, 2 at a time: every test of the suite (but
#               the OutOfDescriptors tests, whose emptied descriptor table the runtime needs), the
#               tests on the large shared meshes as they are (durations: docs/testing.md). The
#               benchmarks' ctest tests (bench/animation) are not built here (Release suite only).
#               A skipped test fails the suite as in the Release run (scripts/run-ctest.sh).
#               Leaks: scripts/sanitizers/lsan.supp lists OpenMesh's one-time registry only.
#   TSan:       build-tsan ($DEFORM_TSAN_BUILD_DIR), deform_service_concurrency_tests (the files of
#               the suites below only, so that TSan compiles no other test), run on the suites in
#               TSAN_SUITES: the frame slots, outbox, pending pose, write pump, self-owning handler,
#               stiffness switch, worker pool and its parallel runner, registry, token table and the allocation-free
#               frame paths, where threads meet through our mutexes, condition variables and
#               atomics, which TSan sees. The tests that start gRPC servers or channels (and
#               deform_hostile_client_tests, deformd) are not run under TSan: Debian's gRPC,
#               protobuf and absl are not instrumented, so the handover between gRPC's threads
#               (absl::Mutex on futexes, atomics inside libgrpc) is invisible and TSan reports
#               every reactor callback as racing with the reactor's constructor (thousands of
#               reports in one run of the service tests: docs/testing.md); hiding them would
#               mean suppressing our own code. Those tests run under ASan+UBSan above.
#               scripts/sanitizers/tsan.supp is for third-party code only and lists nothing.
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
# What ctest runs in build-asan: every test program, and what the process tests execute.
TSAN_SUITES=(AnnotatedMutexTest DeformOutboxTest FrameSlotsTest FrameSolverTest PendingPoseSlotTest
  PoseInputTest SelfOwningHandlerTest StiffnessSwitchTest StreamWritePumpTest WorkerPoolTest
  MeshRegistryTest StatusMappingTest TokenTableTest WorkerPoolParallelRunnerTest)
# The one program (tests/CMakeLists.txt, built in this build only) that holds those suites' files.
TSAN_PROGRAMS=(deform_service_concurrency_tests)

scripts/install-deps.sh scripts/packages/build.txt scripts/packages/checks.txt
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

configure_tsan_build() {  # DIR
  cmake -S . -B "$1" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DDEFORM_BUILD_BENCHMARKS=OFF >/dev/null
}

if [ "$only" = all ] || [ "$only" = asan ]; then
  configure_asan_build "$ASAN_DIR"
  # Everything ctest runs (benchmarks are off in this build): the test programs, deformd and
  # the clients the process tests start, the C API, the Python stubs, the viewer's files.
  cmake --build "$ASAN_DIR" --parallel "$(nproc)"
  echo "check-sanitizers: ASan+UBSan build done after $(($(date +%s) - start)) s"
  # The tests that run a server out of descriptors are the Release suite's alone: the sanitizer
  # runtime needs descriptors of its own (UBSan's vptr check opens a pipe to probe memory), so
  # with none left it reports every virtual call of ours as a bad object.
  (export_sanitizer_options &&
    scripts/run-ctest.sh "$ASAN_DIR" --output-on-failure --parallel "$(nproc)" --timeout 1200 \
      -E 'OutOfDescriptors')
  echo "check-sanitizers: ASan+UBSan suite passed after $(($(date +%s) - start)) s"
fi

if [ "$only" = all ] || [ "$only" = tsan ]; then
  tsan_start=$(date +%s)
  configure_tsan_build "$TSAN_DIR"
  cmake --build "$TSAN_DIR" --parallel "$(nproc)" --target "${TSAN_PROGRAMS[@]}"
  echo "check-sanitizers: TSan build done after $(($(date +%s) - tsan_start)) s"
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/scripts/sanitizers/tsan.supp"
  filter=$(printf '%s.*:' "${TSAN_SUITES[@]}")
  listed=""
  for program in "${TSAN_PROGRAMS[@]}"; do
    listed+=$("$TSAN_DIR/tests/$program" --gtest_list_tests --gtest_filter="${filter%:}")$'\n'
  done
  for suite in "${TSAN_SUITES[@]}"; do  # a renamed suite must not leave the check empty
    grep -qx "$suite\." <<<"$listed" ||
      { echo "check-sanitizers: no suite $suite in ${TSAN_PROGRAMS[*]}" >&2; exit 1; }
  done
  # Five rounds for more interleavings (the suites take under a second a round).
  for program in "${TSAN_PROGRAMS[@]}"; do
    "$TSAN_DIR/tests/$program" --gtest_brief=1 --gtest_filter="${filter%:}" --gtest_repeat=5
  done
  echo "check-sanitizers: TSan service tests passed after $(($(date +%s) - tsan_start)) s"
fi
echo "check-sanitizers: PASSED in $(($(date +%s) - start)) s"
