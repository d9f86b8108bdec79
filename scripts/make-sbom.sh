#!/usr/bin/env bash
# Writes the Software Bill of Materials of what deformd ships, as CycloneDX 1.5 JSON:
# - the Debian packages of the image's runtime stage: scripts/packages/runtime.txt (what
#   docker/Dockerfile's runtime stage installs) and the packages their Depends and Pre-Depends
#   pull in, recursively, each at the version installed on this machine (Debian 12, the image's
#   distribution), with the licences of its DEP-5 copyright file (none where the file is not
#   machine-readable: nothing is guessed); a property tells direct from transitive;
# - the npm packages of the browser viewer: client/web/package-lock.json's packages that are
#   not dev: true (three, meshoptimizer, @bufbuild/protobuf: the build copies them into
#   build/server/deformd/web/vendor; the viewer has no bundler, and the image does not hold it);
# - deformd itself as metadata.component (the version of CMakeLists.txt's project()).
# Deterministic: sorted components, the time of SOURCE_DATE_EPOCH or else of the last commit,
# never the clock, so two runs on the same machine and commit write the same bytes. Reads only
# local files and dpkg's database, nothing from the network. Fails, writing nothing, when a listed
# package is not installed or the lock file is missing. DEFORM_SBOM_RUNTIME_LIST and
# DEFORM_SBOM_NPM_LOCK point it at another list or lock file (scripts/check-sbom.sh does).
#
#   scripts/make-sbom.sh [OUT]      (default build/sbom/deformd.cdx.json)
set -euo pipefail
OUT="$(realpath -m "${1:-$(dirname "$0")/../build/sbom/deformd.cdx.json}")"
RUNTIME_LIST="$(realpath -m "${DEFORM_SBOM_RUNTIME_LIST:-$(dirname "$0")/packages/runtime.txt}")"
NPM_LOCK="$(realpath -m "${DEFORM_SBOM_NPM_LOCK:-$(dirname "$0")/../client/web/package-lock.json}")"
cd "$(dirname "$0")/.."

[ -f "$RUNTIME_LIST" ] || { echo "make-sbom: no package list $RUNTIME_LIST" >&2; exit 1; }
[ -f "$NPM_LOCK" ] || { echo "make-sbom: no lock file $NPM_LOCK (client/web's)" >&2; exit 1; }
if [ -n "${SOURCE_DATE_EPOCH:-}" ]; then
  when="@$SOURCE_DATE_EPOCH"
else
  when=$(git log -1 --format=%cI) ||
    { echo "make-sbom: no commit date (set SOURCE_DATE_EPOCH)" >&2; exit 1; }
fi
timestamp=$(date -u -d "$when" +%Y-%m-%dT%H:%M:%SZ)

mkdir -p "$(dirname "$OUT")"
python3 - "$RUNTIME_LIST" "$NPM_LOCK" "$timestamp" "$OUT" <<'PY'
import base64, json, os, re, subprocess, sys
from urllib.parse import quote

runtime_list, npm_lock, timestamp, out = sys.argv[1:]

def fail(message):
    print(f"make-sbom: {message}", file=sys.stderr)
    sys.exit(1)

def purl_part(text):
    # purl percent-encodes all but unreserved characters; ':' stays as is (the purl spec), '+'
    # is %2B (a URL parser may read a bare '+' as a space).
    return quote(text, safe=":")

def prop(name, value):
    return {"name": f"deformd:{name}", "value": value}

# --- Debian: runtime.txt as scripts/install-deps.sh reads it (first word, '#' comments).
direct = []
with open(runtime_list) as f:
    for line in f:
        words = line.split()
        if words and not words[0].startswith("#"):
            direct.append(words[0])

native = subprocess.run(["dpkg", "--print-architecture"], check=True, capture_output=True,
                        text=True).stdout.strip()
