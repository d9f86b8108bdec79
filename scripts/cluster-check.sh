#!/usr/bin/env bash
# The cluster check (docs/cluster.md, "How far it was tested"): three deformd replicas on loopback
# ports sharing one store directory (--store-shared, one --store-key), HAProxy in front with the
# shipped configuration (docker/cluster/haproxy.cfg), and deform-loadtest clients through it:
#
#   1. Content keys: the 26k leg loaded twice through the balancer gets the same key, the second
#      time without a rebuild (its connect-and-load time is printed).
#   2. Routing: 64 streams over 4 meshes at 90 Hz for 10 s; every mesh's streams are on one
#      replica (each replica's deformd_mesh_streams_open{mesh}). Then 13 streams over the same
#      meshes, connected to their replicas directly and through the balancer in alternating
#      rounds (three each): the balancer adds at most 0.5 ms to the median latency (the median
#      over the rounds) of each mesh whose frames take less than 5 ms (the 26k leg's figure is
#      printed, not gated); the added p99 is printed (on a 2-core machine that also runs the replicas and the clients it is scheduling
#      noise, docs/cluster.md).
#   3. SIGKILL of the replica holding the 26k leg during a run: every one of its streams gets
#      frames again (from another replica, which builds the mesh from the store) within 3 s, with
#      no error; the other meshes' streams do not reconnect, miss no frame beyond the noise (their
#      largest gap at most 100 ms over the balanced run's), and see no error.
#   4. SIGTERM of a replica that holds streams (--drain-delay-ms): its streams move to the last
#      replica with no error, and it exits 0.
#
# Usage: scripts/cluster-check.sh [BUILD_DIR]   (default build/, built already; needs
# DEFORM_SHARED_DATA or ../shared/data for the legs). Exits 1 naming the failed check.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
DATA="${DEFORM_SHARED_DATA:-../shared/data}"
scripts/install-deps.sh scripts/packages/checks.txt >/dev/null
DEFORMD="$BUILD/server/deformd/deformd"
LOADTEST="$BUILD/client/loadtest/deform-loadtest"
for binary in "$DEFORMD" "$LOADTEST"; do
  [ -x "$binary" ] || { echo "cluster-check: $binary is missing (build first)" >&2; exit 1; }
done
LEG_SMALL="$DATA/leg/leg_1633.obj"
LEG_LARGE="$DATA/leg/leg_25969.obj"
LEG_SKELETON="$DATA/leg/leg.tgf"
for file in "$LEG_SMALL" "$LEG_LARGE" "$LEG_SKELETON"; do
  [ -f "$file" ] || { echo "cluster-check: $file is missing (set DEFORM_SHARED_DATA)" >&2; exit 1; }
done

