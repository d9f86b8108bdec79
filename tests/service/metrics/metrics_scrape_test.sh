#!/usr/bin/env bash
# deformd's Prometheus metrics end to end (ctest):
#   metrics_scrape_test.sh DEFORMD LOADTEST MODE VERSION [PROBE]
#   loadtest  starts a real deformd with --metrics on ports the kernel picks; its first scrape
#             carries deformd_build_info{commit,version} 1 with VERSION (CMake's) and the commit
#             this checkout is at (tests/expected_commit.sh). Then it runs deform-loadtest
#             (--json, no warm-up, so it counts every frame) and scrapes /metrics while it runs
#             (frames are counted live) and after: deformd_frames_sent_total is the loadtest's
#             frames_received, and its bytes are counted. Then a loadtest whose every pose names an
#             axis the knee does not have: its error count equals the server's rejected-pose
#             notices plus the Deform RPCs that did not end OK. The RPC counters see the loads.
#   auth      a deformd with a token file: a scrape without a token is 401, with a tenant's 403,
#             with an operator's 200; another path is 404, POST 405; --metrics on a non-loopback
#             address without a certificate is refused at start-up, exit 1 naming the flag.
#   promtool  after a load test (3 streams) and a health probe, `promtool check metrics` (Debian's
#             prometheus package) passes the scrape with no lint problem, and the standard
#             grpc_server_handled_total counts the calls made, with grpc_code="OK": one LoadMesh,
#             three Deform streams, one UnloadMesh, one health Check; its messages and the
#             process_* metrics are there. PROMTOOL (environment) names another promtool.
#   tls       a deformd serving gRPC over TLS: its metrics stay plain HTTP on loopback (scraped,
#             with the certificate's end of validity as a gauge; an expired one refuses to start),
#             and --metrics on a non-loopback address is refused unless --plaintext.
set -euo pipefail
DEFORMD="$1"
LOADTEST="$2"
MODE="$3"
VERSION="${4:-}"
PROBE="${5:-}"
SOURCE_DIR="$(cd "$(dirname "$0")/../../.." && pwd)"
# shellcheck source=tests/expected_commit.sh
source "$SOURCE_DIR/tests/expected_commit.sh"
# shellcheck source=scripts/deformd-process.sh
source "$SOURCE_DIR/scripts/deformd-process.sh"
deformd_make_work
fail() {
  echo "FAIL: $*" >&2
  [ -f "$WORK/deformd.log" ] && tail -20 "$WORK/deformd.log" >&2
  exit 1
}

start_server() {  # extra deformd flags...
  deformd_start "$WORK/deformd.log" "$DEFORMD" --listen 127.0.0.1:0 --metrics 127.0.0.1:0 \
    --workers 2 "$@" || fail "deformd did not start"
  GRPC="$DEFORMD_ADDRESS"
  METRICS=$(sed -n 's/.*metrics on \(https\{0,1\}:[^ ]*\).*/\1/p' "$WORK/deformd.log" | head -1)
  [ -n "$METRICS" ] || fail "no metrics line"
}

# The value of one series ("name{labels}" exactly as exposed), 0 when absent.
series() {  # file, series
  awk -v s="$2" '$1 == s { v = $2 } END { printf "%d\n", (v == "" ? 0 : v) }' "$1"
}

json_field() {  # file, python expression on `r`
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print($2)" "$1"
}

