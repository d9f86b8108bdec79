#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz: every mesh reader, the glTF rig reader, the skeleton
# and skin-weight readers, the phantom's size, the request conversions: pose, stiffness update,
# LoadMesh header, and the Deform and LoadMesh stream handlers end to end through a scripted
# transport) with ASan and UBSan, and runs each from its seed corpus
# (tests/fuzz/corpus/<target>/) for DEFORM_FUZZ_SECONDS seconds (default 20). Prints every
# target's executions; exits non-zero on any crash, sanitizer report, timeout or leak (the input
# is kept under $DEFORM_FUZZ_ARTIFACTS, default build-asan/fuzz-artifacts), or when fewer than
# DEFORM_FUZZ_MIN_RUNS executions (default 1,000,000) ran in total.
#
# Builds in build-asan ($DEFORM_ASAN_BUILD_DIR), the ASan+UBSan build it shares with
# scripts/check-sanitizers.sh (scripts/sanitizers/asan-build.sh: clang++, ccache when installed,
# -O1 and line tables; one sanitizer build of the core instead of two keeps .ci/run in its time);
# only the fuzz targets and what they link are compiled here. New inputs found go to a temporary
# corpus, never into the repository. Installs what is missing (scripts/packages/build.txt and
# checks.txt: clang, libclang-rt-14-dev).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
# shellcheck source=scripts/sanitizers/asan-build.sh
source scripts/sanitizers/asan-build.sh
BUILD_DIR="$DEFORM_ASAN_BUILD_DIR"
SECONDS_PER_TARGET="${DEFORM_FUZZ_SECONDS:-20}"
MIN_TOTAL_RUNS="${DEFORM_FUZZ_MIN_RUNS:-1000000}"
ARTIFACTS="${DEFORM_FUZZ_ARTIFACTS:-$BUILD_DIR/fuzz-artifacts}"
TARGETS=(mesh_obj_fuzz mesh_off_fuzz mesh_ply_fuzz mesh_stl_fuzz gltf_fuzz skeleton_tgf_fuzz
  skeleton_json_fuzz weights_dmat_fuzz weights_csv_fuzz phantom_fuzz pose_request_fuzz
  stiffness_request_fuzz load_header_fuzz deform_stream_fuzz load_mesh_stream_fuzz)

scripts/install-deps.sh scripts/packages/build.txt scripts/packages/checks.txt

configure_asan_build "$BUILD_DIR"
cmake --build "$BUILD_DIR" --target fuzzers --parallel "$(nproc)"
echo "run-fuzz: built in $(($(date +%s) - start)) s"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$ARTIFACTS"
export_sanitizer_options
total=0
failed=()
for target in "${TARGETS[@]}"; do
  seeds="tests/fuzz/corpus/$target"
  [ -d "$seeds" ] || { echo "run-fuzz: no seed corpus $seeds" >&2; exit 1; }
  mkdir -p "$work/$target"
  log="$work/$target.log"
  status=0
  "$BUILD_DIR/tests/fuzz/$target" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 \
    -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$ARTIFACTS/$target-" "$work/$target" "$seeds" >"$log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  runs=${runs:-0}
  total=$((total + runs))
  if [ "$status" -ne 0 ]; then
    tail -40 "$log"
    failed+=("$target")
    printf 'run-fuzz: %-24s %9d executions in %s s: FAILED (exit %d)\n' "$target" "$runs" \
      "$SECONDS_PER_TARGET" "$status"
  else
    printf 'run-fuzz: %-24s %9d executions in %s s, 0 crashes, corpus %d inputs\n' "$target" \
      "$runs" "$SECONDS_PER_TARGET" "$(find "$work/$target" "$seeds" -type f | wc -l)"
  fi
done
echo "run-fuzz: $total executions in total, $((${#TARGETS[@]} - ${#failed[@]})) of" \
  "${#TARGETS[@]} targets clean, $(($(date +%s) - start)) s"
[ ${#failed[@]} -eq 0 ] || { echo "run-fuzz: FAILED: ${failed[*]} (inputs in $ARTIFACTS)" >&2; exit 1; }
[ "$total" -ge "$MIN_TOTAL_RUNS" ] ||
  { echo "run-fuzz: FAILED: only $total executions, fewer than $MIN_TOTAL_RUNS" >&2; exit 1; }
echo "run-fuzz: PASSED"
