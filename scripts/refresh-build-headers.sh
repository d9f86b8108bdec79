#!/usr/bin/env bash
# Brings the headers and compilers a build reads to the Debian mirror's current versions: every
# installed -dev package (linux-libc-dev, libc6-dev, libstdc++-12-dev, libssl-dev, ...) and the
# GCC and Clang compilers that have an upgrade, nothing else. Run by .ci/run before it builds: the
# image's builder stage (scripts/container-check.sh) installs the current versions, and ccache
# reuses the host's objects there only when both compiled against the same header files. A
# machine made from an older snapshot otherwise compiles the image's programs a second time.
# Prints what it upgraded; does nothing when nothing is behind.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
mapfile -t behind < <(apt list --upgradable 2>/dev/null | sed -n 's|^\([^/]*\)/.*|\1|p' |
  grep -E -- '-dev$|^(cpp|gcc|g\+\+|clang|libclang-rt)(-[0-9]+)?(-dev)?$' || true)
if [ ${#behind[@]} -eq 0 ]; then
  echo "refresh-build-headers: every -dev package and compiler is current"
  exit 0
fi
echo "refresh-build-headers: upgrading ${behind[*]}"
$SUDO apt-get install -y -qq --only-upgrade --no-install-recommends "${behind[@]}" >/dev/null
