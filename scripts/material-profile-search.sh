#!/usr/bin/env bash
# Searches the default material profile (METHOD.md's material weights: rigid far from a joint,
# soft in its region, seam on the region's border; deformctl --material-profile RIGID,SOFT,SEAM)
# with the constraints on: for every profile of the grid, every case at 90 and 120 degrees, the
# clearance minimum and 1st percentile and the rigid-zone error. Prints a markdown table; the
# decision it fed is in docs/method.md ("Material profile"). Needs a build and python3.
# DEFORM_PROFILES="4,1,4 1,1,1" limits the grid.
set -euo pipefail
cd "$(dirname "$0")/.."
DEFORMCTL="${DEFORM_BUILD_DIR:-build}/server/deformctl/deformctl"
DATA="${DEFORM_SHARED_DATA:-../shared/data}"
CASES=("phantom_2k||||knee:flexion:DEG"
  "leg_1633|$DATA/leg/leg_1633.obj|$DATA/leg/leg.tgf||1:x:DEG"
  "leg_25969|$DATA/leg/leg_25969.obj|$DATA/leg/leg.tgf||1:x:DEG"
  "arm_8311|$DATA/arm/arm_8311.obj|$DATA/arm/arm.tgf||2:z:-DEG"
  "body_13380|$DATA/body/body_13380.obj|$DATA/body/body.tgf||joint5:x:DEG,joint4:x:-HALF,joint10:x:HALF")
PROFILES=${DEFORM_PROFILES:-1,1,1 2,1,1 4,1,1 8,1,1 2,1,2 4,1,2 4,1,4 8,1,4 8,1,8 16,1,4}
echo "| profile | mesh | deg | clearance min | p01 | rigid-zone error | inside |"
echo "|---|---|---|---|---|---|---|"
for profile in $PROFILES; do
  for case in "${CASES[@]}"; do
    IFS='|' read -r name mesh skeleton weights pose <<<"$case"
    args=()
    [ -n "$mesh" ] && args=(--mesh "$mesh" --skeleton "$skeleton" --bones capsules)
    [ -n "$weights" ] && args+=(--weights "$weights")
    for degrees in 90 120; do
      spec=${pose//DEG/$degrees}
      spec=${spec//HALF/$((degrees / 2))}
      "$DEFORMCTL" deform "${args[@]}" --pose "$spec" --method paper \
        --material-profile "$profile" 2>/dev/null |
        python3 -c "import json,sys; d=json.load(sys.stdin); print('| $profile | $name | $degrees | %.3f | %.3f | %.1e | %d |' % (d['clearance_min'], d['clearance_p01'], d['rigid_zone_error'], d['bone_penetration']['vertices']))"
    done
  done
done