case "$MODE" in
loadtest)
  start_server
  curl -sf "$METRICS" >"$WORK/before.txt" || fail "scrape before the load test"
  [ -n "$VERSION" ] || fail "no VERSION given"
  build_info="deformd_build_info{commit=\"$(expected_commit "$SOURCE_DIR")\",version=\"$VERSION\"}"
  [ "$(series "$WORK/before.txt" "$build_info")" -eq 1 ] ||
    fail "no '$build_info 1' in the scrape: $(grep '^deformd_build_info' "$WORK/before.txt")"
  [ "$(series "$WORK/before.txt" 'deformd_frames_sent_total{encoding="float32"}')" -eq 0 ] ||
    fail "frames counted before any stream"
  "$LOADTEST" --target "$GRPC" --streams 4 --rate 60 --duration 3 --warmup 0 --json \
    >"$WORK/run.json" &
  LOAD=$!
  sleep 2.5
  curl -sf "$METRICS" >"$WORK/during.txt" || fail "scrape during the load test"
  wait "$LOAD" || fail "deform-loadtest failed"
  curl -sf "$METRICS" >"$WORK/after.txt" || fail "scrape after the load test"
  received=$(json_field "$WORK/run.json" 'r["frames_received"]')
  during=$(series "$WORK/during.txt" 'deformd_frames_sent_total{encoding="float32"}')
  after=$(series "$WORK/after.txt" 'deformd_frames_sent_total{encoding="float32"}')
  bytes=$(series "$WORK/after.txt" 'deformd_frame_bytes_sent_total{encoding="float32"}')
  open_during=$(series "$WORK/during.txt" 'deformd_streams_open')
  streams_memory=$(series "$WORK/during.txt" 'deformd_memory_budget_streams_bytes')
  echo "loadtest frames_received=$received; server frames during=$during after=$after" \
    "bytes=$bytes; streams open during=$open_during"
  [ "$received" -gt 100 ] || fail "too few frames received ($received)"
  # The phantom carries its bones: every frame reports its constraints, and the load test counts
  # them (the skin kept outside the bones, the volume kept) and their share of the server's time.
  constrained=$(json_field "$WORK/run.json" 'r["constraints"]["frames"]')
  penetrating=$(json_field "$WORK/run.json" 'r["constraints"]["frames_penetrating"]')
  volume_kept=$(json_field "$WORK/run.json" 'int(r["constraints"]["volume_change_max_abs"] <= 1e-4)')
  constraint_ms=$(json_field "$WORK/run.json" 'int(r["server_ms_p50"]["constraints"] > 0)')
  echo "loadtest constraints: frames=$constrained penetrating=$penetrating" \
    "volume_kept=$volume_kept constraint_ms_positive=$constraint_ms"
  [ "$constrained" -eq "$received" ] || fail "$constrained of $received frames report constraints"
  [ "$penetrating" -eq 0 ] || fail "$penetrating frames left skin inside a bone"
  [ "$volume_kept" -eq 1 ] || fail "a frame's volume moved by more than its tolerance"
  [ "$constraint_ms" -eq 1 ] || fail "the constraints' share of the server's time is not counted"
  [ "$after" -eq "$received" ] || fail "server counted $after frames, the loadtest $received"
  [ "$during" -gt 0 ] && [ "$during" -lt "$after" ] || fail "frames not counted live ($during)"
  [ "$open_during" -eq 4 ] || fail "streams open during the run: $open_during, expected 4"
  [ "$streams_memory" -gt $((4 * 3 * 12 * 1900)) ] ||
    fail "the four streams' buffers are not in the budget gauge ($streams_memory bytes)"
  [ "$bytes" -gt $((after * 12 * 100)) ] || fail "frame bytes $bytes too few for $after frames"
  [ "$(series "$WORK/after.txt" 'deformd_rpcs_total{code="OK",method="LoadMesh"}')" -eq 1 ] ||
    fail "the load is not counted"
  [ "$(series "$WORK/after.txt" 'deformd_rpcs_total{code="OK",method="Deform"}')" -eq 4 ] ||
    fail "the four streams are not counted as OK"
  grep -q '^deformd_frame_server_seconds_count ' "$WORK/after.txt" || fail "no frame histogram"
  grep -q '^deformd_build_seconds_count{result="ok"} 1' "$WORK/after.txt" ||
    fail "the build is not in deformd_build_seconds"

  # Errors: every pose names an axis the knee does not have.
  "$LOADTEST" --target "$GRPC" --streams 2 --rate 30 --duration 1 --warmup 0 --json \
    --joint knee --axis no_such_axis >"$WORK/bad.json" || fail "deform-loadtest failed"
  curl -sf "$METRICS" >"$WORK/errors.txt" || fail "scrape after the failing load test"
  errors=$(json_field "$WORK/bad.json" 'r["errors"]')
  rejected=$(series "$WORK/errors.txt" 'deformd_notices_sent_total{kind="pose_rejected"}')
  stiffness=$(series "$WORK/errors.txt" 'deformd_notices_sent_total{kind="stiffness_rejected"}')
  failed=$(grep '^deformd_rpcs_total{.*method="Deform"}' "$WORK/errors.txt" |
    grep -v 'code="OK"' | awk '{ s += $2 } END { printf "%d\n", s }')
  echo "loadtest errors=$errors; server: pose_rejected=$rejected stiffness_rejected=$stiffness" \
    "Deform not OK=$failed"
  [ "$errors" -gt 0 ] || fail "the failing load test counted no error"
  [ "$errors" -eq $((rejected + stiffness + failed)) ] ||
    fail "the loadtest counted $errors errors, the server $((rejected + stiffness + failed))"
  ;;
