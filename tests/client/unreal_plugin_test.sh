#!/usr/bin/env bash
# The Unreal plugin skeleton (client/unreal), which cannot be compiled here (no Unreal toolchain):
# DeformClient.uplugin parses as JSON, names the runtime module DeformClient and carries the
# project's version; the module's folder holds DeformClient.Build.cs declaring that class, its
# Android APL file parses as XML; every deform_* function the plugin calls and every deform_*
# type and constant it names is declared in deform_c.h, and the functions are exported by
# deform_c.map's pattern; scripts/bundle-unreal-plugin.sh lays the plugin out with the header and
# the Linux library where DeformClient.Build.cs looks for them.
# Usage: unreal_plugin_test.sh SOURCE_DIR VERSION [LIBRARY]
set -euo pipefail
source_dir="$1"
version="$2"
library="${3:-}"
fail() { echo "unreal_plugin_test: $*" >&2; exit 1; }
plugin="$source_dir/client/unreal"
module="$plugin/Source/DeformClient"
header="$source_dir/client/c/deform_c.h"

python3 - "$plugin/DeformClient.uplugin" "$version" "$module/DeformClient_APL.xml" <<'PY' ||
import json, sys, xml.etree.ElementTree as ElementTree
path, version, apl = sys.argv[1:4]
try:
    descriptor = json.load(open(path))
except ValueError as e:
    sys.exit(f"{path}: {e}")
modules = [m for m in descriptor.get("Modules", []) if m.get("Name") == "DeformClient"]
if len(modules) != 1 or modules[0].get("Type") != "Runtime":
    sys.exit("DeformClient.uplugin: no Runtime module named DeformClient")
if descriptor.get("VersionName") != version:
    sys.exit(f"DeformClient.uplugin: VersionName {descriptor.get('VersionName')}, the project's is {version}")
if not any(p.get("Name") == "ProceduralMeshComponent" and p.get("Enabled") for p in descriptor.get("Plugins", [])):
    sys.exit("DeformClient.uplugin does not enable ProceduralMeshComponent")
ElementTree.parse(apl)
PY
  fail "the descriptor is wrong (above)"
grep -q 'public class DeformClient : ModuleRules' "$module/DeformClient.Build.cs" ||
  fail "DeformClient.Build.cs declares no DeformClient ModuleRules"
grep -q 'IMPLEMENT_MODULE(FDeformClientModule, DeformClient)' "$module/Private/DeformClientModule.cpp" ||
  fail "the module is not implemented under the name DeformClient"

sources=$(find "$module" -name '*.h' -o -name '*.cpp')
declared=$(tr '\n' ' ' <"$header" | grep -o 'DEFORM_C_API [^;(]*(' |
  sed -nE 's/.*[ *](deform_[a-z_0-9]+)\($/\1/p' | sort -u)
called=$(cat $sources | grep -oE '\bdeform_[a-z_0-9]+\(' | tr -d '(' | sort -u)
[ -n "$called" ] || fail "the plugin calls no deform_* function"
for function in $called; do
  echo "$declared" | grep -qx "$function" || fail "the plugin calls $function, which deform_c.h does not declare"
  grep -qE '^\s*deform_\*;' "$source_dir/client/c/deform_c.map" ||
    fail "deform_c.map does not export deform_*"
done
named=$(cat $sources | grep -oE '\b(deform_[a-z_0-9]+|DEFORM_[A-Z_0-9]+)\b' | grep -v '^DEFORM_CLIENT_' |
  sort -u | grep -vxF "$called" || true)
for name in $named; do
  grep -qE "\b$name\b" "$header" || fail "the plugin names $name, which deform_c.h does not define"
done

if [ -n "$library" ]; then
  WORK="$(mktemp -d)"
  trap 'rm -rf "$WORK"' EXIT
  "$source_dir/scripts/bundle-unreal-plugin.sh" "$WORK" "$library" || fail "bundle-unreal-plugin failed"
  third_party="$WORK/DeformClient/Source/ThirdParty/deform_c"
  cmp "$header" "$third_party/include/deform_c.h" || fail "the bundled header is not deform_c.h"
  lib="$third_party/lib/Linux/x86_64-unknown-linux-gnu"
  [ -e "$lib/libdeform_c.so" ] && [ -f "$lib/libdeform_c.so.0" ] ||
    fail "no libdeform_c.so and libdeform_c.so.0 in $lib"
  grep -q 'x86_64-unknown-linux-gnu' "$WORK/DeformClient/Source/DeformClient/DeformClient.Build.cs" ||
    fail "DeformClient.Build.cs does not look where the library is bundled"
fi
echo "unreal_plugin_test: DeformClient $version calls $(echo "$called" | wc -w) functions of" \
  "deform_c.h and names $(echo "$named" | wc -w) of its types and constants:" $called
