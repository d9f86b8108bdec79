#!/usr/bin/env bash
# scripts/bundle-unity-package.sh, run both ways (a folder and a .tgz), and what a Unity user
# then adds: package.json and the asmdef parse as JSON with the fields Unity needs, the package's
# version is the project's (CMake's project(VERSION), the one source), Runtime/Deform.cs is
# client/csharp/Deform.cs byte for byte, the plugin folder holds libdeform_c.so as a file whose
# every dependency but the C and C++ runtimes loads from that folder, every asset outside Samples~
# has a .meta with a GUID of its own (the same on a second run), the library's marks it a Linux
# x86_64 plugin, and the tarball holds the folder's files under package/.
# Usage: unity_package_test.sh SOURCE_DIR VERSION LIBRARY
set -euo pipefail
source_dir="$1"
version="$2"
library="$3"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "unity_package_test: $*" >&2; exit 1; }

bundle="$source_dir/scripts/bundle-unity-package.sh"
"$bundle" "$WORK/package" "$library" || fail "the folder could not be assembled"
"$bundle" "$WORK/package.tgz" "$library" || fail "the tarball could not be assembled"
package="$WORK/package"

python3 - "$package" "$version" <<'PY' || fail "package.json or the asmdef is wrong (above)"
import json, os, sys
package, version = sys.argv[1], sys.argv[2]
def load(path):
    try:
        with open(os.path.join(package, path)) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"{path}: {e}")
manifest = load("package.json")
for field in ("name", "version", "displayName", "description", "unity"):
    if not isinstance(manifest.get(field), str) or not manifest[field]:
        sys.exit(f"package.json: no {field}")
if manifest["name"] != "org.deformd.client":
    sys.exit(f"package.json: name {manifest['name']}")
if manifest["version"] != version:
    sys.exit(f"package.json: version {manifest['version']}, the project's is {version}")
for sample in manifest.get("samples", []):
    if not os.path.isdir(os.path.join(package, sample["path"])) or not sample["path"].startswith("Samples~/"):
        sys.exit(f"package.json: sample path {sample['path']} is not a folder under Samples~")
if not manifest.get("samples"):
    sys.exit("package.json: no samples")
asmdef = load("Runtime/Deformd.Client.asmdef")
if asmdef.get("name") != "Deformd.Client":
    sys.exit(f"the asmdef's name: {asmdef.get('name')}")
if not isinstance(asmdef.get("includePlatforms"), list):
    sys.exit("the asmdef has no includePlatforms list")
PY
[ "$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["version"])' \
  "$source_dir/client/unity/package.json")" = "$version" ] ||
  fail "client/unity/package.json's version is not the project's $version"

for file in package.json LICENSE.md Runtime/Deform.cs Runtime/DeformAxes.cs \
  Runtime/DeformMeshStream.cs Runtime/DeformMeshStreamer.cs Runtime/Deformd.Client.asmdef \
  Samples~/KneeFlexion/KneeFlexionSample.cs Runtime/Plugins/x86_64/libdeform_c.so; do
  [ -f "$package/$file" ] && [ ! -L "$package/$file" ] || fail "no file $file"
done
cmp "$source_dir/client/csharp/Deform.cs" "$package/Runtime/Deform.cs" ||
  fail "Runtime/Deform.cs is not client/csharp/Deform.cs"

plugin="$package/Runtime/Plugins/x86_64/libdeform_c.so"
readelf -d "$plugin" | grep -q 'Library rpath: \[\$ORIGIN\]' || fail "the library's DT_RPATH is not \$ORIGIN"
system='^(linux-vdso|ld-linux.*|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s)\.so'
outside=$(env -u LD_LIBRARY_PATH ldd "$plugin" | awk '/=>/ {print $1, $3}' | while read -r name path; do
  [[ "$name" =~ $system ]] && continue
  [ "$(dirname "$path")" = "$(dirname "$plugin")" ] || echo "$name from $path"
done)
[ -z "$outside" ] || fail "the plugin loads libraries from outside its folder: $outside"
dependencies=$(env -u LD_LIBRARY_PATH ldd "$plugin" | awk '/=>/ {print $1}' | grep -vcE "$system")

# .meta files: one per asset and folder outside Samples~, GUIDs of 32 hex digits, all different.
missing=$(find "$package" -mindepth 1 \( -name 'Samples~' -prune \) -o ! -name '*.meta' -print |
  while read -r asset; do [ -f "$asset.meta" ] || echo "$asset"; done)
[ -z "$missing" ] || fail "assets without a .meta: $missing"
[ -z "$(find "$package/Samples~" -name '*.meta')" ] || fail ".meta files under Samples~"
guids=$(find "$package" -name '*.meta' -exec sed -n 's/^guid: //p' {} +)
metas=$(find "$package" -name '*.meta' | wc -l)
[ "$(echo "$guids" | grep -cE '^[0-9a-f]{32}$')" = "$metas" ] || fail "a .meta without a GUID"
[ "$(echo "$guids" | sort -u | wc -l)" = "$metas" ] || fail "two .meta files share a GUID"
grep -q '^PluginImporter:' "$plugin.meta" && grep -q 'Standalone: Linux64' "$plugin.meta" ||
  fail "libdeform_c.so.meta does not make it a Linux x86_64 plugin"
"$bundle" "$WORK/again" "$library" >/dev/null
diff -r "$package" "$WORK/again" >/dev/null || fail "a second run wrote other files (GUIDs must be stable)"

mkdir "$WORK/unpacked"
tar -xzf "$WORK/package.tgz" -C "$WORK/unpacked"
[ "$(ls "$WORK/unpacked")" = package ] || fail "the tarball holds more than package/"
diff -r "$package" "$WORK/unpacked/package" || fail "the tarball's files differ from the folder's"
echo "unity_package_test: org.deformd.client $version: $(find "$package" -type f | wc -l) files," \
  "libdeform_c.so and its $dependencies dependencies in Runtime/Plugins/x86_64, $metas .meta files"