promtool)
  PROMTOOL="${PROMTOOL:-promtool}"
  command -v "$PROMTOOL" >/dev/null ||
    fail "no $PROMTOOL: install Debian's prometheus package (scripts/packages/build.txt)"
  [ -x "$PROBE" ] || fail "no health probe given"
  start_server
  "$LOADTEST" --target "$GRPC" --streams 3 --rate 60 --duration 2 --warmup 0 --json \
    >"$WORK/run.json" || fail "deform-loadtest failed"
  "$PROBE" --target "$GRPC" >/dev/null || fail "the health probe failed"
  curl -sf "$METRICS" >"$WORK/page.txt" || fail "scrape after the load test"
  "$PROMTOOL" check metrics <"$WORK/page.txt" >"$WORK/lint.txt" 2>&1 ||
    fail "promtool check metrics: $(cat "$WORK/lint.txt")"
  [ ! -s "$WORK/lint.txt" ] || fail "promtool check metrics said: $(cat "$WORK/lint.txt")"
  handled() {  # service, method, type
    series "$WORK/page.txt" "grpc_server_handled_total{grpc_code=\"OK\",grpc_method=\"$2\",grpc_service=\"$1\",grpc_type=\"$3\"}"
  }
  labels() {  # service, method, type
    echo "{grpc_method=\"$2\",grpc_service=\"$1\",grpc_type=\"$3\"}"
  }
  svc=deform.v1.DeformService
  deform=$(labels $svc Deform bidi_stream)
  echo "grpc_server_handled_total OK: LoadMesh=$(handled $svc LoadMesh bidi_stream)" \
    "Deform=$(handled $svc Deform bidi_stream) UnloadMesh=$(handled $svc UnloadMesh unary)" \
    "Check=$(handled grpc.health.v1.Health Check unary)"
  [ "$(handled $svc LoadMesh bidi_stream)" -eq 1 ] || fail "the load is not counted"
  [ "$(handled $svc Deform bidi_stream)" -eq 3 ] || fail "the three streams are not counted"
  [ "$(handled $svc UnloadMesh unary)" -eq 1 ] || fail "the unload is not counted"
  [ "$(handled grpc.health.v1.Health Check unary)" -eq 1 ] || fail "the health check is not counted"
  [ "$(series "$WORK/page.txt" "grpc_server_started_total$deform")" -eq 3 ] ||
    fail "the three streams' starts are not counted"
  [ "$(series "$WORK/page.txt" "grpc_server_handling_seconds_count$deform")" -eq 3 ] ||
    fail "the three streams' durations are not in grpc_server_handling_seconds"
  received=$(json_field "$WORK/run.json" 'r["frames_received"]')
  poses=$(json_field "$WORK/run.json" 'r["frames_sent"]')
  sent=$(series "$WORK/page.txt" "grpc_server_msg_sent_total$deform")
  got=$(series "$WORK/page.txt" "grpc_server_msg_received_total$deform")
  echo "Deform messages: server sent $sent (loadtest received $received frames)," \
    "server received $got (loadtest sent $poses poses)"
  [ "$sent" -ge "$received" ] && [ "$received" -gt 0 ] || fail "messages sent not counted"
  [ "$got" -ge "$poses" ] && [ "$poses" -gt 0 ] || fail "messages received not counted"
  frames=$(series "$WORK/page.txt" 'deformd_frames_sent_total{encoding="float32"}')
  [ "$(series "$WORK/page.txt" deformd_frame_queue_seconds_count)" -eq "$frames" ] &&
    [ "$(series "$WORK/page.txt" deformd_frame_compute_seconds_count)" -eq "$frames" ] ||
    fail "the queue and compute histograms do not count the $frames frames"
  for name in process_cpu_seconds_total process_resident_memory_bytes \
    process_virtual_memory_bytes process_open_fds process_max_fds process_start_time_seconds; do
    grep -q "^$name [0-9]" "$WORK/page.txt" || fail "no $name"
  done
  ;;
auth)
  python3 - "$WORK/tokens" <<'PY'
import hashlib, sys
with open(sys.argv[1], "w") as f:
    for token, tenant, role in (("op-secret", "ops", "operator"), ("ward-secret", "ward", "tenant"),
                                ("scrape-secret", "prometheus", "metrics")):
        f.write(f"{hashlib.sha256(token.encode()).hexdigest()} {tenant} {role}\n")
