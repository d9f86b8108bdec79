#!/usr/bin/env bash
# client/csharp/Deform.cs, the P/Invoke binding of the C API, compiled with Mono's mcs and run
# under mono against the real deformd through the build's libdeform_c.so: first that it declares
# every function of deform_c.h and no other, then tests/client/csharp/DeformBindingTest.cs (its
# structs' layouts against the C compiler's, then a stream; see that file).
# Usage: csharp_binding_test.sh MCS MONO DEFORMD LIBRARY_DIR SOURCE_DIR VERSION
set -euo pipefail
mcs="$1"
mono="$2"
deformd="$3"
library_dir="$4"
source_dir="$5"
version="$6"
# shellcheck source=scripts/deformd-process.sh
source "$source_dir/scripts/deformd-process.sh"
deformd_make_work

fail() {
  echo "csharp_binding_test: $*" >&2
  [ -f "$WORK/deformd.log" ] && sed 's/^/  deformd: /' "$WORK/deformd.log" >&2
  exit 1
}

header="$source_dir/client/c/deform_c.h"
binding="$source_dir/client/csharp/Deform.cs"
declared=$(tr '\n' ' ' <"$header" | grep -o 'DEFORM_C_API [^;(]*(' |
  sed -nE 's/.*[ *](deform_[a-z_0-9]+)\($/\1/p' | sort)
bound=$(tr '\n' ' ' <"$binding" | grep -oE 'static extern [^(]*\(' |
  sed -nE 's/.* (deform_[a-z_0-9]+)\($/\1/p' | sort)
if [ "$declared" != "$bound" ]; then
  echo "csharp_binding_test: deform_c.h and Deform.cs differ (< header, > Deform.cs):" >&2
  diff <(echo "$declared") <(echo "$bound") >&2 || true
  exit 1
fi

cc -std=c11 -Wall -Wextra -Werror -I"$source_dir/client/c" -o "$WORK/c_layouts" \
  "$source_dir/tests/client/csharp/c_layouts.c" || fail "the layout program did not compile"
"$WORK/c_layouts" >"$WORK/layouts.txt"
"$mcs" -warnaserror -out:"$WORK/DeformBindingTest.exe" "$binding" \
  "$source_dir/tests/client/csharp/DeformBindingTest.cs" || fail "mcs failed"

deformd_start "$WORK/deformd.log" "$deformd" --listen 127.0.0.1:0 --workers 2 ||
  fail "deformd did not start"
# DllImport("deform_c") finds libdeform_c.so on the loader's path.
LD_LIBRARY_PATH="$library_dir" "$mono" "$WORK/DeformBindingTest.exe" "$DEFORMD_ADDRESS" \
  "$version" "$WORK/layouts.txt" || fail "the binding test failed against deformd"
echo "csharp_binding_test: Deform.cs binds the $(echo "$declared" | wc -l) functions of deform_c.h"
