#!/usr/bin/env bash
# Checks the cluster's deployment files (docs/cluster.md) without a cluster: every YAML under
# DIR/k8s and DIR/compose.yaml is parsed (python3-yaml) and checked for what a schema checker
# would catch and for what ties the files together:
#
#   Kubernetes: every document has apiVersion, kind and metadata.name, of a known kind (apps/v1
#   Deployment|StatefulSet, v1 Service|PersistentVolumeClaim|Secret|ConfigMap, policy/v1
#   PodDisruptionBudget), names unique per kind; kustomization.yaml lists every manifest but the
#   *.template.yaml ones, and only files that exist; workloads' selectors match their templates'
#   labels; every container has an image, resources (requests, limits of cpu and memory), a
#   readinessProbe and a livenessProbe on a port it declares, and is hardened (runAsNonRoot,
#   readOnlyRootFilesystem, no privilege escalation, capabilities drop ALL, seccomp
#   RuntimeDefault); mounts name declared volumes, which name claims, Secrets (and their keys)
#   and ConfigMaps that exist; each Service selects some pod template and targets ports its pods
#   declare; a StatefulSet's serviceName is a headless Service selecting it; the
#   PodDisruptionBudget selects the replicas and leaves one of them to disrupt; the
#   PersistentVolumeClaim is ReadWriteMany; the replicas share the store (DEFORMD_STORE on the
#   claim's mount, DEFORMD_STORE_SHARED, DEFORMD_STORE_KEY on the Secret's) and drain within
#   --shutdown-grace-s, within terminationGracePeriodSeconds, and take no DEFORMD_* variables from
#   Services (enableServiceLinks false); the balancer's DEFORM_REPLICA_N are
#   the StatefulSet's pods under its Service, one per replica, and its ConfigMap's haproxy.cfg
#   passes `haproxy -c` with the balancer's environment and is DIR/haproxy.cfg line for line but
#   for the Kubernetes additions (resolvers, monitor, the servers' resolver options).
#
#   Compose: three deformd replicas (the services with DEFORMD_STORE_SHARED) with one named
#   volume at their store's path, one key file, hardened as docker/compose.yaml (read_only,
#   cap_drop ALL, no-new-privileges, mem_limit, cpus), a health check and a stop_grace_period
#   above --shutdown-grace-s; a balancer whose DEFORM_REPLICA_1..3 are those services, that
#   waits for them to be healthy and publishes the gRPC port, and with whose environment
#   haproxy.cfg passes `haproxy -c`; the key file ignored by git and
#   by the image's build context.
#
# Schemas first: the Kubernetes documents against the API's (scripts/k8s-schema: kubernetes-models
# from npm, installed by scripts/install-node-tools.sh; Debian 12 packages no kubeconform or
# kubeval), which checks types, formats and required fields but lets unknown fields pass; the
# compose file against Compose's (`docker-compose config`, Debian's docker-compose). Then the
# checks above, which are this script's own.
#
# Usage: scripts/check-deploy-manifests.sh [DIR]   (default docker/cluster). Exits 1 naming each
# problem.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
DIR="${1:-$ROOT/docker/cluster}"
missing() { echo "check-deploy-manifests: $1 is missing ($2)" >&2; exit 1; }
for tool in python3 haproxy docker-compose; do
  command -v "$tool" >/dev/null 2>&1 || missing "$tool" "scripts/install-deps.sh scripts/packages/deploy.txt"
done
python3 -c 'import yaml' 2>/dev/null || missing python3-yaml "scripts/install-deps.sh scripts/packages/deploy.txt"
command -v node >/dev/null 2>&1 || missing node "scripts/install-node-tools.sh"
[ -d "$ROOT/scripts/k8s-schema/node_modules/kubernetes-models" ] ||
  missing "scripts/k8s-schema/node_modules" "scripts/install-node-tools.sh"

exec python3 - "$DIR" "$ROOT" <<'EOF'
import json, os, re, subprocess, sys, tempfile
import yaml

directory, root = sys.argv[1], sys.argv[2]
problems = []


def malformed(kind, value, trace):
    # A document shaped where the checks expect none (a list for a mapping, ...): named, exit 1.
    import traceback
    for p in problems:
        print(f"check-deploy-manifests: {p}", file=sys.stderr)
    line = traceback.extract_tb(trace)[-1].lineno
    print(f"check-deploy-manifests: FAILED: a malformed document stopped the checks "
          f"({kind.__name__}: {value}, at the script's line {line})", file=sys.stderr)
    sys.exit(1)


