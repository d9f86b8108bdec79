#!/usr/bin/env bash
# deformctl deform's flags (ctest): deformctl_test.sh DEFORMCTL
# On a small phantom: the ablation switches --joint-nodes and --material (default on/on, in the
# JSON as joint_nodes_enabled and material_enabled, off removing the joint nodes or the material
# weights; --material-profile 1,1,1 is --material off), the methods cor and ddm (rest pose in,
# rest mesh out), the triangle counts in the JSON, the bone surfaces (the phantom's, capsules,
# files; bone_penetration for every method), the
# constraints (--contacts, --bone-reach, --volume), bad values (exit 2 for a flag CLI11 refuses,
# 1 for an unknown method or a bad bone surface), and --tool (a sphere, a capsule:
# tool_penetration_max, tool_dent; bad tools refused with exit 1). Needs python3.
set -euo pipefail
DEFORMCTL="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
failed=0

# run NAME EXPECTED-EXIT PYTHON-CHECK ARGS...: the check is a Python expression over d (the JSON).
run() {
  local name=$1 expected=$2 check=$3
  shift 3
  local status=0
  "$DEFORMCTL" deform --phantom-vertices 800 "$@" >"$WORK/out" 2>"$WORK/err" </dev/null || status=$?
  if [ "$status" -ne "$expected" ]; then
    echo "FAIL: $name: exit $status (expected $expected): $(head -c 300 "$WORK/err")" >&2
    failed=1
    return
  fi
  if [ -n "$check" ] &&
    ! python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if ($check) else 1)" \
      "$WORK/out"; then
    echo "FAIL: $name: '$check' does not hold for $(head -c 600 "$WORK/out")" >&2
    failed=1
    return
  fi
  echo "ok: $name"
}

run "defaults: both switches on" 0 \
  "d['joint_nodes_enabled'] and d['material_enabled'] and d['joint_nodes'] > 0" \
  --pose knee:flexion:90
run "triangle counts are reported" 0 \
  "isinstance(d['inverted_triangles'], int) and isinstance(d['self_intersections'], int)" \
  --pose knee:flexion:90
run "--joint-nodes off" 0 \
  "not d['joint_nodes_enabled'] and d['material_enabled'] and d['joint_nodes'] == 0" \
  --pose knee:flexion:90 --joint-nodes off
run "--material off" 0 \
  "d['joint_nodes_enabled'] and not d['material_enabled'] and d['joint_nodes'] > 0" \
  --pose knee:flexion:90 --material off
uniform=$(python3 -c "import json; print(json.load(open('$WORK/out'))['clearance_min'])")
run "--material-profile 1,1,1 is every row weight 1" 0 \
  "d['material_enabled'] and abs(d['clearance_min'] - $uniform) < 1e-12" \
  --pose knee:flexion:90 --material-profile 1,1,1
run "--material-profile 8,1,8 reaches the model" 0 \
  "abs(d['clearance_min'] - $uniform) > 1e-6" --pose knee:flexion:90 --material-profile 8,1,8
run "both off is the plain Laplacian's volume" 0 \
  "not d['joint_nodes_enabled'] and not d['material_enabled']" \
  --pose knee:flexion:90 --joint-nodes off --material off --contacts off --volume off
plain=$(python3 -c "import json; print(json.load(open('$WORK/out'))['volume_change'])")
run "laplacian reports neither" 0 \
  "not d['joint_nodes_enabled'] and not d['material_enabled'] and \
   abs(d['volume_change'] - $plain) < 1e-12" \
  --pose knee:flexion:90 --method laplacian --bone-reach off
run "--bone-reach off keeps the rigid zones" 0 \
  "not d['constraints']['bone_reach'] and d['constraints']['reached_vertices'] == 0" \
  --pose knee:flexion:120 --bone-reach off
rigid_kept=$(python3 -c "import json; print(sum(b['rigid_vertices'] for b in json.load(open('$WORK/out'))['binding']['bones']))")
run "--bone-reach (default on): the skin the bones reach leaves the rigid zones" 0 \
  "d['constraints']['bone_reach'] and d['constraints']['reached_vertices'] > 0 and \
   sum(b['rigid_vertices'] for b in d['binding']['bones']) < $rigid_kept and \
   d['bone_penetration']['vertices'] == 0" \
  --pose knee:flexion:120
run "--method cor: rest in, rest out" 0 "d['method'] == 'cor' and d['max_displacement'] < 1e-9" \
  --method cor
run "--method ddm: rest in, rest out" 0 "d['method'] == 'ddm' and d['max_displacement'] < 1e-9" \
  --method ddm
run "--method ddm bends the knee" 0 "abs(d['volume_change']) < 0.05 and d['max_displacement'] > 0.1" \
  --method ddm --pose knee:flexion:90
run "bones: the phantom's three, none inside after the frame, volume kept" 0 \
  "d['bone_surfaces'] == 3 and d['bone_penetration']['vertices'] == 0 and \
   abs(d['volume_change']) < 1e-4 and d['constraints']['rounds'] >= 1" \
  --pose knee:flexion:120
run "constraints off: the model's own frame" 0 \
  "d['constraints']['rounds'] == 0 and abs(d['volume_change']) > 1e-3" \
  --pose knee:flexion:120 --contacts off --volume off
run "--method lbs reports its bone penetration" 0 \
  "d['bone_penetration']['vertices'] >= 0 and 'constraints' not in d" \
  --pose knee:flexion:120 --method lbs