fields = "\t".join(["${Package}", "${Version}", "${Architecture}", "${db:Status-Abbrev}",
                    "${Pre-Depends}", "${Depends}", "${Provides}"]) + "\n"
listing = subprocess.run(["dpkg-query", "-W", "-f", fields], check=True, capture_output=True,
                         text=True).stdout
installed, providers = {}, {}
for row in listing.splitlines():
    name, version, arch, status, pre, deps, provides = row.split("\t")
    # Installed for this machine's architecture (or all): what a Depends without a qualifier names.
    if not status.startswith("ii") or arch not in (native, "all"):
        continue
    installed[name] = {"version": version, "arch": arch,
                       "depends": ", ".join(d for d in (pre, deps) if d)}
    for virtual in provides.split(","):
        if virtual.strip():
            providers.setdefault(virtual.split()[0], []).append(name)

missing = [p for p in direct if p not in installed]
if missing:
    fail(f"not installed: {' '.join(missing)} (listed in {runtime_list}; "
         f"scripts/install-deps.sh {runtime_list} installs them)")

def satisfier(clause):
    # The package that satisfies one Depends clause, "a (>= 1) | b:any | c": the first
    # alternative installed by name, else by the first of its providers in name order (dpkg has
    # checked the version constraints, so they are not compared here).
    for alternative in clause.split("|"):
        name = alternative.split("(")[0].strip().split(":")[0]
        if name in installed:
            return name
        if providers.get(name):
            return sorted(providers[name])[0]
    fail(f"no installed package satisfies '{clause.strip()}'")

deb_deps, todo = {}, list(direct)
while todo:
    name = todo.pop()
    if name in deb_deps:
        continue
    clauses = [c for c in installed[name]["depends"].split(",") if c.strip()]
    deb_deps[name] = sorted({satisfier(c) for c in clauses} - {name})
    todo.extend(deb_deps[name])

def deb_licenses(name):
    # The short names of the License: fields of a DEP-5 (machine-readable) copyright file, as
    # Debian writes them (not always SPDX identifiers); none for a free-form file.
    try:
        with open(f"/usr/share/doc/{name}/copyright", encoding="utf-8", errors="replace") as f:
            text = f.read()
    except OSError:
        return []
    if not re.match(r"Format:\s*\S*copyright-format/1\.0", text.lstrip(), re.I):  # DEP-5
        return []
    names = {" ".join(m.split()) for m in re.findall(r"^License:[ \t]*(\S.*)$", text, re.M | re.I)}
    return [{"license": {"name": n}} for n in sorted(names)]

def deb_purl(name):
    p = installed[name]
    return (f"pkg:deb/debian/{purl_part(name)}@{purl_part(p['version'])}"
            f"?arch={p['arch']}&distro=debian-12")

components, dependencies = [], {}
for name in deb_deps:
    component = {"type": "library", "bom-ref": deb_purl(name), "name": name,
                 "version": installed[name]["version"], "purl": deb_purl(name)}
    if licenses := deb_licenses(name):
        component["licenses"] = licenses
    component["properties"] = [
        prop("dependency", "direct" if name in direct else "transitive"),
        prop("shipped-in", "container image (runtime stage)")]
    components.append(component)
    dependencies[deb_purl(name)] = [deb_purl(d) for d in deb_deps[name]]

# --- npm: the lock file's packages (lockfileVersion 2 or 3: the "packages" map) that are not
# dev: true, i.e. the root's dependencies and what they pull in.
with open(npm_lock) as f:
    lock = json.load(f)
if "packages" not in lock:
    fail(f"{npm_lock} has no 'packages' (lockfileVersion {lock.get('lockfileVersion')}: "
         "2 or 3 needed)")
packages = lock["packages"]
web_dir = os.path.dirname(npm_lock)

def npm_name(path, entry):
    return entry.get("name") or path.rsplit("node_modules/", 1)[1]

