#!/usr/bin/env bash
# The main job: installs what is missing, builds, starts deformd and runs the VR-frontend
# stand-in (deform-vr) against it: the built-in knee phantom bent 0 -> 120 -> 0 degrees at 90 Hz,
# printing pose-to-frame latency. Extra arguments go to deform-vr (see deform-vr --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/install-node-tools.sh
scripts/build.sh
BIN="${DEFORM_BUILD_DIR:-build}"
ADDR="127.0.0.1:${DEFORM_DEMO_PORT:-50051}"

"$BIN/server/deformd/deformd" --listen "$ADDR" --log-level warn &
SERVER=$!
trap 'kill -TERM $SERVER 2>/dev/null || true; wait $SERVER 2>/dev/null || true' EXIT

"$BIN/client/vr/deform-vr" --target "$ADDR" "$@"
