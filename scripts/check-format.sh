#!/usr/bin/env bash
# clang-format's verdict on the tracked C and C++ sources (*.h, *.cc, *.c: git ls-files), with the
# repository's .clang-format: exits 1 listing every file whose formatting differs (and the first
# differences clang-format reports), 0 when none does. Pinned to clang-format-14 (Debian 12,
# scripts/packages/checks.txt) because another version formats some constructs differently.
# Every tracked source is the project's own: third-party code comes from Debian's packages
# (server/core/io/internal/tiny_gltf.h only configures and includes <tiny_gltf.h>), so nothing is
# excluded. Fix a file with `clang-format-14 -i FILE`.
#
#   scripts/check-format.sh [FILE...]   default: every tracked source
set -euo pipefail
cd "$(dirname "$0")/.."
CLANG_FORMAT="${CLANG_FORMAT:-clang-format-14}"
if ! command -v "$CLANG_FORMAT" >/dev/null 2>&1; then
  scripts/install-deps.sh scripts/packages/checks.txt
fi
command -v "$CLANG_FORMAT" >/dev/null 2>&1 ||
  { echo "check-format: $CLANG_FORMAT not found" >&2; exit 1; }

if [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(git ls-files -- '*.h' '*.cc' '*.c')
fi
[ ${#files[@]} -gt 0 ] || { echo "check-format: no files to check" >&2; exit 1; }

report=$(mktemp)
trap 'rm -f "$report"' EXIT
status=0
"$CLANG_FORMAT" --style=file --dry-run --Werror "${files[@]}" 2>"$report" || status=$?
mapfile -t differing < <(sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' \
  "$report" | sort -u)
if [ "$status" -ne 0 ] && [ ${#differing[@]} -eq 0 ]; then  # failed for another reason
  cat "$report" >&2
  echo "check-format: FAILED: $CLANG_FORMAT exited $status" >&2
  exit 1
fi
if [ ${#differing[@]} -gt 0 ]; then
  head -30 "$report" >&2
  printf 'check-format: differs: %s\n' "${differing[@]}" >&2
  echo "check-format: FAILED: ${#differing[@]} of ${#files[@]} files differ from .clang-format" \
    "(clang-format-14 -i FILE fixes one)" >&2
  exit 1
fi
echo "check-format: ${#files[@]} files formatted as .clang-format says"