sys.excepthook = malformed


def problem(where, text):
    problems.append(f"{os.path.relpath(where, directory) if os.path.isabs(where) else where}: {text}")


def load_all(path):
    try:
        with open(path) as f:
            return [d for d in yaml.safe_load_all(f) if d is not None]
    except (OSError, yaml.YAMLError) as error:
        problem(path, f"not readable YAML: {error}")
        return []


def matches(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


# ---------------------------------------------------------------- Kubernetes
KNOWN = {("apps/v1", "Deployment"), ("apps/v1", "StatefulSet"), ("v1", "Service"),
         ("v1", "PersistentVolumeClaim"), ("v1", "Secret"), ("v1", "ConfigMap"),
         ("policy/v1", "PodDisruptionBudget")}
k8s = os.path.join(directory, "k8s")
docs = []  # (path, document)
kustomization = None
if not os.path.isdir(k8s):
    problem(k8s, "missing")
else:
    for name in sorted(os.listdir(k8s)):
        if not name.endswith((".yaml", ".yml")):
            continue
        path = os.path.join(k8s, name)
        if name == "kustomization.yaml":
            loaded = load_all(path)
            kustomization = (path, loaded[0] if loaded else {})
            continue
        for document in load_all(path):
            docs.append((path, document))

by_kind = {}
for path, d in docs:
    if not isinstance(d, dict):
        problem(path, "a document that is not a mapping")
        continue
    api, kind, name = d.get("apiVersion"), d.get("kind"), (d.get("metadata") or {}).get("name")
    if not api or not kind or not name:
        problem(path, f"a document without apiVersion, kind or metadata.name ({api}, {kind}, {name})")
        continue
    if (api, kind) not in KNOWN:
        problem(path, f"{api} {kind} {name}: not a known kind")
        continue
    if name in by_kind.setdefault(kind, {}):
        problem(path, f"{kind} {name} is defined twice")
    by_kind[kind][name] = (path, d)

# The API's schemas (scripts/k8s-schema/validate.mjs).
with tempfile.NamedTemporaryFile("w", suffix=".json") as f:
    json.dump([{"where": os.path.relpath(p, directory), "document": d} for p, d in docs
               if isinstance(d, dict) and (d.get("apiVersion"), d.get("kind")) in KNOWN], f)
    f.flush()
    schema = subprocess.run(["node", os.path.join(root, "scripts/k8s-schema/validate.mjs"), f.name],
                            capture_output=True, text=True)
for line in (schema.stdout + schema.stderr).splitlines():
    problems.append(f"schema: {line}")
if schema.returncode != 0 and not (schema.stdout + schema.stderr).strip():
    problems.append(f"schema: validate.mjs exited {schema.returncode}")

if kustomization:
    path, k = kustomization
    if k.get("kind") != "Kustomization":
        problem(path, "kind is not Kustomization")
    listed = set(k.get("resources") or [])
    for resource in sorted(listed):
        if not os.path.isfile(os.path.join(k8s, resource)):
            problem(path, f"resource {resource} does not exist")
    for manifest in sorted({os.path.basename(p) for p, _ in docs}):
        if manifest not in listed and not manifest.endswith(".template.yaml"):
            problem(path, f"{manifest} is not among the resources")
elif os.path.isdir(k8s):
    problem(k8s, "no kustomization.yaml")

workloads = [(kind, name, path, d) for kind in ("Deployment", "StatefulSet")
             for name, (path, d) in by_kind.get(kind, {}).items()]


def pod_labels(d):
    return ((d.get("spec") or {}).get("template") or {}).get("metadata", {}).get("labels") or {}


def pod_spec(d):
    return ((d.get("spec") or {}).get("template") or {}).get("spec") or {}


def declared_ports(spec):
    ports = set()
    for c in spec.get("containers") or []:
        for p in c.get("ports") or []:
            ports.add(p.get("containerPort"))
            if p.get("name"):
                ports.add(p["name"])
    return ports


def probe_port(probe):
    for way in ("grpc", "httpGet", "tcpSocket"):
        if way in probe:
            return probe[way].get("port")
    return None if "exec" in probe else "(no handler)"


def env_of(container):
    return {e["name"]: e.get("value") for e in container.get("env") or [] if "name" in e}


SECTIONS = ("global", "defaults", "frontend", "backend", "listen", "resolvers", "peers")
KUBERNETES_OPTIONS = re.compile(r" (resolvers|init-addr|resolve-prefer) \S+")


def haproxy_lines(text, kubernetes):
    """The configuration's lines without comments and blanks; with `kubernetes`, also without
    what Kubernetes adds to docker/cluster/haproxy.cfg: the resolvers section, the monitor
    lines, and the servers' resolvers, init-addr and resolve-prefer options."""
    lines, skipping = [], False
    for raw in text.splitlines():
        line = " ".join(raw.split("#", 1)[0].split())
        if not line:
            continue
        if line.split()[0] in SECTIONS:
            skipping = kubernetes and line.startswith("resolvers ")
        if skipping or (kubernetes and line.startswith("monitor")):
            continue
        if kubernetes and line.startswith("default-server "):
            line = KUBERNETES_OPTIONS.sub("", line)
        lines.append(line)
    return lines


def haproxy_drift(text):
    shipped_path = os.path.join(directory, "haproxy.cfg")
    try:
        with open(shipped_path) as f:
            shipped = haproxy_lines(f.read(), False)
    except OSError:
        return f"{shipped_path} is missing"
    ours = haproxy_lines(text, True)
    for i, (a, b) in enumerate(zip(shipped, ours)):
        if a != b:
            return f"'{b}' where haproxy.cfg has '{a}'"
    if len(shipped) != len(ours):
        extra = (shipped[len(ours):] or ours[len(shipped):])[0]
        return f"'{extra}' is only in {'haproxy.cfg' if len(shipped) > len(ours) else 'the ConfigMap'}"
    return None


for kind, name, path, d in workloads:
    where = f"{kind} {name}"
    spec = d.get("spec") or {}
    selector = (spec.get("selector") or {}).get("matchLabels") or {}
    if not matches(selector, pod_labels(d)):
        problem(path, f"{where}: spec.selector.matchLabels {selector} does not match the "
                      f"template's labels {pod_labels(d)}")
    if not isinstance(spec.get("replicas"), int):
        problem(path, f"{where}: spec.replicas is not a number")
    pod = pod_spec(d)
    if not isinstance(pod.get("terminationGracePeriodSeconds"), int):
        problem(path, f"{where}: no terminationGracePeriodSeconds")
    pod_security = pod.get("securityContext") or {}
    volumes = {v.get("name"): v for v in pod.get("volumes") or []}
    for v in volumes.values():
        claim = (v.get("persistentVolumeClaim") or {}).get("claimName")
        if claim is not None and claim not in by_kind.get("PersistentVolumeClaim", {}):
            problem(path, f"{where}: volume {v['name']} names the claim {claim}, which no manifest defines")
        secret = (v.get("secret") or {}).get("secretName")
        if secret is not None and secret not in by_kind.get("Secret", {}):
            problem(path, f"{where}: volume {v['name']} names the Secret {secret}, which no manifest defines")
        config = (v.get("configMap") or {}).get("name")
        if config is not None and config not in by_kind.get("ConfigMap", {}):
            problem(path, f"{where}: volume {v['name']} names the ConfigMap {config}, which no manifest defines")
    containers = pod.get("containers") or []
    if not containers:
        problem(path, f"{where}: no containers")
    ports = declared_ports(pod)
    for c in containers:
        cw = f"{where} container {c.get('name')}"
        if not c.get("name") or not c.get("image"):
            problem(path, f"{cw}: no name or image")
        resources = c.get("resources") or {}
        for part in ("requests", "limits"):
            for what in ("cpu", "memory"):
                if what not in (resources.get(part) or {}):
                    problem(path, f"{cw}: no resources.{part}.{what}")
        for probe in ("readinessProbe", "livenessProbe"):
            if probe not in c:
                problem(path, f"{cw}: no {probe}")
            elif probe_port(c[probe]) is not None and probe_port(c[probe]) not in ports:
                problem(path, f"{cw}: {probe} on port {probe_port(c[probe])}, which no container declares")
        security = c.get("securityContext") or {}

        def setting(key):
            return security.get(key, pod_security.get(key))

        if setting("runAsNonRoot") is not True:
            problem(path, f"{cw}: runAsNonRoot is not true")
        if security.get("readOnlyRootFilesystem") is not True:
            problem(path, f"{cw}: readOnlyRootFilesystem is not true")
        if security.get("allowPrivilegeEscalation") is not False:
            problem(path, f"{cw}: allowPrivilegeEscalation is not false")
        if "ALL" not in ((security.get("capabilities") or {}).get("drop") or []):
            problem(path, f"{cw}: capabilities do not drop ALL")
        if (setting("seccompProfile") or {}).get("type") != "RuntimeDefault":
            problem(path, f"{cw}: seccompProfile is not RuntimeDefault")
        for mount in c.get("volumeMounts") or []:
            volume = volumes.get(mount.get("name"))
            if volume is None:
                problem(path, f"{cw}: mounts {mount.get('name')}, which is not among the volumes")
                continue
            secret = (volume.get("secret") or {}).get("secretName")
            if secret in by_kind.get("Secret", {}) and "subPath" in mount:
                _, s = by_kind["Secret"][secret]
                if mount["subPath"] not in (s.get("data") or {}) | (s.get("stringData") or {}):
                    problem(path, f"{cw}: mounts {mount['subPath']} of the Secret {secret}, which has no such key")

for name, (path, d) in by_kind.get("Service", {}).items():
    spec = d.get("spec") or {}
    selector = spec.get("selector") or {}
    selected = [w for w in workloads if matches(selector, pod_labels(w[3]))]
    if not selected:
        problem(path, f"Service {name}: its selector {selector} matches no pod template")
    for port in spec.get("ports") or []:
        target = port.get("targetPort", port.get("port"))
        for kind, wname, _, w in selected:
            if target not in declared_ports(pod_spec(w)):
                problem(path, f"Service {name}: port {port.get('name')} targets {target}, which "
                              f"{kind} {wname} does not declare")

for name, (path, d) in by_kind.get("PersistentVolumeClaim", {}).items():
    spec = d.get("spec") or {}
    if "ReadWriteMany" not in (spec.get("accessModes") or []):
        problem(path, f"PersistentVolumeClaim {name}: not ReadWriteMany (the replicas share it)")
    if not ((spec.get("resources") or {}).get("requests") or {}).get("storage"):
        problem(path, f"PersistentVolumeClaim {name}: no resources.requests.storage")

replicas = []  # (kind, name, path, document, container) of deformd's replicas
for kind, name, path, d in workloads:
    for c in pod_spec(d).get("containers") or []:
        if "DEFORMD_STORE_SHARED" in env_of(c):
            replicas.append((kind, name, path, d, c))
if len(replicas) != 1:
    problem(k8s, f"{len(replicas)} workloads run deformd with DEFORMD_STORE_SHARED; expected one")

for kind, name, path, d, c in replicas:
    where = f"{kind} {name}"
    env, pod = env_of(c), pod_spec(d)
    count = (d.get("spec") or {}).get("replicas")
    if not isinstance(count, int):
        count = None
    elif count != 3:
        problem(path, f"{where}: {count} replicas; the cluster has 3")
    if str(env.get("DEFORMD_STORE_SHARED")).lower() not in ("true", "1"):
        problem(path, f"{where}: DEFORMD_STORE_SHARED is not true")
    # Kubernetes sets NAME_PORT=tcp://... for every Service NAME in the namespace unless
    # enableServiceLinks is false: a Service `deformd` would give the replicas a DEFORMD_PORT that
    # the image's entry point takes for its port.
    if pod.get("enableServiceLinks") is not False and any(
            n.upper().replace("-", "_").startswith("DEFORMD") for n in by_kind.get("Service", {})):
        problem(path, f"{where}: enableServiceLinks is not false, and a Service's variables would "
                      f"set DEFORMD_* (DEFORMD_PORT is the entry point's port)")
    volumes = {v.get("name"): v for v in pod.get("volumes") or []}

    def mounted_from(file, kinds):
        for mount in c.get("volumeMounts") or []:
            target = mount.get("mountPath", "").rstrip("/")
            if file == target or file.startswith(target + "/"):
                volume = volumes.get(mount.get("name")) or {}
                return next((k for k in kinds if k in volume), None)
        return None

    if mounted_from(env.get("DEFORMD_STORE") or "", ["persistentVolumeClaim"]) is None:
        problem(path, f"{where}: DEFORMD_STORE ({env.get('DEFORMD_STORE')}) is not on a claim's mount")
    if mounted_from(env.get("DEFORMD_STORE_KEY") or "", ["secret"]) is None:
        problem(path, f"{where}: DEFORMD_STORE_KEY ({env.get('DEFORMD_STORE_KEY')}) is not on a Secret's mount")
    grace = next((float(a.split("=", 1)[1]) for a in c.get("args") or []
                  if a.startswith("--shutdown-grace-s=")), 5.0)
    drain = int(env.get("DEFORMD_DRAIN_DELAY_MS") or 0)
    if drain <= 0:
        problem(path, f"{where}: no DEFORMD_DRAIN_DELAY_MS")
    if drain >= grace * 1000:
        problem(path, f"{where}: the drain delay ({drain} ms) is not within --shutdown-grace-s ({grace} s)")
    if (pod.get("terminationGracePeriodSeconds") or 0) <= grace:
        problem(path, f"{where}: terminationGracePeriodSeconds is not above --shutdown-grace-s ({grace} s)")
    budgets = [(n, p, b) for n, (p, b) in by_kind.get("PodDisruptionBudget", {}).items()
               if matches(((b.get("spec") or {}).get("selector") or {}).get("matchLabels"), pod_labels(d))]
    if not budgets:
        problem(k8s, f"no PodDisruptionBudget selects the pods of {where}")
    for n, p, b in budgets:
        least = (b.get("spec") or {}).get("minAvailable")
        if count is not None and (not isinstance(least, int) or not 2 <= least < count):
            problem(p, f"PodDisruptionBudget {n}: minAvailable {least} is not at least 2 and below "
                       f"the {count} replicas")
    for n, (p, b) in by_kind.get("PodDisruptionBudget", {}).items():
        if not any(matches(((b.get("spec") or {}).get("selector") or {}).get("matchLabels"), pod_labels(w[3]))
                   for w in workloads):
            problem(p, f"PodDisruptionBudget {n}: its selector matches no pod template")
    if kind == "StatefulSet":
        service = (d.get("spec") or {}).get("serviceName")
        headless = by_kind.get("Service", {}).get(service)
        if headless is None or (headless[1].get("spec") or {}).get("clusterIP") != "None" or \
                not matches((headless[1].get("spec") or {}).get("selector"), pod_labels(d)):
            problem(path, f"{where}: serviceName {service} is not a headless Service selecting its pods")

        # The balancer: DEFORM_REPLICA_N are this StatefulSet's pods, one each.
        balancers = [(bk, bn, bp, bd, bc) for bk, bn, bp, bd in workloads
                     for bc in pod_spec(bd).get("containers") or [] if "DEFORM_REPLICA_1" in env_of(bc)]
        if len(balancers) != 1:
            problem(k8s, f"{len(balancers)} workloads have DEFORM_REPLICA_1; expected one balancer")
        for bk, bn, bp, bd, bc in balancers:
            benv = env_of(bc)
            for i in range(count or 0):
                value = benv.get(f"DEFORM_REPLICA_{i + 1}") or ""
                if not value.startswith(f"{name}-{i}.{service}.") or not value.endswith(":50051"):
                    problem(bp, f"{bk} {bn}: DEFORM_REPLICA_{i + 1} ({value}) is not "
                                f"{name}-{i}.{service}.…:50051")
            if count is not None and f"DEFORM_REPLICA_{count + 1}" in benv:
                problem(bp, f"{bk} {bn}: more DEFORM_REPLICA_N than the {count} replicas")
            # haproxy -c on its ConfigMap's configuration, in its environment (the pod's
            # namespace as `default`).
            mounts = {m.get("name"): m.get("mountPath") for m in bc.get("volumeMounts") or []}
            configs = [(mounts.get(v.get("name")), v["configMap"].get("name"))
                       for v in pod_spec(bd).get("volumes") or [] if "configMap" in v]
            args = bc.get("args") or []
            file = args[args.index("-f") + 1] if "-f" in args[:-1] else None
            found = False
            for mount, config in configs:
                if config not in by_kind.get("ConfigMap", {}) or not file or not mount:
                    continue
                key = os.path.relpath(file, mount)
                cp, cm = by_kind["ConfigMap"][config]
                text = (cm.get("data") or {}).get(key)
                if text is None:
                    continue
                found = True
                environment = dict(os.environ)
                for e in bc.get("env") or []:
                    value = "default" if "valueFrom" in e else str(e.get("value", ""))
                    environment[e["name"]] = re.sub(r"\$\((\w+)\)",
                                                    lambda m: environment.get(m.group(1), ""), value)
                with tempfile.NamedTemporaryFile("w", suffix=".cfg") as f:
                    f.write(text)
                    f.flush()
                    check = subprocess.run(["haproxy", "-c", "-f", f.name], env=environment,
                                           capture_output=True, text=True)
                if check.returncode != 0:
                    problem(cp, f"ConfigMap {config} {key}: haproxy -c fails: "
                                + (check.stderr or check.stdout).strip().replace("\n", " | "))
                drift = haproxy_drift(text)
                if drift:
                    problem(cp, f"ConfigMap {config} {key}: differs from haproxy.cfg beyond the "
                                f"Kubernetes additions: {drift}")
                for i in range(count or 0):
                    if f"${{DEFORM_REPLICA_{i + 1}}}" not in text:
                        problem(cp, f"ConfigMap {config} {key}: no server at DEFORM_REPLICA_{i + 1}")
            if not found:
                problem(bp, f"{bk} {bn}: its -f {file} is no key of a mounted ConfigMap")

# ---------------------------------------------------------------- Compose
compose_path = os.path.join(directory, "compose.yaml")
compose = (load_all(compose_path) or [{}])[0] if os.path.isfile(compose_path) else None
if compose is None:
    problem(compose_path, "missing")
    compose = {}
if os.path.isfile(compose_path):
    schema = subprocess.run(["docker-compose", "-f", compose_path, "config", "-q"],
                            capture_output=True, text=True, cwd=directory)
    if schema.returncode != 0:
        problem(compose_path, "docker-compose config fails: "
                + (schema.stderr + schema.stdout).strip().replace("\n", " | "))
services = compose.get("services") or {}
named_volumes = set((compose.get("volumes") or {}).keys())


def compose_env(service):
    env = service.get("environment") or {}
    if isinstance(env, list):
        env = dict(item.split("=", 1) if "=" in item else (item, None) for item in env)
    return {k: ("" if v is None else str(v)) for k, v in env.items()}


def compose_mounts(service):
    mounts = []  # (source, target, read_only)
    for v in service.get("volumes") or []:
        if isinstance(v, str):
            parts = v.split(":")
            mounts.append((parts[0], parts[1] if len(parts) > 1 else parts[0],
                           len(parts) > 2 and "ro" in parts[2].split(",")))
        else:
            mounts.append((v.get("source"), v.get("target"), bool(v.get("read_only"))))
    return mounts


def mount_for(service, file):
    best = None
    for source, target, ro in compose_mounts(service):
        target = (target or "").rstrip("/")
        if (file == target or file.startswith(target + "/")) and (best is None or len(target) > len(best[1])):
            best = (source, target, ro)
    return best


def hardened(name, service):
    if service.get("read_only") is not True:
        problem(compose_path, f"service {name}: not read_only")
    if "ALL" not in (service.get("cap_drop") or []):
        problem(compose_path, f"service {name}: cap_drop is not ALL")
    if not any(str(o).replace(" ", "") in ("no-new-privileges:true", "no-new-privileges")
               for o in service.get("security_opt") or []):
        problem(compose_path, f"service {name}: no no-new-privileges")
    for limit in ("mem_limit", "cpus"):
        if limit not in service:
            problem(compose_path, f"service {name}: no {limit}")


def seconds(text):
    match = re.fullmatch(r"(\d+(?:\.\d+)?)(ms|s|m)?", str(text or "").strip())
    if not match:
        return 0.0
    value, unit = float(match.group(1)), match.group(2) or "s"
    return value / 1000 if unit == "ms" else value * 60 if unit == "m" else value


deformd = {n: s for n, s in services.items() if "DEFORMD_STORE_SHARED" in compose_env(s)}
if len(deformd) != 3:
    problem(compose_path, f"{len(deformd)} deformd services (with DEFORMD_STORE_SHARED); expected 3")
stores, keys = set(), set()
for name, s in deformd.items():
    env = compose_env(s)
    hardened(name, s)
    if env.get("DEFORMD_STORE_SHARED", "").lower() not in ("true", "1"):
        problem(compose_path, f"service {name}: DEFORMD_STORE_SHARED is not true")
    store = mount_for(s, env.get("DEFORMD_STORE", ""))
    if store is None or store[0] not in named_volumes:
        problem(compose_path, f"service {name}: DEFORMD_STORE ({env.get('DEFORMD_STORE')}) is not on a named volume")
    else:
        stores.add((store[0], store[1], env.get("DEFORMD_STORE")))
    key = mount_for(s, env.get("DEFORMD_STORE_KEY", ""))
    if key is None or not key[2]:
        problem(compose_path, f"service {name}: DEFORMD_STORE_KEY ({env.get('DEFORMD_STORE_KEY')}) is not on a read-only mount")
    else:
        keys.add((key[0], env.get("DEFORMD_STORE_KEY")))
    if "healthcheck" not in s:
        problem(compose_path, f"service {name}: no healthcheck")
    grace = next((float(a.split("=", 1)[1]) for a in s.get("command") or []
                  if str(a).startswith("--shutdown-grace-s=")), 5.0)
    drain = int(env.get("DEFORMD_DRAIN_DELAY_MS") or 0)
    if drain <= 0 or drain >= grace * 1000:
        problem(compose_path, f"service {name}: DEFORMD_DRAIN_DELAY_MS ({drain}) is not within --shutdown-grace-s ({grace} s)")
    if seconds(s.get("stop_grace_period")) <= grace:
        problem(compose_path, f"service {name}: stop_grace_period ({s.get('stop_grace_period')}) is not above --shutdown-grace-s ({grace} s)")
if len(stores) > 1:
    problem(compose_path, f"the deformd services do not share one store: {sorted(stores)}")
if len(keys) > 1:
    problem(compose_path, f"the deformd services do not share one key file: {sorted(keys)}")

balancers = {n: s for n, s in services.items() if "DEFORM_REPLICA_1" in compose_env(s)}
if len(balancers) != 1:
    problem(compose_path, f"{len(balancers)} balancer services (with DEFORM_REPLICA_1); expected 1")
for name, s in balancers.items():
    env = compose_env(s)
    hardened(name, s)
    named = {env.get(f"DEFORM_REPLICA_{i}", "").rsplit(":", 1)[0] for i in (1, 2, 3)}
    if named != set(deformd):
        problem(compose_path, f"service {name}: DEFORM_REPLICA_1..3 name {sorted(named)}, not the "
                              f"deformd services {sorted(deformd)}")
    # The image's configuration (Dockerfile.haproxy copies haproxy.cfg) with this environment,
    # the replicas' names as loopback addresses (haproxy -c resolves them, and they exist only
    # on the compose network).
    environment = dict(os.environ, **env)
    for i in (1, 2, 3):
        environment[f"DEFORM_REPLICA_{i}"] = "127.0.0.1:" + env.get(f"DEFORM_REPLICA_{i}", ":").rsplit(":", 1)[1]
    check = subprocess.run(["haproxy", "-c", "-f", os.path.join(directory, "haproxy.cfg")],
                           env=environment, capture_output=True, text=True)
    if check.returncode != 0:
        problem(compose_path, f"service {name}: haproxy -c fails on haproxy.cfg: "
                              + (check.stderr or check.stdout).strip().replace("\n", " | "))
    depends = s.get("depends_on") or {}
    for replica in deformd:
        condition = depends.get(replica, {}).get("condition") if isinstance(depends, dict) else None
        if condition != "service_healthy":
            problem(compose_path, f"service {name}: does not wait for {replica} to be healthy")
    port = env.get("DEFORM_LB_BIND", "").rsplit(":", 1)[-1]
    published = [str(p) for p in s.get("ports") or []]
    if not port or not any(p.endswith(":" + port) for p in published):
        problem(compose_path, f"service {name}: the balancer's port ({port}) is not published")
for name, s in services.items():
    if name not in deformd and name not in balancers:
        hardened(name, s)

for ignore in (".gitignore", ".dockerignore"):
    try:
        with open(os.path.join(root, ignore)) as f:
            lines = {line.strip().lstrip("/") for line in f}
    except OSError:
        lines = set()
    for key in ("docker/cluster/store.key", "docker/cluster/k8s/store.key"):
        if key not in lines:
            problem(ignore, f"does not list {key} (a key must not enter git or an image)")

if problems:
    for p in problems:
        print(f"check-deploy-manifests: {p}", file=sys.stderr)
    print(f"check-deploy-manifests: FAILED: {len(problems)} problems", file=sys.stderr)
    sys.exit(1)
print(f"check-deploy-manifests: {len(docs)} Kubernetes documents and {len(services)} compose "
      f"services checked, no problem")
EOF
