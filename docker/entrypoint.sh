#!/bin/sh
# The image's entry point: starts deformd (exec: it is PID 1 and receives SIGTERM itself) with the
# listen address and preloads from the environment, then every argument given to `docker run IMAGE
# ...` or to compose's `command:`. So `docker run IMAGE --log-level debug` keeps listening on
# 0.0.0.0:$DEFORMD_PORT.
#
#   DEFORMD_PORT     port inside the container (default 50051); the health check probes it too
#   DEFORMD_LISTEN   the whole listen address (default 0.0.0.0:$DEFORMD_PORT)
#   DEFORMD_PRELOAD  space-separated meshes to load before serving: `phantom:N` (the built-in knee
#                    phantom of about N vertices) or `MESH:SKELETON` (files inside the container);
#                    empty or unset: none
#
# An explicit --listen among the arguments wins over DEFORMD_LISTEN (the health check then still
# probes DEFORMD_PORT: change the port through DEFORMD_PORT).
set -eu
port="${DEFORMD_PORT:-50051}"
listen="${DEFORMD_LISTEN:-0.0.0.0:$port}"

preloads=""
for item in ${DEFORMD_PRELOAD:-}; do
  case "$item" in
    phantom:*) preloads="$preloads --preload-phantom=${item#phantom:}" ;;
    *) preloads="$preloads --preload=$item" ;;
  esac
done

for arg in "$@"; do
  case "$arg" in
    --listen | --listen=*) exec deformd $preloads "$@" ;;
  esac
done
# $preloads is split on purpose (one word per flag; paths with spaces are not supported).
# shellcheck disable=SC2086
exec deformd --listen "$listen" $preloads "$@"
