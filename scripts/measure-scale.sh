#!/usr/bin/env bash
# Issue "scale" figures: deform-loadtest (the default quaternion blend, float32 frames, 90 Hz,
# loopback, server and load test on the same cores) against this build's deformd and, when given,
# a baseline deformd (another checkout's build, e.g. the main before a change), the two started
# one after the other in the same run, each scenario ROUNDS times:
#   leg_1633 x 128 streams, leg_25969 x 8 streams, arm_132946 x 1 stream, leg_1633 x 1 stream.
# Prints one JSON line per run (server, scenario, frames per second, delivered fraction,
# p50/p99 latency, the server's share of the p50, the constraints' median share, the frames that
# left skin inside a bone, the most contacts a frame held, the largest |volume change|) and needs
# a Release build in build/.
#
#   scripts/measure-scale.sh [BASELINE_DEFORMD] [ROUNDS] [DURATION_S]   (default: none, 1, 10)
#
# DEFORM_SCALE_ONLY=REGEX runs only the scenarios whose "mesh skeleton streams" line matches it
# (e.g. arm_132946). DEFORM_SCALE_BONES=capsules loads each mesh with bone surfaces, one capsule
# per bone by the sizing rule (deformctl --bones capsules --out-bones, at rest), so that every
# frame keeps the skin outside them as well as keeping the volume; the JSON lines then say
# "bones": "capsules".
#
# Uses ports 52000-52999 (random).
set -euo pipefail
cd "$(dirname "$0")/.."
baseline=${1:-}
rounds=${2:-1}
duration=${3:-10}
data=${DEFORM_SHARED_DATA:-../shared/data}
for f in leg/leg_1633.obj leg/leg_25969.obj leg/leg.tgf arm/arm_132946.obj arm/arm.tgf; do
  [[ -f $data/$f ]] || { echo "measure-scale: $data/$f missing" >&2; exit 1; }
done
bones=${DEFORM_SCALE_BONES:-none}
[[ $bones == none || $bones == capsules ]] ||
  { echo "measure-scale: DEFORM_SCALE_BONES must be none or capsules" >&2; exit 2; }
work=$(mktemp -d)
trap 'kill "${server:-}" 2>/dev/null || true; rm -rf "$work"' EXIT
port=$((52000 + RANDOM % 1000))

# The --bone-surface flags for mesh $1 with skeleton $2: none, or its capsules (written once).
bone_flags() {
  [[ $bones == capsules ]] || return 0
  local dir
  dir="$work/bones/$(basename "$1" .obj)"
  if [[ ! -d $dir ]]; then
    mkdir -p "$dir"
    build/server/deformctl/deformctl deform --mesh "$1" --skeleton "$2" --bones capsules \
      --out-bones "$dir" >/dev/null
  fi
  local f
  for f in "$dir"/*.obj; do printf -- '--bone-surface\n%s:%s\n' "$f" "$(basename "$f" .obj)"; done
}

run() {  # label deformd mesh skeleton streams
  local label=$1 deformd=$2 mesh=$3 skeleton=$4 streams=$5
  local flags=()
  mapfile -t flags < <(bone_flags "$mesh" "$skeleton")
  "$deformd" --listen "127.0.0.1:$port" --log-level warn >"$work/deformd.log" 2>&1 &
  server=$!
  for _ in $(seq 100); do
    build/client/probe/deform-health-probe --target "127.0.0.1:$port" >/dev/null 2>&1 && break
    sleep 0.1
  done
  build/client/loadtest/deform-loadtest --target "127.0.0.1:$port" --mesh "$mesh" \
    --skeleton "$skeleton" "${flags[@]}" --streams "$streams" --rate 90 --duration "$duration" --json \
    >"$work/run.json" 2>"$work/run.err" || { cat "$work/run.err" >&2; }
  kill "$server"; wait "$server" 2>/dev/null || true
  python3 - "$label" "$(basename "$mesh" .obj)" "$streams" "$work/run.json" "$bones" <<'PY'
import json, sys
label, mesh, streams, path, bones = sys.argv[1:]
d = json.load(open(path))
l = d["latency_ms"]
print(json.dumps({"server": label, "mesh": mesh, "streams": int(streams), "bones": bones,
                  "fps": d["throughput_fps"], "delivered": d["delivered_fraction"],
                  "p50_ms": l["p50"], "p99_ms": l["p99"],
                  "server_p50_ms": d["server_total_ms"]["p50"],
                  "constraint_p50_ms": d["server_ms_p50"]["constraints"],
                  "frames_penetrating": d["constraints"]["frames_penetrating"],
                  "contacts_max": d["constraints"]["contacts_max"],
                  "volume_change_max_abs": d["constraints"]["volume_change_max_abs"]}))
PY
}

for round in $(seq "$rounds"); do
  for scenario in "leg/leg_1633.obj leg/leg.tgf 128" "leg/leg_25969.obj leg/leg.tgf 8" \
                  "arm/arm_132946.obj arm/arm.tgf 1" "leg/leg_1633.obj leg/leg.tgf 1"; do
    [[ $scenario =~ ${DEFORM_SCALE_ONLY:-.} ]] || continue
    read -r mesh skeleton streams <<<"$scenario"
    if [[ -n $baseline ]]; then run baseline "$baseline" "$data/$mesh" "$data/$skeleton" "$streams"; fi
    run current build/server/deformd/deformd "$data/$mesh" "$data/$skeleton" "$streams"
  done
done