def npm_purl(path):
    # A scope is the purl's namespace: @scope/name is pkg:npm/%40scope/name.
    name = "/".join(purl_part(part) for part in npm_name(path, packages[path]).split("/"))
    return f"pkg:npm/{name}@{purl_part(packages[path]['version'])}"

def npm_resolve(path, dep):
    # Node's lookup: DEP in PATH's own node_modules, then in each enclosing one.
    base = path
    while True:
        candidate = f"{base}/node_modules/{dep}" if base else f"node_modules/{dep}"
        if candidate in packages:
            return candidate
        if not base:
            return None
        base = base.rsplit("/node_modules/", 1)[0] if "/node_modules/" in base else ""

def npm_license(path, entry):
    # The lock file's license, else the installed package.json's if it is the locked version.
    if entry.get("license"):
        return entry["license"]
    try:
        with open(os.path.join(web_dir, path, "package.json")) as f:
            manifest = json.load(f)
    except (OSError, ValueError):
        return None
    found = manifest.get("license")
    return found if isinstance(found, str) and manifest.get("version") == entry["version"] else None

root = packages.get("", {})
npm_direct = set(root.get("dependencies", {})) | set(root.get("optionalDependencies", {}))
root_refs = [deb_purl(p) for p in direct]
for path, entry in packages.items():
    if not path or entry.get("dev") or entry.get("link"):
        continue
    name = npm_name(path, entry)
    component = {"type": "library", "bom-ref": npm_purl(path), "name": name,
                 "version": entry["version"], "purl": npm_purl(path)}
    algorithm, _, digest = entry.get("integrity", "").partition("-")
    if algorithm == "sha512":
        component["hashes"] = [{"alg": "SHA-512", "content": base64.b64decode(digest).hex()}]
    if license := npm_license(path, entry):
        component["licenses"] = [{"expression": license}]
    top = path.count("node_modules/") == 1 and name in npm_direct
    component["properties"] = [
        prop("dependency", "direct" if top else "transitive"),
        prop("shipped-in", "browser viewer (build/server/deformd/web; not in the image)")]
    components.append(component)
    if top:
        root_refs.append(npm_purl(path))
    wanted = {**entry.get("dependencies", {}), **entry.get("optionalDependencies", {})}
    dependencies[npm_purl(path)] = [npm_purl(r) for d in wanted if (r := npm_resolve(path, d))]

# --- deformd itself.
with open("CMakeLists.txt") as f:
    match = re.search(r"project\(\s*deformd\s+VERSION\s+([0-9.]+)", f.read())
if not match:
    fail("no project(deformd VERSION ...) in CMakeLists.txt")
version = match.group(1)
dependencies["deformd"] = root_refs

bom = {
    "bomFormat": "CycloneDX",
    "specVersion": "1.5",
    "version": 1,
    "metadata": {
        "timestamp": timestamp,
        "component": {"type": "application", "bom-ref": "deformd", "name": "deformd",
                      "version": version, "purl": f"pkg:generic/deformd@{version}",
                      "licenses": [{"license": {"id": "Apache-2.0"}}]},
        "properties": [
            prop("deb-selection", "scripts/packages/runtime.txt and its Depends/Pre-Depends "
                 "closure, as installed here; not listed: the base image's other packages and "
                 "the header-only libraries compiled into the programs"),
            prop("npm-selection", "client/web/package-lock.json without dev: true"),
        ],
    },
    "components": sorted(components, key=lambda c: c["purl"]),
    "dependencies": [{"ref": ref, "dependsOn": sorted(set(refs))}
                     for ref, refs in sorted(dependencies.items())],
}
with open(out + ".tmp", "w") as f:  # then renamed: a failed run leaves no partial file
    json.dump(bom, f, indent=2)
    f.write("\n")
os.replace(out + ".tmp", out)
npm_count = sum(c["purl"].startswith("pkg:npm/") for c in components)
print(f"make-sbom: {len(components) - npm_count} Debian and {npm_count} npm packages in {out}")
PY