PY
  start_server --token-file "$WORK/tokens"
  code() { curl -s -o /dev/null -w '%{http_code}' "$@"; }
  [ "$(code "$METRICS")" = 401 ] || fail "a scrape without a token is not 401"
  [ "$(code -H 'Authorization: Bearer wrong' "$METRICS")" = 401 ] || fail "bad token not 401"
  [ "$(code -H 'Authorization: Bearer ward-secret' "$METRICS")" = 403 ] ||
    fail "a tenant's token is not 403"
  [ "$(code -H 'Authorization: Bearer op-secret' "$METRICS")" = 200 ] ||
    fail "an operator's token is not 200"
  [ "$(code -H 'Authorization: Bearer scrape-secret' "$METRICS")" = 200 ] ||
    fail "a metrics token is not 200"
  curl -sf -H 'Authorization: Bearer op-secret' "$METRICS" >"$WORK/page.txt" ||
    fail "the operator's scrape failed"
  grep -q '^deformd_streams_open ' "$WORK/page.txt" || fail "the operator's page has no gauge"
  [ "$(code -H 'Authorization: Bearer op-secret' "${METRICS%/metrics}/index.html")" = 404 ] ||
    fail "another path is not 404"
  [ "$(code -X POST -H 'Authorization: Bearer op-secret' "$METRICS")" = 405 ] ||
    fail "POST is not 405"
  grep -q "metrics: scrape by tenant=ward refused" "$WORK/deformd.log" || fail "no refusal logged"
  status=0
  "$DEFORMD" --listen 127.0.0.1:0 --metrics 0.0.0.0:0 >"$WORK/refused.log" 2>&1 || status=$?
  [ "$status" -eq 1 ] || fail "plaintext metrics on 0.0.0.0 started (exit $status)"
  grep -q -- "--metrics '0.0.0.0:0' is not a loopback address" "$WORK/refused.log" ||
    fail "the refusal does not name --metrics"
  ;;
tls)
  bash "$SOURCE_DIR/scripts/make-test-certificates.sh" "$WORK/certs" >/dev/null
  start_server --tls-cert "$WORK/certs/server.pem" --tls-key "$WORK/certs/server.key"
  grep -q "listening on .*(TLS)" "$WORK/deformd.log" || fail "gRPC is not TLS"
  case "$METRICS" in http://127.0.0.1:*) ;; *) fail "metrics not on loopback HTTP: $METRICS" ;; esac
  curl -sf "$METRICS" >"$WORK/page.txt" || fail "loopback scrape failed"
  grep -q '^deformd_meshes_loaded ' "$WORK/page.txt" || fail "the page has no gauge"
  # The certificate's end of validity as Unix seconds, as openssl reads it.
  not_after=$(date -d "$(openssl x509 -in "$WORK/certs/server.pem" -noout -enddate | cut -d= -f2)" +%s)
  expiry=$(sed -n 's/^deformd_tls_certificate_expiry_seconds \(.*\)$/\1/p' "$WORK/page.txt")
  awk -v a="$expiry" -v b="$not_after" 'BEGIN { exit !(a != "" && a + 0 == b + 0) }' ||
    fail "deformd_tls_certificate_expiry_seconds is '$expiry', the certificate ends at $not_after"
  status=0
  "$DEFORMD" --listen 127.0.0.1:0 --tls-cert "$WORK/certs/expired.pem" \
    --tls-key "$WORK/certs/expired.key" >"$WORK/expired.log" 2>&1 || status=$?
  [ "$status" -eq 1 ] || fail "deformd started with an expired certificate (exit $status)"
  grep -q "expired on 2020-02-01 00:00:00 UTC.*--tls-allow-expired" "$WORK/expired.log" ||
    fail "the refusal of the expired certificate does not say when and which flag"
  status=0
  "$DEFORMD" --listen 127.0.0.1:0 --tls-cert "$WORK/certs/server.pem" \
    --tls-key "$WORK/certs/server.key" --metrics 0.0.0.0:0 >"$WORK/refused.log" 2>&1 || status=$?
  [ "$status" -eq 1 ] || fail "plain HTTP metrics on 0.0.0.0 started beside TLS (exit $status)"
  grep -q "serves plain HTTP only" "$WORK/refused.log" || fail "the refusal does not say why"
  ;;
*)
  fail "unknown mode $MODE"
  ;;
esac
echo "PASS"
