#!/bin/sh
# The image's health check: the standard gRPC health service on the port deformd was told to use
# (DEFORMD_PORT, default 50051; see entrypoint.sh). deform-health-probe's exit codes tell why a
# check failed (1 arguments, 2 no connection, 3 RPC failed, 4 NOT_SERVING: docs/clients/probe.md),
# but Docker's HEALTHCHECK reads only 0 (healthy) and 1 (unhealthy) and reserves 2, so every
# failure exits 1 here; the probe's reason stays on stderr, in `docker inspect`'s health log.
deform-health-probe --target "127.0.0.1:${DEFORMD_PORT:-50051}" --connect-timeout-ms 1500 \
  --timeout-ms 1000 || exit 1