WORK="$(mktemp -d)"
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if [ -n "${CLUSTER_CHECK_KEEP:-}" ]; then echo "cluster-check: kept $WORK" >&2; else rm -rf "$WORK"; fi
}
trap cleanup EXIT
fail() {
  echo "cluster-check: FAILED: $*" >&2
  for log in "$WORK"/*.log; do echo "--- $log (last lines)" >&2; tail -n 15 "$log" >&2; done
  exit 1
}

# Free loopback ports: 3 replicas x (gRPC, metrics), the balancer, its stats page.
read -r -a PORTS <<<"$(python3 - <<'EOF'
import socket
socks = []
for _ in range(8):
    s = socket.socket(); s.bind(("127.0.0.1", 0)); socks.append(s)
print(" ".join(str(s.getsockname()[1]) for s in socks))
EOF
)"
GRPC=("${PORTS[0]}" "${PORTS[1]}" "${PORTS[2]}")
METRICS=("${PORTS[3]}" "${PORTS[4]}" "${PORTS[5]}")
LB="127.0.0.1:${PORTS[6]}"
STATS="127.0.0.1:${PORTS[7]}"
REPLICA_PID=()

start_replica() {  # INDEX
  local i=$1
  "$DEFORMD" --listen "127.0.0.1:${GRPC[$i]}" --metrics "127.0.0.1:${METRICS[$i]}" \
    --store "$WORK/store" --store-shared --store-key "$WORK/store.key" \
    --drain-delay-ms 1500 --shutdown-grace-s 8 --log-level info >"$WORK/replica$((i + 1)).log" 2>&1 &
  REPLICA_PID[$i]=$!
  PIDS+=("$!")
  for _ in $(seq 1 300); do
    grep -q "listening on" "$WORK/replica$((i + 1)).log" && return 0
    kill -0 "${REPLICA_PID[$i]}" 2>/dev/null || fail "replica $((i + 1)) exited at start-up"
    sleep 0.1
  done
  fail "replica $((i + 1)) did not listen within 30 s"
}
for i in 0 1 2; do start_replica "$i"; done

DEFORM_LB_BIND="$LB" DEFORM_LB_STATS="$STATS" DEFORM_REPLICA_1="127.0.0.1:${GRPC[0]}" \
  DEFORM_REPLICA_2="127.0.0.1:${GRPC[1]}" DEFORM_REPLICA_3="127.0.0.1:${GRPC[2]}" \
  haproxy -db -f docker/cluster/haproxy.cfg >"$WORK/haproxy.log" 2>&1 &
PIDS+=("$!")
replicas_up() { curl -fsS "http://$STATS/stats;csv" 2>/dev/null | grep -c '^replicas,replica[0-9],.*,UP' || true; }
for _ in $(seq 1 100); do [ "$(replicas_up)" = 3 ] && break; sleep 0.1; done
[ "$(replicas_up)" = 3 ] || fail "HAProxy does not see the three replicas UP (gRPC health)"
echo "cluster-check: 3 replicas and HAProxy up (balancer $LB)"

# The streams of each mesh: the 26k leg's few (one 2-core machine holds about 8 of them in all).
MESH_NAMES=(leg1633 leg25969 phantom800 phantom500)
MESH_FLAGS=("--mesh $LEG_SMALL --skeleton $LEG_SKELETON" "--mesh $LEG_LARGE --skeleton $LEG_SKELETON"
            "--phantom-vertices 800" "--phantom-vertices 500")
MESH_STREAMS=(21 2 21 20)
LIGHT_STREAMS=(4 1 4 4)
declare -A KEY

loadtest() {  # OUT TARGET MESH-FLAGS... ; runs deform-loadtest --json into OUT
  local out=$1 target=$2
  shift 2
  # shellcheck disable=SC2068
  "$LOADTEST" --target "$target" --json "$@" >"$out" 2>>"$WORK/loadtest.log"
}
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))$2)" "$1"; }

# 1. Content keys: load each mesh through the balancer (and the 26k leg twice).
for m in 0 1 2 3; do
  # shellcheck disable=SC2086
  loadtest "$WORK/load-$m.json" "$LB" ${MESH_FLAGS[$m]} --keep-mesh --streams 1 --duration 0.2 \
    --warmup 0.2 || fail "loading ${MESH_NAMES[$m]} through the balancer"
  KEY[$m]="$(field "$WORK/load-$m.json" "['mesh_id']")"
done
# shellcheck disable=SC2086
loadtest "$WORK/load-again.json" "$LB" ${MESH_FLAGS[1]} --keep-mesh --streams 1 --duration 0.2 \
  --warmup 0.2 || fail "loading the 26k leg again"
[ "$(field "$WORK/load-again.json" "['mesh_id']")" = "${KEY[1]}" ] ||
  fail "the 26k leg loaded again got another key"
echo "cluster-check: the 26k leg loaded twice: the same key ${KEY[1]}; connect and load" \
  "$(field "$WORK/load-1.json" "['acquire_ms']") ms the first time," \
  "$(field "$WORK/load-again.json" "['acquire_ms']") ms the second (no rebuild)"
grep -q "mesh=${KEY[1]} is loaded already" "$WORK"/replica*.log ||
  fail "the second load of the 26k leg was not answered from the loaded mesh"

# Which replica holds each mesh's streams, from their metrics (sampled mid-run).
holder_of() {  # KEY -> "INDEX STREAMS" of every replica with streams of it
  local key=$1 i
  for i in 0 1 2; do
    kill -0 "${REPLICA_PID[$i]}" 2>/dev/null || continue
    curl -fsS "http://127.0.0.1:${METRICS[$i]}/metrics" 2>/dev/null |
      awk -v k="$key" -v i="$i" '$1 == "deformd_mesh_streams_open{mesh=\"" k "\"}" && $2 > 0 { print i, $2 }'
  done
}

run_all() {  # TAG DIRECT(0|1) DURATION [EXTRA...]: the 4 meshes' loadtests at once
  local tag=$1 direct=$2 duration=$3 m target
  shift 3
  local -n streams=${STREAMS_OF:-MESH_STREAMS}
  local pids=()
  for m in 0 1 2 3; do
    target="$LB"
    [ "$direct" = 1 ] && target="127.0.0.1:${GRPC[${HOLDER[$m]}]}"
    loadtest "$WORK/$tag-$m.json" "$target" --mesh-id "${KEY[$m]}" --streams "${streams[$m]}" \
      --rate 90 --duration "$duration" --warmup 1 --encoding quantized "$@" &
    pids+=("$!")
  done
  RUN_PIDS=("${pids[@]}")
}
wait_all() {
  local pid status=0
  for pid in "${RUN_PIDS[@]}"; do wait "$pid" || status=1; done
  return $status
}

# 2. Routing, then the balancer's cost against direct connections, in alternating rounds.
declare -A HOLDER
run_all routed 0 10 --reconnect
sleep 6
for m in 0 1 2 3; do
  holders="$(holder_of "${KEY[$m]}")"
  [ "$(wc -l <<<"$holders")" = 1 ] && [ -n "$holders" ] ||
    fail "${MESH_NAMES[$m]}'s streams are on several replicas (or none): $holders"
  read -r index streams <<<"$holders"
  [ "${streams%.*}" = "${MESH_STREAMS[$m]}" ] ||
    fail "${MESH_NAMES[$m]}: ${streams} of ${MESH_STREAMS[$m]} streams on replica $((index + 1))"
  HOLDER[$m]=$index
  echo "cluster-check: ${MESH_NAMES[$m]} (${KEY[$m]}): all ${MESH_STREAMS[$m]} streams on replica $((index + 1))"
done
wait_all || fail "a balanced run failed"
# The comparison at a load the machine holds besides the balancer (64 streams at 90 Hz are more
# than 2 cores solve, relay and decode together: every latency is then a queue).
STREAMS_OF=LIGHT_STREAMS
for round in 1 2 3; do
  run_all "direct-$round" 1 10 --reconnect
  wait_all || fail "a direct run failed"
  run_all "balanced-$round" 0 10 --reconnect
  wait_all || fail "a balanced run failed"
done
STREAMS_OF=MESH_STREAMS
python3 - "$WORK" <<'EOF' || fail "the balancer adds more than 0.5 ms to the median, or a run had errors"
import json, statistics, sys
work = sys.argv[1]
names = ["leg1633", "leg25969", "phantom800", "phantom500"]
ok = True
for m, name in enumerate(names):
    added = {"p50": [], "p99": []}
    direct_p50 = []
    for r in (1, 2, 3):
        lb = json.load(open(f"{work}/balanced-{r}-{m}.json"))
        direct = json.load(open(f"{work}/direct-{r}-{m}.json"))
        for run in (lb, direct):
            if run["errors"] or run["reconnects"]:
                sys.exit(f"{name}: errors {run['errors_by_code']} reconnects {run['reconnects']}")
        for q in added:
            added[q].append(lb["latency_ms"][q] - direct["latency_ms"][q])
        direct_p50.append(direct["latency_ms"]["p50"])
        print(f"cluster-check: {name} round {r}: p50 {lb['latency_ms']['p50']:.3f} / p99 "
              f"{lb['latency_ms']['p99']:.3f} ms via the balancer, p50 {direct['latency_ms']['p50']:.3f}"
              f" / p99 {direct['latency_ms']['p99']:.3f} ms direct")
    p50, p99 = (statistics.median(added[q]) for q in ("p50", "p99"))
    # A mesh whose frames take several ms to solve, encode and decode (the 26k leg) differs by more
    # than a millisecond between rounds alone on 2 shared cores: its figure is printed, not gated.
    gated = statistics.median(direct_p50) < 5
    print(f"cluster-check: {name}: the balancer adds {p50:.3f} ms to the median"
          f"{' (at most 0.5)' if gated else ' (not gated)'} and {p99:.3f} ms to the p99 "
          "(medians of the rounds)")
    ok = ok and (not gated or p50 <= 0.5)
sys.exit(0 if ok else 1)
EOF
BASE_GAP="$(python3 -c "
import json,sys
print(max(json.load(open(f'$WORK/routed-{m}.json'))['max_gap_ms'] for m in (0,2,3)))")"

# 3. SIGKILL of the replica holding the 26k leg, 4 s into a 12 s run.
victim=${HOLDER[1]}
run_all failover 0 12 --reconnect
sleep 5
kill -KILL "${REPLICA_PID[$victim]}"
echo "cluster-check: SIGKILL of replica $((victim + 1)) (the 26k leg's)"
wait_all || fail "a run failed across the SIGKILL"
python3 - "$WORK" "$victim" "$BASE_GAP" "${HOLDER[0]} ${HOLDER[1]} ${HOLDER[2]} ${HOLDER[3]}" <<'EOF' || fail "failover"
import json, sys
work, victim, base_gap = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
holders = [int(h) for h in sys.argv[4].split()]
names = ["leg1633", "leg25969", "phantom800", "phantom500"]
ok = True
for m, name in enumerate(names):
    run = json.load(open(f"{work}/failover-{m}.json"))
    moved = holders[m] == victim
    gap, reconnects, errors = run["max_gap_ms"], run["reconnects"], run["errors"]
    print(f"cluster-check: {name} ({'on the killed replica' if moved else 'elsewhere'}): "
          f"largest gap {gap:.0f} ms, {reconnects} reconnects of {run['streams']} streams, "
          f"errors {run['errors_by_code']}, delivered {run['delivered_fraction']:.4f}")
    if errors:
        ok = False
    if moved and (reconnects < run["streams"] or gap > 3000):
        print(f"cluster-check: {name}: every stream must reconnect and resume within 3 s")
        ok = False
    if not moved and (reconnects or gap > base_gap + 100):
        print(f"cluster-check: {name}: must not reconnect nor miss frames (gap over {base_gap + 100:.0f} ms)")
        ok = False
sys.exit(0 if ok else 1)
EOF

# 4. SIGTERM of a surviving replica that holds streams: they move, with no error.
for m in 0 1 2 3; do HOLDER[$m]=$(holder_of "${KEY[$m]}" | cut -d' ' -f1); done
run_all drain 0 8 --reconnect
sleep 3
drained=""
for m in 0 1 2 3; do
  h=$(holder_of "${KEY[$m]}" | head -n 1 | cut -d' ' -f1)
  [ -n "$h" ] && [ "$h" != "$victim" ] && { drained=$h; break; }
done
[ -n "$drained" ] || fail "no surviving replica holds streams"
kill -TERM "${REPLICA_PID[$drained]}"
echo "cluster-check: SIGTERM of replica $((drained + 1))"
wait_all || fail "a run failed across the SIGTERM"
drain_status=0
wait "${REPLICA_PID[$drained]}" || drain_status=$?
[ "$drain_status" = 0 ] || fail "the drained replica exited $drain_status"
python3 - "$WORK" <<'EOF' || fail "a stream of the drained replica saw an error"
import json, sys
bad = False
for m, name in enumerate(["leg1633", "leg25969", "phantom800", "phantom500"]):
    run = json.load(open(f"{sys.argv[1]}/drain-{m}.json"))
    print(f"cluster-check: drain: {name}: largest gap {run['max_gap_ms']:.0f} ms, "
          f"{run['reconnects']} reconnects, errors {run['errors_by_code']}")
    bad = bad or run["errors"] > 0
sys.exit(1 if bad else 0)
EOF
echo "cluster-check: passed"
