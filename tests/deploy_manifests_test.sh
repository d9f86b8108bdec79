#!/usr/bin/env bash
# scripts/check-deploy-manifests.sh fails on broken deployment files, naming the problem: each case
# copies docker/cluster, breaks one thing and expects exit 1 with its message; the unbroken copy
# must pass first (so that a case fails for its own break, not for the copy).
#
# Usage: deploy_manifests_test.sh SOURCE_DIR
set -euo pipefail
SOURCE="$1"
CHECK="$SOURCE/scripts/check-deploy-manifests.sh"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
failures=0

# break NAME EXPECTED PYTHON: PYTHON edits the copy (the current directory), given `edit(file,
# function)`, which loads a YAML file's documents, passes each to function and writes them back.
break_case() {
  local name="$1" expected="$2" edit="$3"
  rm -rf "$WORK/cluster"
  cp -r "$SOURCE/docker/cluster" "$WORK/cluster"
  (cd "$WORK/cluster" && python3 - <<EOF
import yaml
def edit(file, function):
    with open(file) as f:
        documents = list(yaml.safe_load_all(f))
    for document in documents:
        function(document)
    with open(file, "w") as f:
        yaml.safe_dump_all(documents, f, sort_keys=False)
$edit
EOF
  )
  if "$CHECK" "$WORK/cluster" >"$WORK/out" 2>&1; then
    echo "FAIL $name: the check passed" >&2
    failures=$((failures + 1))
  elif ! grep -qF -- "$expected" "$WORK/out"; then
    echo "FAIL $name: the check failed without '$expected':" >&2
    cat "$WORK/out" >&2
    failures=$((failures + 1))
  else
    echo "ok   $name: $(grep -F -- "$expected" "$WORK/out" | head -n 1)"
  fi
}

rm -rf "$WORK/cluster"
cp -r "$SOURCE/docker/cluster" "$WORK/cluster"
"$CHECK" "$WORK/cluster" || { echo "FAIL: the unbroken copy does not pass" >&2; exit 1; }

break_case pdb-selector "PodDisruptionBudget deformd: its selector matches no pod template" '
def f(d): d["spec"]["selector"]["matchLabels"]["app.kubernetes.io/component"] = "replicas"
edit("k8s/replicas-pdb.yaml", f)'
break_case pdb-min-available "minAvailable 3 is not at least 2 and below the 3 replicas" '
def f(d): d["spec"]["minAvailable"] = 3
edit("k8s/replicas-pdb.yaml", f)'
break_case pvc-access "PersistentVolumeClaim deformd-store: not ReadWriteMany" '
def f(d): d["spec"]["accessModes"] = ["ReadWriteOnce"]
edit("k8s/store-pvc.yaml", f)'
break_case template-labels "spec.selector.matchLabels" '
def f(d): d["spec"]["template"]["metadata"]["labels"]["app.kubernetes.io/name"] = "other"
edit("k8s/replicas.yaml", f)'
break_case no-readiness "container deformd: no readinessProbe" '
def f(d): del d["spec"]["template"]["spec"]["containers"][0]["readinessProbe"]
edit("k8s/replicas.yaml", f)'
break_case no-limits "container haproxy: no resources.limits.memory" '
def f(d): del d["spec"]["template"]["spec"]["containers"][0]["resources"]["limits"]["memory"]
edit("k8s/balancer.yaml", f)'
break_case root-filesystem "container deformd: readOnlyRootFilesystem is not true" '
def f(d): d["spec"]["template"]["spec"]["containers"][0]["securityContext"]["readOnlyRootFilesystem"] = False
edit("k8s/replicas.yaml", f)'
break_case service-selector "Service deformd: its selector" '
def f(d): d["spec"]["selector"]["app.kubernetes.io/component"] = "balancers"
edit("k8s/balancer-service.yaml", f)'
break_case unknown-kind "apps/v1 DaemonSet deformd: not a known kind" '
def f(d): d["kind"] = "DaemonSet"
edit("k8s/replicas.yaml", f)'
break_case schema-type "schema: k8s/replicas.yaml: data/spec/replicas must be integer" '
def f(d): d["spec"]["replicas"] = "3"
edit("k8s/replicas.yaml", f)'
break_case balancer-replica-name "DEFORM_REPLICA_2 (" '
def f(d):
    for e in d["spec"]["template"]["spec"]["containers"][0]["env"]:
        if e["name"] == "DEFORM_REPLICA_2": e["value"] = e["value"].replace("deformd-1.", "deformd-2.")
