#!/usr/bin/env bash
# The animation benchmark: builds what is missing, starts deformd on a free port (the kernel
# picks it; never 50051), streams an animation through it with deform-animation-bench and stops
# the server. Every frame is measured against the same model built locally: volume change and
# skin-to-bone clearance beside linear blend skinning's, the rigid zones' distance from that LBS,
# round-trip latency; per frame and in summary.
#
#   scripts/animation-benchmark.sh [--rotation-blend quaternion|linear] [--json] [--poses FILE]
#                                  [--mesh FILE [--skeleton FILE] [--weights FILE]]
#                                  [--save-animation FILE] [other deform-animation-bench flags]
#
# Without --poses it generates the animation: on the shared body (../shared/data/body, or
# $DEFORM_SHARED_DATA/body) a scripted walk, two gait cycles of 60 frames (hips +-25 degrees in
# antiphase, knees 5 to 60 degrees in the swing phase, arms swinging +-15 degrees against the
# legs, elbows 10 to 30, the root moving forward with a small vertical bob and a +-2 degree yaw);
# without the shared data, a knee flexion cycle of the built-in phantom (0 -> 120 -> 0 degrees,
# 60 frames). --save-animation writes the generated animation to FILE. With --mesh, --poses is
# required (the joints are the rig's).
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/deformd-process.sh
source scripts/deformd-process.sh
BIN="${DEFORM_BUILD_DIR:-build}"
SHARED="${DEFORM_SHARED_DATA:-../shared/data}"

POSES=""
SAVE=""
MESH=()
PASS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --poses) POSES="$2"; shift 2 ;;
    --save-animation) SAVE="$2"; shift 2 ;;
    --mesh | --skeleton | --weights) MESH+=("$1" "$2"); shift 2 ;;
    *) PASS+=("$1"); shift ;;
  esac
done

deformd_make_work

# The walk on the shared body's TGF skeleton (joints joint0..joint69): joint4 / joint9 the left /
# right hip (flexion is a negative x rotation), joint5 / joint10 the knees (flexion positive x),
# joint18 / joint20 the shoulders and joint21 / joint24 the elbows (forward swing and flexion are
# negative x rotations). The body stands in decimetres, Y up, facing +Z; legs about 8 long, so
# a step of 2 * 8 * sin(25 deg) = 6.8 and a gait cycle of two steps 13.5 forward.
generate_walk() {
  awk 'BEGIN {
    pi = 3.14159265358979; frames_per_cycle = 60; cycles = 2; stride = 13.5; bob = 0.1;
    print "# a walk on the shared body: two gait cycles of 60 frames";
    for (k = 0; k < frames_per_cycle * cycles; ++k) {
      p = 2 * pi * k / frames_per_cycle;
      s = sin(p); c = cos(p);
      left_knee = 5 + (c > 0 ? 55 * c * c : 0);    # swing phase of the left leg: cos(p) > 0
      right_knee = 5 + (c < 0 ? 55 * c * c : 0);
      printf "joint4:x:%.3f,joint9:x:%.3f,joint5:x:%.3f,joint10:x:%.3f,", -25 * s, 25 * s, left_knee, right_knee;
      printf "joint18:x:%.3f,joint20:x:%.3f,joint21:x:%.3f,joint24:x:%.3f", 15 * s, -15 * s, -(20 - 10 * s), -(20 + 10 * s);
      printf ";root=0,%.4f,%.4f,0,1,0,%.3f\n", bob * cos(2 * p), stride * k / frames_per_cycle, 2 * s;
    }
  }'
}

generate_knee_cycle() {
  awk 'BEGIN {
    pi = 3.14159265358979;
    print "# the phantom knee: 0 -> 120 -> 0 degrees of flexion in 60 frames";
    for (k = 0; k < 60; ++k) printf "knee:flexion:%.3f\n", 60 * (1 - cos(2 * pi * k / 60));
  }'
}

SOURCE=()
if [ ${#MESH[@]} -gt 0 ]; then
  [ -n "$POSES" ] || { echo "animation-benchmark: --mesh needs --poses (the joints are the rig's)" >&2; exit 2; }
  SOURCE=("${MESH[@]}")
elif [ -z "$POSES" ] && [ -f "$SHARED/body/body_13380.obj" ]; then
  POSES="$WORK/walk.txt"
  generate_walk >"$POSES"
  SOURCE=(--mesh "$SHARED/body/body_13380.obj" --skeleton "$SHARED/body/body.tgf")
elif [ -z "$POSES" ]; then
  echo "animation-benchmark: no shared data at $SHARED: the phantom's knee cycle" >&2
  POSES="$WORK/knee.txt"
  generate_knee_cycle >"$POSES"
fi
[ -z "$SAVE" ] || cp "$POSES" "$SAVE"

# Build output goes to stderr: stdout is the report alone (one JSON object with --json).
if [ ! -f "$BIN/CMakeCache.txt" ]; then
  scripts/build.sh >&2
else
  cmake --build "$BIN" --parallel "$(nproc)" --target deformd deform-animation-bench >&2
fi

# Port 0: the kernel picks a free port. 50051 is left to the demo and to others' servers.
start_server() {
  deformd_start "$WORK/deformd.log" "$BIN/server/deformd/deformd" --listen 127.0.0.1:0 \
    --log-level info || { cat "$WORK/deformd.log" >&2; exit 1; }
}
start_server
if [ "${DEFORMD_ADDRESS##*:}" = 50051 ]; then
  deformd_stop
  start_server
fi

"$BIN/bench/animation/deform-animation-bench" --target "$DEFORMD_ADDRESS" "${SOURCE[@]}" \
  --poses "$POSES" "${PASS[@]}"
