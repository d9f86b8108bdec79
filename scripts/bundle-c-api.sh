#!/usr/bin/env bash
# A plugin folder for the C API: copies libdeform_c.so.MAJOR (as that name and as libdeform_c.so,
# the name P/Invoke's "deform_c" opens) and every shared library it needs into DEST, except the
# C and C++ runtimes every Linux machine has (glibc's libraries, libstdc++, libgcc_s). The library
# looks for its dependencies beside itself first (its DT_RPATH is $ORIGIN), so the folder works
# wherever it is copied, on a machine without gRPC. Prints what it copied, with sizes.
#
#   scripts/bundle-c-api.sh DEST [LIBRARY]   LIBRARY: default build/client/c/libdeform_c.so
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: bundle-c-api.sh DEST [LIBRARY]" >&2; exit 2; }
dest="$1"
library="${2:-$(dirname "$0")/../build/client/c/libdeform_c.so}"
[ -e "$library" ] || { echo "bundle-c-api: no library at $library" >&2; exit 1; }
library="$(readlink -f "$library")"
soname="$(readelf -d "$library" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
[ -n "$soname" ] || { echo "bundle-c-api: $library has no SONAME" >&2; exit 1; }
# The runtimes not shipped: glibc's (libc, libm, the loader, ...), libstdc++ and libgcc_s.
system='^(linux-vdso|ld-linux.*|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s)\.so'
mkdir -p "$dest"
cp "$library" "$dest/$soname"
ln -sf "$soname" "$dest/libdeform_c.so"
missing="$(ldd "$library" | awk '/not found/ {print $1}')"
[ -z "$missing" ] || { echo "bundle-c-api: unresolved dependencies: $missing" >&2; exit 1; }
total=0
while read -r name path; do
  [[ "$name" =~ $system ]] && continue
  cp -L "$path" "$dest/$name"
  size=$(stat -c %s "$dest/$name")
  total=$((total + size))
  echo "$size $name"
done < <(ldd "$library" | awk '/=>/ {print $1, $3}')
size=$(stat -c %s "$dest/$soname")
echo "$size $soname"
echo "bundle-c-api: $dest holds $soname and $(($(find "$dest" -type f | wc -l) - 1)) libraries," \
  "$((total + size)) bytes"
