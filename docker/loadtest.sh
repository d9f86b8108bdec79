#!/bin/sh
# compose's load test: N streams against the deformd service. LOADTEST_MESH and LOADTEST_SKELETON
# (files inside the container, e.g. under /meshes) upload a mesh; unset or empty, the built-in knee
# phantom. LOADTEST_TARGET, LOADTEST_STREAMS, LOADTEST_RATE, LOADTEST_DURATION as named.
set -eu
if [ -n "${LOADTEST_MESH:-}" ]; then
  set -- --mesh "$LOADTEST_MESH" --skeleton "${LOADTEST_SKELETON:?LOADTEST_SKELETON is required with LOADTEST_MESH}" "$@"
fi
exec deform-loadtest --target "${LOADTEST_TARGET:-deformd:50051}" \
  --streams "${LOADTEST_STREAMS:-8}" --rate "${LOADTEST_RATE:-90}" \
  --duration "${LOADTEST_DURATION:-10}" --json "$@"
