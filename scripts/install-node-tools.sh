#!/usr/bin/env bash
# Installs the project's npm tooling from its lock files (npm ci: exactly the locked versions,
# nothing else): proto/ (buf) and client/web/ (the browser viewer's three.js, meshoptimizer
# decoder and protobuf runtime, copied beside deformd by the build; protoc-gen-es, with which the
# build generates the viewer's messages from the proto; puppeteer-core for its browser test, which
# drives Debian's chromium and downloads no browser) and scripts/k8s-schema/ (the Kubernetes API's
# schemas, which scripts/check-deploy-manifests.sh validates the cluster's manifests against).
# Installs Debian's nodejs and npm first if npm is missing.
# Idempotent: a folder whose node_modules was installed from its current lock file is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v npm >/dev/null 2>&1; then
  echo "install-node-tools: installing Debian's nodejs and npm"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm
fi

for dir in proto client/web scripts/k8s-schema; do
  stamp="$dir/node_modules/.installed-lock.json"  # the lock file the last npm ci installed
  if cmp -s "$dir/package-lock.json" "$stamp"; then continue; fi
  echo "install-node-tools: npm ci in $dir"
  npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error
  cp "$dir/package-lock.json" "$stamp"
done
