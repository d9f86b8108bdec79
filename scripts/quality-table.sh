#!/usr/bin/env bash
# Prints a markdown table of the quality measures of all seven methods (paper, its linear-blend
# fast path paper-linear, laplacian, lbs, dqs, cor, ddm) at 45, 90 and 120 degrees, for the built-in
# phantom and, where ../shared/data is present, the shared legs, the arm (its natural elbow
# flexion, a negative angle; with the binding through the body and with its authored weights) and
# the whole body (a multi-joint pose: left knee DEG, left hip flexed DEG/2, right knee DEG/2).
# Needs a build (scripts/build.sh) and python3. DEFORM_QUALITY_METHODS="paper-linear lbs" limits
# the methods, DEFORM_QUALITY_DEGREES="90 120" the angles.
#
# Every case has bone surfaces: the phantom its femur, tibia and patella, the shared meshes one
# capsule per bone by MakeCapsuleBoneSurfaces' sizing rule (deformctl --bones capsules), and
# bone_inside counts the skin vertices inside one. paper and paper-linear keep the skin outside
# them and keep the volume (deformctl --contacts, --volume); DEFORM_QUALITY_CONSTRAINTS=off
# measures them without.
#
# DEFORM_QUALITY_ABLATION=1 prints the ablation of METHOD.md's two additions instead (the paper's
# figure 2): the paper's model plain (neither), with the joint node only, with the material
# weights only, and with both, on every case at 90 and 120 degrees (deformctl's --joint-nodes and
# --material switches).
set -euo pipefail
cd "$(dirname "$0")/.."
DEFORMCTL="${DEFORM_BUILD_DIR:-build}/server/deformctl/deformctl"
DATA="${DEFORM_SHARED_DATA:-../shared/data}"

# name | mesh | skeleton | weights | pose, DEG and HALF standing for the angle and its half
CASES=("phantom_2k||||knee:flexion:DEG")
for mesh in leg_1633 leg_25969; do
  [ -f "$DATA/leg/$mesh.obj" ] && CASES+=("$mesh|$DATA/leg/$mesh.obj|$DATA/leg/leg.tgf||1:x:DEG")
done
if [ -f "$DATA/arm/arm_8311.obj" ]; then
  CASES+=("arm_8311|$DATA/arm/arm_8311.obj|$DATA/arm/arm.tgf||2:z:-DEG")
  CASES+=("arm_8311 (authored weights)|$DATA/arm/arm_8311.obj|$DATA/arm/arm.tgf|$DATA/arm/arm_8311_weights.dmat|2:z:-DEG")
fi
[ -f "$DATA/arm/arm_132946.obj" ] &&
  CASES+=("arm_132946|$DATA/arm/arm_132946.obj|$DATA/arm/arm.tgf||2:z:-DEG")
[ -f "$DATA/body/body_13380.obj" ] &&
  CASES+=("body_13380|$DATA/body/body_13380.obj|$DATA/body/body.tgf||joint5:x:DEG,joint4:x:-HALF,joint10:x:HALF")

# The body once more as one tree: body.tgf's joints and bones with body_parents.txt's parents, in
# the project's JSON skeleton (TGF cannot state a parent away from the parent's tail), so the hips
# are joints with regions instead of roots.
if [ -f "$DATA/body/body_13380.obj" ] && [ -f "$DATA/body/body_parents.txt" ]; then
  PARENTED_SKELETON="$(mktemp --suffix=.json)"
  trap 'rm -f "$PARENTED_SKELETON"' EXIT
  python3 - "$DATA/body/body.tgf" "$DATA/body/body_parents.txt" >"$PARENTED_SKELETON" <<'PY'
import json, sys
lines = open(sys.argv[1]).read().split("\n")
split = lines.index("#")
ids, joints = {}, []
for line in lines[:split]:
    if line.strip():
        fields = line.split()
        ids[fields[0]] = len(joints)
        joints.append({"name": "joint%d" % len(joints), "position": [float(v) for v in fields[1:4]]})
edges = lines[split + 1:]
edges = edges[:edges.index("#")] if "#" in edges else edges
bones = [[ids[l.split()[0]], ids[l.split()[1]]] for l in edges if l.strip()]
parents = {}
for line in open(sys.argv[2]):
    if line.strip() and not line.startswith("#"):
        bone, parent = line.split()[:2]
        parents[int(bone)] = int(parent)
out = []
for k, (head, tail) in enumerate(bones):
    bone = {"head": joints[head]["name"], "tail": joints[tail]["name"]}
    if parents.get(k, -1) >= 0:
        bone["parent"] = parents[k]
    out.append(bone)
print(json.dumps({"joints": joints, "bones": out}))
PY
  CASES+=("body_13380 (one tree)|$DATA/body/body_13380.obj|$PARENTED_SKELETON||joint5:x:DEG,joint4:x:-HALF,joint10:x:HALF")
fi

# One row: the measures of deformctl's JSON on stdin, after the row's leading cells.
row() {
  python3 -c "import json,sys; d=json.load(sys.stdin); print('| $1 | %+.4f | %.3f | %.3f | %.4f | %.1e | %d | %d | %s |' % (d['volume_change'], d['clearance_min'], d['clearance_p01'], d['sink_fraction'], d['rigid_zone_error'], d['inverted_triangles'], d['self_intersections'], d.get('bone_penetration', {}).get('vertices', '-')))"
}

if [ "${DEFORM_QUALITY_ABLATION:-0}" = 1 ]; then
  # variant name | --joint-nodes | --material
  VARIANTS=("plain|off|off" "node only|on|off" "material only|off|on" "both|on|on")
  echo "| mesh | degrees | variant | volume_change | clearance_min | clearance_p01 | sink_fraction | rigid_zone_error | inverted_triangles | self_intersections | bone_inside |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
else
  echo "| mesh | degrees | method | volume_change | clearance_min | clearance_p01 | sink_fraction | rigid_zone_error | inverted_triangles | self_intersections | bone_inside |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
fi
for case in "${CASES[@]}"; do
  IFS='|' read -r name mesh skeleton weights pose <<<"$case"
  args=()
  [ -n "$mesh" ] && args=(--mesh "$mesh" --skeleton "$skeleton" --bones capsules)
  [ -n "$weights" ] && args+=(--weights "$weights")
  constraints=${DEFORM_QUALITY_CONSTRAINTS:-on}
  args+=(--contacts "$constraints" --volume "$constraints")
  if [ "${DEFORM_QUALITY_ABLATION:-0}" = 1 ]; then
    degree_list=${DEFORM_QUALITY_DEGREES:-90 120}
  else
    degree_list=${DEFORM_QUALITY_DEGREES:-45 90 120}
  fi
  for degrees in $degree_list; do
    spec=${pose//DEG/$degrees}
    spec=${spec//HALF/$((degrees / 2))}
    if [ "${DEFORM_QUALITY_ABLATION:-0}" = 1 ]; then
      for variant in "${VARIANTS[@]}"; do
        IFS='|' read -r label nodes material <<<"$variant"
        # The paper's figure 2: the method's two additions alone, no constraints.
        "$DEFORMCTL" deform "${args[@]}" --pose "$spec" --method paper --joint-nodes "$nodes" \
          --material "$material" --contacts off --volume off 2>/dev/null | row "$name | $degrees | $label"
      done
      continue
    fi
    for method in ${DEFORM_QUALITY_METHODS:-paper paper-linear laplacian lbs dqs cor ddm}; do
      "$DEFORMCTL" deform "${args[@]}" --pose "$spec" --method "$method" 2>/dev/null |
        row "$name | $degrees | $method"
    done
  done
done
