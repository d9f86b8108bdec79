#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs the whole test suite, where a
# skipped test fails the run (scripts/run-ctest.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh scripts/packages/build.txt scripts/packages/browser.txt \
  scripts/packages/csharp.txt scripts/packages/deploy.txt
scripts/install-node-tools.sh
scripts/build.sh
scripts/run-ctest.sh "${DEFORM_BUILD_DIR:-build}" --output-on-failure --parallel "$(nproc)" \
  --timeout 600
