#!/usr/bin/env bash
# --version on the project's programs (ctest): version_test.sh VERSION PROGRAM...
# Each PROGRAM --version must print exactly "NAME VERSION (commit COMMIT)" on stdout and nothing on
# stderr, and exit 0, where NAME is the program's file name, VERSION the project's (CMake's
# PROJECT_VERSION, given by the test) and COMMIT the one this checkout is at
# (tests/expected_commit.sh). Every program is checked; the failures are listed together.
set -euo pipefail
VERSION="$1"
shift
[ $# -gt 0 ] || { echo "FAIL: no program given" >&2; exit 1; }
SOURCE_DIR="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=tests/expected_commit.sh
source "$SOURCE_DIR/tests/expected_commit.sh"
COMMIT=$(expected_commit "$SOURCE_DIR")
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
failed=0
for program in "$@"; do
  name=$(basename "$program")
  expected="$name $VERSION (commit $COMMIT)"
  status=0
  "$program" --version >"$WORK/out" 2>"$WORK/err" </dev/null || status=$?
  out=$(cat "$WORK/out")
  if [ "$status" -ne 0 ] || [ "$out" != "$expected" ] || [ -s "$WORK/err" ]; then
    echo "FAIL: $name --version: exit $status, stdout '$out', stderr '$(head -c 300 "$WORK/err")';" \
      "expected exit 0 and '$expected'" >&2
    failed=1
  else
    echo "ok: $out"
  fi
done
[ "$failed" -eq 0 ] || exit 1
echo "PASS: $# programs print '<name> $VERSION (commit $COMMIT)'"
