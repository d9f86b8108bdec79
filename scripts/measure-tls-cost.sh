#!/usr/bin/env bash
# The cost of TLS on the frames: deform-loadtest on the shared 1.6k leg, one stream and 64 streams
# at 90 Hz, against a plaintext deformd and a TLS deformd started one after the other (same
# machine, same run, alternating), each configuration ROUNDS times. Prints one JSON line per run
# (mode, streams, delivered fraction, p50/p99 latency) and needs a Release build in build/.
#
#   scripts/measure-tls-cost.sh [ROUNDS] [DURATION_S]         (default 2 rounds of 10 s)
#
# Uses ports 51000-51999 (random) and a throw-away CA (scripts/make-test-certificates.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-2}
duration=${2:-10}
data=${DEFORM_SHARED_DATA:-../shared/data}
mesh=$data/leg/leg_1633.obj
skeleton=$data/leg/leg.tgf
[[ -f $mesh && -f $skeleton ]] || { echo "measure-tls-cost: $mesh or $skeleton missing" >&2; exit 1; }
work=$(mktemp -d)
trap 'kill "${server:-}" 2>/dev/null || true; rm -rf "$work"' EXIT
scripts/make-test-certificates.sh "$work/certs" >/dev/null
port=$((51000 + RANDOM % 1000))

run() {  # mode streams
  local mode=$1 streams=$2 server_tls=() client_tls=()
  if [[ $mode == tls ]]; then
    server_tls=(--tls-cert "$work/certs/server.pem" --tls-key "$work/certs/server.key")
    client_tls=(--tls-ca "$work/certs/ca.pem")
  fi
  build/server/deformd/deformd --listen "127.0.0.1:$port" --log-level warn "${server_tls[@]}" \
    >"$work/deformd.log" 2>&1 &
  server=$!
  build/client/loadtest/deform-loadtest --target "127.0.0.1:$port" "${client_tls[@]}" \
    --mesh "$mesh" --skeleton "$skeleton" --streams "$streams" --rate 90 \
    --duration "$duration" --json >"$work/report.json"
  kill -TERM "$server"
  wait "$server" || true
  python3 - "$mode" "$streams" "$work/report.json" <<'PY'
import json, sys
mode, streams, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
r = json.load(open(path))
print(json.dumps({"mode": mode, "streams": streams, "frames_sent": r["frames_sent"],
                  "frames_received": r["frames_received"], "delivered": r["delivered_fraction"],
                  "p50_ms": r["latency_ms"]["p50"], "p99_ms": r["latency_ms"]["p99"],
                  "errors": r["errors"]}))
PY
}

for ((round = 0; round < rounds; ++round)); do
  for streams in 1 64; do
    run plaintext "$streams"
    run tls "$streams"
  done
done
