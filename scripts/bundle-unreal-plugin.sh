#!/usr/bin/env bash
# The Unreal plugin (client/unreal) with the C API it links, ready to copy into a project's
# Plugins/ folder: DEST/DeformClient/ holds the .uplugin and Source/, the header in
# Source/ThirdParty/deform_c/include/ and, for Linux x86_64, the plugin folder of
# scripts/bundle-c-api.sh in Source/ThirdParty/deform_c/lib/Linux/x86_64-unknown-linux-gnu/
# (DeformClient.Build.cs stages it into the plugin's Binaries/). The Win64 and Android libraries
# are built elsewhere and copied into lib/Win64/ and lib/Android/arm64-v8a/
# (docs/clients/unreal.md). Prints what it wrote.
#
#   scripts/bundle-unreal-plugin.sh DEST [LIBRARY]   LIBRARY: default build/client/c/libdeform_c.so
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: bundle-unreal-plugin.sh DEST [LIBRARY]" >&2; exit 2; }
root="$(cd "$(dirname "$0")/.." && pwd)"
library="${2:-$root/build/client/c/libdeform_c.so}"
plugin="$1/DeformClient"
[ ! -e "$plugin" ] || { echo "bundle-unreal-plugin: $plugin exists" >&2; exit 1; }
mkdir -p "$plugin"
cp -R "$root/client/unreal/." "$plugin/"
third_party="$plugin/Source/ThirdParty/deform_c"
mkdir -p "$third_party/include" "$third_party/lib/Win64" "$third_party/lib/Android/arm64-v8a"
cp "$root/client/c/deform_c.h" "$third_party/include/"
cp "$root/LICENSE" "$plugin/LICENSE"
"$root/scripts/bundle-c-api.sh" "$third_party/lib/Linux/x86_64-unknown-linux-gnu" "$library" \
  >/dev/null
echo "bundle-unreal-plugin: $plugin holds $(find "$plugin" -type f | wc -l) files," \
  "$(find "$plugin" -type f -printf '%s\n' | awk '{ s += $1 } END { print s }') bytes"
