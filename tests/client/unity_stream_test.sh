#!/usr/bin/env bash
# The Unity package's Unity-independent code (client/unity/Runtime/DeformAxes.cs and
# DeformMeshStream.cs, with client/csharp/Deform.cs) compiled by Mono's mcs and run under mono
# against the real deformd through the build's libdeform_c.so: tests/client/unity/
# DeformMeshStreamTest.cs (see that file). DeformMeshStreamer.cs needs UnityEngine and is not
# compiled here.
# Usage: unity_stream_test.sh MCS MONO DEFORMD LIBRARY_DIR SOURCE_DIR
set -euo pipefail
mcs="$1"
mono="$2"
deformd="$3"
library_dir="$4"
source_dir="$5"
# shellcheck source=scripts/deformd-process.sh
source "$source_dir/scripts/deformd-process.sh"
deformd_make_work

fail() {
  echo "unity_stream_test: $*" >&2
  [ -f "$WORK/deformd.log" ] && sed 's/^/  deformd: /' "$WORK/deformd.log" >&2
  exit 1
}

runtime="$source_dir/client/unity/Runtime"
"$mcs" -warnaserror -out:"$WORK/DeformMeshStreamTest.exe" "$source_dir/client/csharp/Deform.cs" \
  "$runtime/DeformAxes.cs" "$runtime/DeformMeshStream.cs" \
  "$source_dir/tests/client/unity/DeformMeshStreamTest.cs" || fail "mcs failed"
deformd_start "$WORK/deformd.log" "$deformd" --listen 127.0.0.1:0 --workers 2 ||
  fail "deformd did not start"
LD_LIBRARY_PATH="$library_dir" "$mono" "$WORK/DeformMeshStreamTest.exe" "$DEFORMD_ADDRESS" ||
  fail "the stream test failed against deformd"
