# Sourced by scripts/run-fuzz.sh and scripts/check-sanitizers.sh: the one ASan+UBSan build both
# use, so that the core, the service and the tests are compiled with the sanitizers once.
#
#   configure_asan_build DIR   configures DIR: clang++ (ccache when installed), -O1 with line
#                              tables, ASan + UBSan (no recovery), libFuzzer's coverage
#                              instrumentation (-fsanitize=fuzzer-no-link: the fuzz targets link
#                              libFuzzer, the tests do not), the fuzz targets and the tests, no
#                              benchmarks.
#   export_sanitizer_options   ASAN_OPTIONS, UBSAN_OPTIONS and LSAN_OPTIONS (halt at the first
#                              report; scripts/sanitizers/lsan.supp) unless already set.
# shellcheck source=scripts/ccache-env.sh
source scripts/ccache-env.sh  # the sourcing script is at the repository root
DEFORM_ASAN_BUILD_DIR="${DEFORM_ASAN_BUILD_DIR:-build-asan}"
DEFORM_SANITIZER_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined"

configure_asan_build() {
  local launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  # C (the C API's test) with clang too: with gcc, CMake would take gcc's sanitizer runtime among
  # the C compiler's implicit link libraries, beside clang's (two ASan runtimes in one program).
  cmake -S . -B "$1" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
    -DCMAKE_C_FLAGS="$DEFORM_SANITIZER_FLAGS -fno-omit-frame-pointer" "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS="$DEFORM_SANITIZER_FLAGS -fsanitize=fuzzer-no-link -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="$DEFORM_SANITIZER_FLAGS" \
    -DDEFORM_BUILD_FUZZERS=ON -DDEFORM_BUILD_TESTS=ON -DDEFORM_BUILD_BENCHMARKS=OFF >/dev/null
}

export_sanitizer_options() {
  local here
  here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:allocator_may_return_null=1}"
  export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
  export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$here/lsan.supp:print_suppressions=0}"
}
