#!/usr/bin/env bash
# Checks that libdeform_c.so exports exactly the functions deform_c.h declares: every declared
# deform_* function is defined and exported, and nothing else is (not the client library, the
# generated protobuf code, or a C++ symbol). Usage: check-c-api-exports.sh LIBRARY HEADER
set -euo pipefail
library="$1"
header="$2"
exported=$(nm -D --defined-only "$library" | awk '$2 ~ /^[TtWw]$/ {print $3}' | sort)
declared=$(tr '\n' ' ' <"$header" | grep -o 'DEFORM_C_API [^;(]*(' |
  sed -nE 's/.*[ *](deform_[a-z_0-9]+)\($/\1/p' | sort)
others=$(nm -D --defined-only "$library" | awk '$2 !~ /^[TtWw]$/ {print $3}')
if [ -n "$others" ]; then
  echo "check-c-api-exports: data or other symbols exported:" $others >&2
  exit 1
fi
if [ "$exported" != "$declared" ]; then
  echo "check-c-api-exports: exported and declared functions differ (< exported, > declared):" >&2
  diff <(echo "$exported") <(echo "$declared") >&2 || true
  exit 1
fi
echo "check-c-api-exports: $(echo "$exported" | wc -l) functions, exactly those of $(basename "$header")"
