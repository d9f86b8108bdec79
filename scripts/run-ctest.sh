#!/usr/bin/env bash
# ctest over a build directory, with a skipped test failing the run as a failed one does: ctest
# counts a skip as a pass ("100% tests passed"), so a run that lost what its tests need (the
# shared data above all: tests/shared_data.h) would otherwise stay green. The only skips allowed
# are those the CPU decides: a solve kernel whose instruction set this CPU lacks (the reasons in
# CPU_SKIP_REASONS, as the kernel tests word them). Every other skip is listed with its reason and
# fails the run (exit 1). Used by scripts/run-tests.sh and scripts/check-sanitizers.sh.
#
#   scripts/run-ctest.sh BUILD_DIR [ctest arguments...]
set -euo pipefail
BUILD_DIR="$1"
shift
CPU_SKIP_REASONS=("this CPU lacks the instruction set" "is not available on this build or CPU")
junit=$(mktemp)
trap 'rm -f "$junit"' EXIT
status=0
ctest --test-dir "$BUILD_DIR" --output-junit "$junit" "$@" || status=$?
skips=0
python3 - "$junit" "${CPU_SKIP_REASONS[@]}" <<'PY' || skips=$?
import sys
import xml.etree.ElementTree as ET

junit, allowed = sys.argv[1], sys.argv[2:]
cases = ET.parse(junit).getroot().iter("testcase")
skipped = [(case.get("name"), case.findtext("system-out") or "")
           for case in cases if case.find("skipped") is not None]
refused = [(name, out) for name, out in skipped if not any(reason in out for reason in allowed)]
for name, out in refused:
    # gtest prints the reason on the lines before "[  SKIPPED ]".
    lines = [line for line in out.splitlines() if line.strip()]
    reason = next((lines[i - 1] for i, line in enumerate(lines)
                   if line.startswith("[  SKIPPED ]") and i > 0), out.strip()[-300:])
    print(f"run-ctest: skipped: {name}: {reason}", file=sys.stderr)
if refused:
    print(f"run-ctest: FAILED: {len(refused)} of {len(skipped)} skipped tests were not skipped for "
          "the CPU (a skip is not a pass)", file=sys.stderr)
    sys.exit(1)
print(f"run-ctest: {len(skipped)} tests skipped, each for this CPU's instruction set" if skipped
      else "run-ctest: no test skipped")
PY
[ "$status" -eq 0 ] || exit "$status"
exit "$skips"
