#!/usr/bin/env bash
# Prints a markdown table of the quality measures of all five methods (paper, its linear-blend
# fast path paper-linear, laplacian, lbs, dqs) at 45, 90 and 120 degrees of flexion, for the built-in phantom and, where ../shared/data
# is present, the shared leg and arm. Needs a build (scripts/build.sh) and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
DEFORMCTL="${DEFORM_BUILD_DIR:-build}/server/deformctl/deformctl"
DATA="${DEFORM_SHARED_DATA:-../shared/data}"

# name | mesh | skeleton | joint:axis | sign of the angle
CASES=("phantom_2k|||knee:flexion|1")
for mesh in leg_1633 leg_25969; do
  [ -f "$DATA/leg/$mesh.obj" ] && CASES+=("$mesh|$DATA/leg/$mesh.obj|$DATA/leg/leg.tgf|1:x|1")
done
[ -f "$DATA/arm/arm_132946.obj" ] && CASES+=("arm_132946|$DATA/arm/arm_132946.obj|$DATA/arm/arm.tgf|2:z|-1")

echo "| mesh | degrees | method | volume_change | clearance_min | clearance_p01 | sink_fraction | rigid_zone_error |"
echo "|---|---|---|---|---|---|---|---|"
for case in "${CASES[@]}"; do
  IFS='|' read -r name mesh skeleton joint sign <<<"$case"
  args=()
  [ -n "$mesh" ] && args=(--mesh "$mesh" --skeleton "$skeleton")
  for degrees in 45 90 120; do
    angle=$((degrees * sign))
    for method in paper paper-linear laplacian lbs dqs; do
      "$DEFORMCTL" deform "${args[@]}" --pose "$joint:$angle" --method "$method" |
        python3 -c "import json,sys; d=json.load(sys.stdin); print('| $name | $degrees | $method | %+.4f | %.3f | %.3f | %.4f | %.1e |' % (d['volume_change'], d['clearance_min'], d['clearance_p01'], d['sink_fraction'], d['rigid_zone_error']))"
    done
  done
done
