# shellcheck shell=bash
# Sourced (bash) by the scripts and tests that run a deformd of their own: starting it on the
# port it is given (127.0.0.1:0: one the kernel picks), learning that port, and stopping it.
#
#   deformd_make_work        WORK = a new temporary folder; on exit, deformd_stop, then WORK is
#                            removed (an EXIT trap: the caller sets none of its own).
#   deformd_start LOG CMD..  runs CMD (a deformd command line) in the background, its output in
#                            LOG, and waits up to 30 s for the "listening on HOST:PORT" line:
#                            DEFORMD_PID is the process, DEFORMD_ADDRESS that HOST:PORT. Returns 1,
#                            saying why on stderr, if deformd exits or reports no address first.
#   deformd_stop             SIGTERM to the deformd deformd_start started, if it runs, and waits.

DEFORMD_PID=""
DEFORMD_ADDRESS=""

deformd_make_work() {
  WORK="$(mktemp -d)"
  trap 'deformd_stop; rm -rf "$WORK"' EXIT
}

deformd_start() {
  local log="$1"
  shift
  "$@" >"$log" 2>&1 &
  DEFORMD_PID=$!
  DEFORMD_ADDRESS=""
  for _ in $(seq 1 300); do
    DEFORMD_ADDRESS="$(sed -n 's/.*listening on \([0-9.]*:[0-9]*\).*/\1/p' "$log" | head -n 1)"
    [ -n "$DEFORMD_ADDRESS" ] && return 0
    if ! kill -0 "$DEFORMD_PID" 2>/dev/null; then
      echo "deformd exited at start-up" >&2
      return 1
    fi
    sleep 0.1
  done
  echo "deformd reported no address within 30 s" >&2
  return 1
}

deformd_stop() {
  if [ -n "$DEFORMD_PID" ]; then
    kill -TERM "$DEFORMD_PID" 2>/dev/null || true
    wait "$DEFORMD_PID" 2>/dev/null || true
    DEFORMD_PID=""
  fi
}
