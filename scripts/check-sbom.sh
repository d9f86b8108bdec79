#!/usr/bin/env bash
# Checks the SBOM (scripts/make-sbom.sh) without a build, in a few seconds:
# - its structure: CycloneDX 1.5, deformd at CMakeLists.txt's version, every component with a
#   name, version, purl and type, none twice, sorted; every package of
#   scripts/packages/runtime.txt present as direct at its installed version; the Debian packages
#   exactly the closure apt-cache resolves on its own; every package of
#   client/web/package-lock.json that is not dev: true present at its locked version;
# - its determinism: a second run, a second later and in another time zone, writes the same bytes;
# - its failures: a list naming a package that is not installed, and a missing lock file, each
#   make it fail and write nothing.
# Installs runtime.txt first (scripts/install-deps.sh): after scripts/run-tests.sh its packages are
# present already (build.txt's -dev packages depend on them), elsewhere perhaps not.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh scripts/packages/runtime.txt

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

scripts/make-sbom.sh "$WORK/sbom.json"
sleep 1
TZ=Pacific/Kiritimati scripts/make-sbom.sh "$WORK/again.json" >/dev/null
if ! cmp -s "$WORK/sbom.json" "$WORK/again.json"; then
  echo "check-sbom: two runs wrote different SBOMs:" >&2
  diff "$WORK/sbom.json" "$WORK/again.json" | head -20 >&2
  exit 1
fi
echo "check-sbom: two runs wrote the same bytes"

python3 - "$WORK/sbom.json" scripts/packages/runtime.txt client/web/package-lock.json <<'PY'
import json, re, subprocess, sys
from urllib.parse import unquote

path, runtime_list, npm_lock = sys.argv[1:]
bom = json.load(open(path))
errors = []
def check(condition, message):
    if not condition:
        errors.append(message)

check(bom.get("bomFormat") == "CycloneDX", "bomFormat is not CycloneDX")
check(bom.get("specVersion") == "1.5", "specVersion is not 1.5")
check(re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", bom["metadata"].get("timestamp", "")),
      "metadata.timestamp is not an ISO 8601 UTC time")
version = re.search(r"project\(\s*deformd\s+VERSION\s+([0-9.]+)", open("CMakeLists.txt").read())[1]
root = bom["metadata"]["component"]
check((root.get("name"), root.get("version")) == ("deformd", version),
      f"metadata.component is not deformd {version}")
check(root.get("licenses") == [{"license": {"id": "Apache-2.0"}}],
      "deformd's licence is not Apache-2.0")

components = bom.get("components", [])
deb, npm, refs = {}, {}, {root.get("bom-ref")}
for c in components:
    label = c.get("purl") or c.get("name") or repr(c)
    absent = [f for f in ("name", "version", "purl", "type", "bom-ref")
              if not isinstance(c.get(f), str) or not c[f]]
    check(not absent, f"{label}: no {', '.join(absent)}")
    if absent:
        continue
    check(c["bom-ref"] not in refs, f"{label}: twice")
    refs.add(c["bom-ref"])
    kind = dict((p["name"], p["value"]) for p in c.get("properties", [])).get("deformd:dependency")
    check(kind in ("direct", "transitive"), f"{label}: neither direct nor transitive")
    match = re.fullmatch(r"pkg:(deb|npm)/(?:debian/)?(.+)@([^?]+)(\?.*)?", c["purl"])
    check(match and unquote(match[2]) == c["name"] and unquote(match[3]) == c["version"],
          f"{label}: the purl does not name {c['name']} {c['version']}")
    if match:
        ecosystem = deb if match[1] == "deb" else npm
        check(c["name"] not in ecosystem, f"{label}: {c['name']} twice")
        ecosystem[c["name"]] = (c["version"], kind)
check([c.get("purl") for c in components] == sorted(c.get("purl") for c in components),
      "components are not sorted by purl")
for d in bom.get("dependencies", []):
    check({d["ref"], *d["dependsOn"]} <= refs, f"dependencies: {d['ref']} names an unknown ref")

lines = (line.split() for line in open(runtime_list))  # as scripts/install-deps.sh reads them
listed = [words[0] for words in lines if words and not words[0].startswith("#")]
query = subprocess.run(["dpkg-query", "-W", "-f", "${Package} ${Version}\n", *listed],
                       capture_output=True, text=True).stdout
installed = dict(line.split(" ", 1) for line in query.splitlines())
for p in listed:
    check(deb.get(p) == (installed.get(p), "direct"),
          f"{p} (runtime.txt): {deb.get(p)} in the SBOM, installed {installed.get(p)}")
check({p for p, (_, kind) in deb.items() if kind == "direct"} == set(listed),
      "direct Debian packages other than runtime.txt's")
apt = subprocess.run(["apt-cache", "depends", "--recurse", "--installed", "--no-recommends",
                      "--no-suggests", "--no-conflicts", "--no-breaks", "--no-replaces",
                      "--no-enhances", *listed], check=True, capture_output=True, text=True).stdout
closure = {line for line in apt.splitlines() if line[:1] not in (" ", "<")}
check(set(deb) == closure, f"Debian packages differ from apt-cache's closure: "
      f"only in the SBOM {sorted(set(deb) - closure)}, "
      f"only apt-cache's {sorted(closure - set(deb))}")

for key, entry in json.load(open(npm_lock))["packages"].items():
    if key and not entry.get("dev") and not entry.get("link"):
        name = entry.get("name") or key.rsplit("node_modules/", 1)[1]
        check(npm.get(name, (None,))[0] == entry["version"],
              f"npm {name} {entry['version']} missing")

for e in errors:
    print(f"check-sbom: {e}", file=sys.stderr)
if errors:
    sys.exit(1)
print(f"check-sbom: structure right: {len(deb)} Debian packages ({len(listed)} direct), "
      f"{len(npm)} npm packages, deformd {version}")
PY

# The failures it must report: a listed package that is not installed, a missing lock file.
cp scripts/packages/runtime.txt "$WORK/runtime.txt"
echo "deformd-no-such-package" >>"$WORK/runtime.txt"
if DEFORM_SBOM_RUNTIME_LIST="$WORK/runtime.txt" scripts/make-sbom.sh "$WORK/bogus.json" \
     >/dev/null 2>"$WORK/bogus.err" || [ -e "$WORK/bogus.json" ] ||
   ! grep -q "deformd-no-such-package" "$WORK/bogus.err"; then
  echo "check-sbom: a package that is not installed did not fail make-sbom.sh" >&2
  exit 1
fi
if DEFORM_SBOM_NPM_LOCK="$WORK/no-such-lock.json" scripts/make-sbom.sh "$WORK/nolock.json" \
     >/dev/null 2>&1 || [ -e "$WORK/nolock.json" ]; then
  echo "check-sbom: a missing lock file did not fail make-sbom.sh" >&2
  exit 1
fi
echo "check-sbom: a package not installed and a missing lock file each fail it"