edit("k8s/balancer.yaml", f)'
break_case haproxy-config "haproxy -c fails" '
def f(d): d["data"]["haproxy.cfg"] = d["data"]["haproxy.cfg"].replace("hash-type consistent", "hash-type ring")
edit("k8s/balancer-config.yaml", f)'
break_case haproxy-drift "differs from haproxy.cfg beyond the Kubernetes additions: 'default-server check proto h2 inter 2s" '
def f(d): d["data"]["haproxy.cfg"] = d["data"]["haproxy.cfg"].replace("inter 500ms", "inter 2s")
edit("k8s/balancer-config.yaml", f)'
break_case haproxy-shipped-changed "'tune.h2.max-concurrent-streams 100' where haproxy.cfg has" '
with open("haproxy.cfg") as f: text = f.read()
with open("haproxy.cfg", "w") as f: f.write(text.replace("max-concurrent-streams 1000", "max-concurrent-streams 2000"))
def g(d): d["data"]["haproxy.cfg"] = d["data"]["haproxy.cfg"].replace("max-concurrent-streams 1000", "max-concurrent-streams 100")
edit("k8s/balancer-config.yaml", g)'
break_case compose-haproxy "service balancer: haproxy -c fails on haproxy.cfg" '
def f(d): d["services"]["balancer"]["environment"]["DEFORM_LB_STATS"] = "0.0.0.0"
edit("compose.yaml", f)'
break_case drain-within-grace "is not within --shutdown-grace-s" '
def f(d):
    for e in d["spec"]["template"]["spec"]["containers"][0]["env"]:
        if e["name"] == "DEFORMD_DRAIN_DELAY_MS": e["value"] = "12000"
edit("k8s/replicas.yaml", f)'
break_case service-links "enableServiceLinks is not false" '
def f(d): del d["spec"]["template"]["spec"]["enableServiceLinks"]
edit("k8s/replicas.yaml", f)'
break_case kustomization "replicas-pdb.yaml is not among the resources" '
def f(d): d["resources"].remove("replicas-pdb.yaml")
edit("k8s/kustomization.yaml", f)'
break_case compose-store "the deformd services do not share one store" '
def f(d):
    d["volumes"]["store-3"] = None
    replica = d["services"]["deformd-3"]  # a copy: the merged replicas share their lists
    replica["volumes"] = ["store-3:/var/lib/deformd/store"] + replica["volumes"][1:]
edit("compose.yaml", f)'
break_case compose-replicas "2 deformd services (with DEFORMD_STORE_SHARED); expected 3" '
def f(d): del d["services"]["deformd-3"]
edit("compose.yaml", f)'
break_case compose-hardening "service deformd-2: cap_drop is not ALL" '
def f(d): d["services"]["deformd-2"]["cap_drop"] = ["NET_RAW"]
edit("compose.yaml", f)'
break_case compose-balancer-wait "service balancer: does not wait for deformd-1 to be healthy" '
def f(d): d["services"]["balancer"]["depends_on"]["deformd-1"]["condition"] = "service_started"
edit("compose.yaml", f)'
break_case compose-schema "docker-compose config fails" '
def f(d): d["services"]["balancer"]["stop_grace"] = "5s"
edit("compose.yaml", f)'

if [ "$failures" -ne 0 ]; then
  echo "deploy_manifests_broken: $failures cases not caught" >&2
  exit 1
fi
echo "deploy_manifests_broken: every broken copy failed the check, naming its problem"
