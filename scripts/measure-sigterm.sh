#!/usr/bin/env bash
# How long deformd takes to exit on SIGTERM while it is busiest: STREAMS Deform streams running
# (deform-loadtest on the built-in phantom at 90 Hz), an idle connection (a client that connected
# and makes no call), and a large phantom build in progress (deform-vr loading PHANTOM vertices).
# Prints the SIGTERM-to-exit time, the exit code and the grace period; ROUNDS rounds. Needs a
# Release build in build/ and /usr/bin/python3 with python3-grpcio (the idle connection).
#
#   scripts/measure-sigterm.sh [ROUNDS] [STREAMS] [PHANTOM] [GRACE_S]   (default 3 50 400000 5)
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
streams=${2:-50}
phantom=${3:-400000}
grace=${4:-5}
work=$(mktemp -d)
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; rm -rf "$work"' EXIT

for round in $(seq 1 "$rounds"); do
  build/server/deformd/deformd --listen 127.0.0.1:0 --shutdown-grace-s "$grace" \
    --max-memory-mb 16384 >"$work/deformd.log" 2>&1 &
  server=$!
  pids=("$server")
  for _ in $(seq 1 100); do grep -q "listening on" "$work/deformd.log" && break; sleep 0.05; done
  target=$(sed -n 's/.*listening on \([0-9.]*:[0-9]*\).*/\1/p' "$work/deformd.log" | head -1)
  build/client/loadtest/deform-loadtest --target "$target" --streams "$streams" --rate 90 \
    --duration 60 --json >"$work/load.json" 2>"$work/load.err" &
  pids+=($!)
  /usr/bin/python3 -c '
import grpc, sys, time
channel = grpc.insecure_channel(sys.argv[1])
grpc.channel_ready_future(channel).result(timeout=10)
time.sleep(120)' "$target" &
  pids+=($!)
  # Wait until every stream is open, then start the build.
  for _ in $(seq 1 200); do
    [ "$(grep -c "opened" "$work/deformd.log")" -ge "$streams" ] && break
    sleep 0.05
  done
  build/client/vr/deform-vr --target "$target" --phantom-vertices "$phantom" --duration 1 \
    >"$work/vr.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 1 400); do grep -q "phantom of $phantom vertices requested" "$work/deformd.log" && break; sleep 0.05; done
  sleep 1  # the build is well under way
  open=$(grep -c "opened" "$work/deformd.log")
  start=$(date +%s.%N)
  kill -TERM "$server"
  status=0
  wait "$server" || status=$?
  end=$(date +%s.%N)
  printf '{"round": %d, "streams_open": %d, "phantom_vertices": %d, "grace_s": %s, "sigterm_to_exit_s": %.2f, "exit_code": %d}\n' \
    "$round" "$open" "$phantom" "$grace" "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')" "$status"
  kill "${pids[@]}" 2>/dev/null || true
  wait 2>/dev/null || true
done
