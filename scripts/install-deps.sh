#!/usr/bin/env bash
# Installs Debian 12 packages: those listed in the given files (one per line, '#' comments), by
# default scripts/packages/build.txt (everything building, testing and running deformd needs).
# Idempotent: packages already present are skipped; apt runs only when something is missing.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
LISTS=("$@")
[ ${#LISTS[@]} -gt 0 ] || LISTS=("$HERE/packages/build.txt")

PACKAGES=()
for list in "${LISTS[@]}"; do
  while read -r package _; do
    [ -n "$package" ] && [ "${package:0:1}" != "#" ] && PACKAGES+=("$package")
  done <"$list"
done

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
