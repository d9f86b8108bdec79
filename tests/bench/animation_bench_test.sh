#!/usr/bin/env bash
# The animation benchmark end to end (ctest): animation_bench_test.sh DEFORMD BENCH MODE
#   phantom    starts a real deformd on a port the kernel picks, runs deform-animation-bench on
#              the built-in phantom with a 10-frame animation (knee flexion, a hip swing and root
#              motion), and checks: exit 0, every frame measured, rigid-zone error below 1e-3 on
#              every frame, the JSON parses, LBS measured beside the method.
#   gltf       the same through a skinned glTF rig split at seams (WRITER, the 4th argument,
#              writes it): frames come in the file's vertex order, more vertices than the solve's;
#              the same checks, and that the frames were mapped (frame vertices > solved).
#   gltf_animation  the glTF rig's own animation (--animation, ANIMATED the 4th argument: a chain
#              with a STEP, a LINEAR and a CUBICSPLINE channel): 5 frames at 4 fps, each with its
#              time, the JSON naming the animation; an unknown animation is exit code 2.
#   malformed  an animation with a malformed line, and one with an unknown joint: exit code 2 and
#              a stderr line naming the line number (checked before any server is contacted).
set -euo pipefail
# shellcheck source=scripts/deformd-process.sh
source "$(dirname "$0")/../../scripts/deformd-process.sh"
DEFORMD="$1"
BENCH="$2"
MODE="$3"
WRITER="${4:-}"
deformd_make_work
fail() { echo "FAIL: $*" >&2; exit 1; }

expect_usage_error() {  # animation-file, line number expected in the message
  local code=0
  "$BENCH" --target 127.0.0.1:1 --connect-timeout-ms 200 --poses "$1" \
    >"$WORK/out.txt" 2>"$WORK/err.txt" || code=$?
  cat "$WORK/err.txt"
  [ "$code" -eq 2 ] || fail "exit code $code for $1, expected 2"
  grep -q "line $2:" "$WORK/err.txt" || fail "stderr does not name line $2"
  [ "$(wc -l <"$WORK/err.txt")" -eq 1 ] || fail "expected one stderr line"
}

if [ "$MODE" = malformed ]; then
  printf '# a knee bend\nknee:flexion:10\n\nknee:flexion:ten\nknee:flexion:30\n' >"$WORK/bad.txt"
  expect_usage_error "$WORK/bad.txt" 4
  printf 'knee:flexion:10\nknee:flexion:20;root=0,0,0,1,0\n' >"$WORK/bad_root.txt"
  expect_usage_error "$WORK/bad_root.txt" 2
  printf 'knee:flexion:10\nknee:flexion:20\nelbow:x:30\n' >"$WORK/unknown_joint.txt"
  expect_usage_error "$WORK/unknown_joint.txt" 3
  echo "PASS"
  exit 0
fi

if [ "$MODE" = gltf_animation ]; then
  deformd_start "$WORK/deformd.log" "$DEFORMD" --listen 127.0.0.1:0 --log-level info ||
    fail "deformd did not start: $(cat "$WORK/deformd.log")"
  "$BENCH" --target "$DEFORMD_ADDRESS" --mesh "$WRITER" --animation bend --fps 4 --json \
    >"$WORK/report.json" || fail "the animation did not play"
  python3 - "$WORK/report.json" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
assert report["frames"] == 5, report["frames"]
assert report["animation"].startswith("bend (index 0"), report["animation"]
assert report["per_frame"]["time_s"] == [0, 0.25, 0.5, 0.75, 1.0], report["per_frame"]["time_s"]
assert abs(report["per_frame"]["lbs_volume_change"][4]) > 1e-2, report["per_frame"]
PY
  code=0
  "$BENCH" --target "$DEFORMD_ADDRESS" --mesh "$WRITER" --animation run 2>"$WORK/err.txt" || code=$?
  [ "$code" -eq 2 ] || fail "exit code $code for an unknown animation, expected 2"
  grep -q "no animation 'run'" "$WORK/err.txt" || fail "stderr does not name the animation"
  echo "PASS"
  exit 0
fi

case "$MODE" in
  phantom) SOURCE=(); KNEE="knee:flexion" ;;
  gltf)
    "$WRITER" "$WORK/split.glb" || fail "cannot write the rig"
    SOURCE=(--mesh "$WORK/split.glb")
    KNEE="knee:x"  # a glTF rig's joints have no named degrees of freedom
    ;;
  *) fail "unknown mode '$MODE'" ;;
esac
deformd_start "$WORK/deformd.log" "$DEFORMD" --listen 127.0.0.1:0 --log-level info ||
  fail "deformd did not start: $(cat "$WORK/deformd.log")"

{
  echo "# 10 frames: the knee 0 -> 120 -> 0 while the hip swings and the body moves forward"
  for k in 0 1 2 3 4 5 6 7 8 9; do
    knee=$(( k <= 5 ? k * 24 : (10 - k) * 24 ))
    echo "$KNEE:$knee, hip:x:$(( k - 5 )) ;root=0,0.$k,$k,0,1,0,$(( k * 2 ))"
  done
} >"$WORK/walk.txt"

code=0
"$BENCH" --target "$DEFORMD_ADDRESS" "${SOURCE[@]}" --poses "$WORK/walk.txt" --json \
  >"$WORK/report.json" 2>"$WORK/err.txt" || code=$?
cat "$WORK/err.txt" >&2
[ "$code" -eq 0 ] || fail "exit code $code"
python3 - "$WORK/report.json" "$MODE" <<'PY'
import json, math, sys
report = json.load(open(sys.argv[1]))
if sys.argv[2] == "gltf":
    assert report["frame_vertices"] > report["solved_vertices"], report
    assert report["binding"] == "given weights", report["binding"]
else:
    assert report["frame_vertices"] == report["solved_vertices"], report
frames = report["per_frame"]
assert report["frames"] == 10, report["frames"]
for key in ("volume_change", "lbs_volume_change", "clearance_min", "lbs_clearance_min",
            "rigid_zone_error", "latency_ms"):
    values = frames[key]
    assert len(values) == 10, (key, len(values))
    assert all(math.isfinite(v) for v in values), (key, values)
assert frames["frame"] == list(range(10)), frames["frame"]
assert max(frames["rigid_zone_error"]) < 1e-3, frames["rigid_zone_error"]
assert all(v > 0 for v in frames["latency_ms"]), frames["latency_ms"]
# The rest frame keeps the volume; the bent ones do not, for the method nor for LBS.
assert abs(frames["volume_change"][0]) < 1e-4, frames["volume_change"][0]
assert abs(frames["lbs_volume_change"][5]) > 1e-3, frames["lbs_volume_change"][5]
assert report["rigid_vertices"] > 0
assert len(report["worst_frames"]["volume_change"]) == 5
assert report["summary"]["rigid_zone_error"]["worst"] == max(frames["rigid_zone_error"])
print("PASS: 10 frames, rigid-zone error at most %.2e" % max(frames["rigid_zone_error"]))
PY
