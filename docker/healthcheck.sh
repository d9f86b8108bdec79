#!/bin/sh
# The image's health check: the standard gRPC health service on the port deformd was told to use
# (DEFORMD_PORT, default 50051; see entrypoint.sh).
exec deform-health-probe --target "127.0.0.1:${DEFORMD_PORT:-50051}" --timeout-ms 2000
