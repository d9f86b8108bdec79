#!/usr/bin/env bash
# The Unity package (client/unity, UPM layout) assembled with what it needs from the rest of the
# repository, as a folder ("Add package from disk...": pick its package.json) or, for DEST ending
# in .tgz, a tarball with the package under package/ ("Add package from tarball..."):
#   - client/unity's package.json, Runtime/ and Samples~/;
#   - Runtime/Deform.cs, a copy of client/csharp/Deform.cs (the binding has one home);
#   - Runtime/Plugins/x86_64/: the plugin folder of scripts/bundle-c-api.sh, with libdeform_c.so a
#     file rather than a link (P/Invoke's "deform_c"; tarballs and Unity's importer do not keep
#     links; the SONAME's copy libdeform_c.so.0 is left out: only programs linked against the
#     library ask for it);
#   - LICENSE.md (the repository's LICENSE);
#   - a .meta file for every file and folder outside Samples~ with a GUID derived from the
#     package's name and the path (the same on every run), since Unity ignores the assets of an
#     immutable package (a tarball's) that have none; the library's marks it a plugin for the
#     Linux x86_64 player and the Linux editor. Its dependencies (libgrpc.so.29, ...) are not
#     plugins: the loader finds them beside it through its DT_RPATH, $ORIGIN.
# package.json's version must be the project's (CMakeLists.txt's project(VERSION)): refused
# otherwise. Prints what it wrote.
#
#   scripts/bundle-unity-package.sh DEST [LIBRARY]   LIBRARY: default build/client/c/libdeform_c.so
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: bundle-unity-package.sh DEST [LIBRARY]" >&2; exit 2; }
dest="$1"
root="$(cd "$(dirname "$0")/.." && pwd)"
library="${2:-$root/build/client/c/libdeform_c.so}"
fail() { echo "bundle-unity-package: $*" >&2; exit 1; }

source="$root/client/unity"
project_version=$(sed -nE 's/^project\(deformd VERSION ([0-9.]+).*/\1/p' "$root/CMakeLists.txt")
package_version=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["version"])' \
  "$source/package.json") || fail "client/unity/package.json does not parse"
[ -n "$project_version" ] || fail "no project(deformd VERSION ...) in CMakeLists.txt"
[ "$package_version" = "$project_version" ] ||
  fail "client/unity/package.json has version $package_version, the project $project_version"
name=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["name"])' \
  "$source/package.json")

case "$dest" in
  *.tgz) staging="$(mktemp -d)"; trap 'rm -rf "$staging"' EXIT; package="$staging/package" ;;
  *) package="$dest"; [ ! -e "$package" ] || [ -z "$(ls -A "$package")" ] ||
       fail "$package exists and is not empty" ;;
esac
mkdir -p "$package"
cp "$source/package.json" "$package/"
cp -R "$source/Runtime" "$source/Samples~" "$package/"
cp "$root/client/csharp/Deform.cs" "$package/Runtime/Deform.cs"
cp "$root/LICENSE" "$package/LICENSE.md"
plugins="$package/Runtime/Plugins/x86_64"
"$root/scripts/bundle-c-api.sh" "$plugins" "$library" >/dev/null
soname="$(readelf -d "$plugins/libdeform_c.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
rm "$plugins/libdeform_c.so"
mv "$plugins/$soname" "$plugins/libdeform_c.so"

guid() { printf '%s:%s' "$name" "$1" | md5sum | cut -c1-32; }
plugin_meta() {
  cat <<META
fileFormatVersion: 2
guid: $1
PluginImporter:
  externalObjects: {}
  serializedVersion: 2
  iconMap: {}
  executionOrder: {}
  defineConstraints: []
  isPreloaded: 0
  isOverridable: 0
  isExplicitlyReferenced: 0
  validateReferences: 1
  platformData:
  - first:
      : Any
    second:
      enabled: 0
      settings:
        Exclude Editor: 0
        Exclude Linux64: 0
        Exclude OSXUniversal: 1
        Exclude Win: 1
        Exclude Win64: 1
  - first:
      Editor: Editor
    second:
      enabled: 1
      settings:
        CPU: x86_64
        DefaultValueInitialized: true
        OS: Linux
  - first:
      Standalone: Linux64
    second:
      enabled: 1
      settings:
        CPU: x86_64
  userData:
  assetBundleName:
  assetBundleVariant:
META
}
while IFS= read -r -d '' path; do
  relative="${path#"$package"/}"
  if [ -d "$path" ]; then
    printf '%s\n' 'fileFormatVersion: 2' "guid: $(guid "$relative")" 'folderAsset: yes' \
      'DefaultImporter:' '  externalObjects: {}' '  userData:' '  assetBundleName:' \
      '  assetBundleVariant:' >"$path.meta"
  elif [ "$relative" = Runtime/Plugins/x86_64/libdeform_c.so ]; then
    plugin_meta "$(guid "$relative")" >"$path.meta"
  else
    printf 'fileFormatVersion: 2\nguid: %s\n' "$(guid "$relative")" >"$path.meta"
  fi
done < <(find "$package" -mindepth 1 \( -name 'Samples~' -prune \) -o -print0 | sort -z)

files=$(find "$package" -type f | wc -l)
bytes=$(find "$package" -type f -printf '%s\n' | awk '{ s += $1 } END { print s }')
if [ -n "${staging:-}" ]; then
  tar -czf "$dest" -C "$staging" --owner=0 --group=0 --sort=name package
  echo "bundle-unity-package: $dest holds $name $package_version: $files files, $bytes bytes" \
    "($(stat -c %s "$dest") bytes compressed)"
else
  echo "bundle-unity-package: $dest holds $name $package_version: $files files, $bytes bytes"
fi
