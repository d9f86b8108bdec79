#!/usr/bin/env bash
# The build context of docker/Dockerfile's target `prebuilt`: the image from an existing build's
# programs, without compiling. DEST receives what the runtime stage copies (docker/'s three
# scripts, scripts/install-deps.sh and scripts/packages/runtime.txt) and prebuilt/: bin/ with the
# shipped programs, stripped (deformd, deformctl, deform-loadtest, deform-vr,
# deform-health-probe), and web/ with the browser viewer's files from beside the build's deformd.
# The build must be a Release build of these sources on Debian 12, the runtime image's system
# (its programs link the same Debian packages' libraries). Prints what it staged.
#
#   scripts/stage-prebuilt-image.sh BUILD_DIR DEST
#   podman build --format docker --target prebuilt -f docker/Dockerfile -t deformd DEST
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: stage-prebuilt-image.sh BUILD_DIR DEST" >&2; exit 2; }
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$1"
dest="$2"
fail() { echo "stage-prebuilt-image: $*" >&2; exit 1; }
programs=(server/deformd/deformd server/deformctl/deformctl client/loadtest/deform-loadtest
  client/vr/deform-vr client/probe/deform-health-probe)
for program in "${programs[@]}"; do
  [ -x "$build/$program" ] || fail "no $build/$program: build first (scripts/build.sh)"
done
web="$build/server/deformd/web"
[ -f "$web/index.html" ] && [ -d "$web/vendor" ] ||
  fail "no viewer files in $web (scripts/install-node-tools.sh, then build)"
grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$build/CMakeCache.txt" ||
  fail "$build is not a Release build"

rm -rf "$dest"
mkdir -p "$dest/docker" "$dest/scripts/packages" "$dest/prebuilt/bin" "$dest/prebuilt/web"
cp "$root/docker/entrypoint.sh" "$root/docker/healthcheck.sh" "$root/docker/loadtest.sh" \
  "$dest/docker/"
cp "$root/scripts/install-deps.sh" "$dest/scripts/"
cp "$root/scripts/packages/runtime.txt" "$dest/scripts/packages/"
for program in "${programs[@]}"; do
  strip -o "$dest/prebuilt/bin/$(basename "$program")" "$build/$program"
done
# The served files only: package.json marks them ES modules for the node tests.
cp -R "$web/." "$dest/prebuilt/web/"
rm -f "$dest/prebuilt/web/package.json"
echo "stage-prebuilt-image: $dest holds $(find "$dest/prebuilt/bin" -type f | wc -l) programs" \
  "($(du -sb "$dest/prebuilt/bin" | cut -f1) bytes) and $(find "$dest/prebuilt/web" -type f |
  wc -l) viewer files ($(du -sb "$dest/prebuilt/web" | cut -f1) bytes)"