run "--bones capsules on the phantom" 0 "d['bone_surfaces'] == 2" --bones capsules
run "--bones none" 0 "d['bone_surfaces'] == 0 and 'bone_penetration' not in d" --bones none
# A box around the whole leg (outward faces): a bone the rest skin is inside of.
cat >"$WORK/box.obj" <<'OBJ'
v -2 -1 -2
v 2 -1 -2
v 2 10 -2
v -2 10 -2
v -2 -1 2
v 2 -1 2
v 2 10 2
v -2 10 2
f 1 4 3
f 1 3 2
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 4 8 7
f 4 7 3
f 1 5 8
f 1 8 4
f 2 3 7
f 2 7 6
OBJ
run "--bone-surface FILE:BONE that the rest skin is inside of is refused" 1 "" \
  --bone-surface "$WORK/box.obj:hip"
grep -q "at rest" "$WORK/err" || { echo "FAIL: the refusal does not say 'at rest'" >&2; failed=1; }
run "--bone-surface with an unknown bone is refused" 1 "" --bone-surface "$WORK/box.obj:elbow"
grep -q "no bone named 'elbow'" "$WORK/err" || { echo "FAIL: the refusal does not name the bone" >&2; failed=1; }
run "--joint-nodes maybe is refused" 2 "" --joint-nodes maybe
run "--material 0 is refused" 2 "" --material 0
run "--material-profile with two weights is refused" 1 "" --material-profile 4,1
run "--material-profile with a zero weight is refused" 1 "" --material-profile 0,1,4
run "an unknown method is refused" 1 "" --method arap
run "--rigid-weight-tolerance 0.6 is refused naming the flag" 1 "" --rigid-weight-tolerance 0.6
grep -q -- "--rigid-weight-tolerance" "$WORK/err" ||
  { echo "FAIL: the refusal does not name --rigid-weight-tolerance" >&2; failed=1; }
run "--rigid-weight-tolerance 0.2 is accepted" 0 "d['input_warnings'] == []" \
  --rigid-weight-tolerance 0.2

# Tools (the 800-vertex phantom: front of the thigh at y 6, z 0.66; diagonal 8.97).
run "--tool sphere presses the skin and leaves none inside" 0 \
  "d['tools'] == 1 and d['tool_penetration']['before']['vertices'] > 0 and \
   d['tool_penetration_max'] <= 1e-4 * 8.97 and not d['tool_penetration']['unresolved'] and \
   d['tool_dent']['vertices'] > 0 and d['tool_dent']['max_displacement'] > 0.05 and \
   d['bone_penetration']['vertices'] == 0" \
  --tool sphere:0,6,0.86,0.3
run "--tool capsule and a sphere together" 0 \
  "d['tools'] == 2 and d['tool_penetration']['before']['vertices'] > 0 and \
   d['tool_penetration_max'] <= 1e-4 * 8.97" \
  --pose knee:flexion:45 --tool capsule:-0.3,6,0.8,0.3,6,0.8,0.2 --tool sphere:0,6.8,0.9,0.3
run "--tool away from the skin changes nothing" 0 \
  "d['tool_penetration']['before']['vertices'] == 0 and d['tool_dent']['vertices'] == 0 and \
   d['tool_dent']['max_displacement'] == 0" \
  --tool sphere:0,6,3,0.3
run "--tool with --contacts off --volume off still pushes" 0 \
  "d['tool_penetration_max'] <= 1e-4 * 8.97 and d['tool_dent']['vertices'] > 0" \
  --contacts off --volume off --tool sphere:0,6,0.86,0.3
run "--tool without a radius is refused" 1 "" --tool sphere:0,6,0.86
grep -q "expected sphere:X,Y,Z,R" "$WORK/err" || { echo "FAIL: the refusal does not show the form" >&2; failed=1; }
run "--tool with a negative radius is refused" 1 "" --tool sphere:0,6,0.86,-1
run "--tool with a radius beyond half the diagonal is refused" 1 "" --tool sphere:0,6,0.86,5
run "--tool cube is refused" 1 "" --tool cube:0,6,0.86,0.3
run "five --tool are refused" 1 "" --tool sphere:0,6,3,0.1 --tool sphere:0,6,3,0.1 \
  --tool sphere:0,6,3,0.1 --tool sphere:0,6,3,0.1 --tool sphere:0,6,3,0.1
run "--tool with --method lbs is refused" 1 "" --method lbs --tool sphere:0,6,0.86,0.3

# A glTF rig's own animation (the animated chain of the glTF fuzz corpus: its knee turns 90
# degrees over 1 s): the rest at t = 0, bent by t = 1 (LBS loses a quarter of the volume), the
# JSON naming the animation and the time; unknown animations and non-glTF meshes are refused.
ANIMATED="$(dirname "$0")/fuzz/corpus/gltf_fuzz/animated_chain.glb"
run "--animation at its start is the rest pose" 0 \
  "d['animation'] == 'bend' and d['time'] == 0 and abs(d['volume_change']) < 1e-9" \
  --mesh "$ANIMATED" --animation bend --time 0 --method lbs
run "--animation by index at its end bends the knee" 0 \
  "d['animation'] == '0' and abs(d['volume_change'] + 0.25) < 1e-3" \
  --mesh "$ANIMATED" --animation 0 --time 1 --method lbs
run "--animation after its end clamps to the last key" 0 "abs(d['volume_change'] + 0.25) < 1e-3" \
  --mesh "$ANIMATED" --animation bend --time 5 --method lbs
run "--animation that the file does not have is refused" 1 "" \
  --mesh "$ANIMATED" --animation run --time 0
grep -q "no animation 'run'" "$WORK/err" || { echo "FAIL: the refusal does not name it" >&2; failed=1; }
run "--animation on the phantom is refused" 1 "" --animation bend --time 0

[ "$failed" -eq 0 ] || exit 1
echo "PASS: deformctl deform's flags"
