#!/usr/bin/env bash
# The API's checks: `buf lint` (STANDARD rules, proto/buf.yaml) and `buf breaking` against the
# commit that completed deform.v1 (its hash in proto/v1-baseline-commit), so that additions pass
# and breaking changes fail. Installs buf from proto/package-lock.json first (install-node-tools).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-node-tools.sh
BUF=proto/node_modules/.bin/buf

"$BUF" lint proto
echo "check-proto: buf lint passed"

baseline=$(grep -v '^#' proto/v1-baseline-commit | tr -d '[:space:]')
if ! git cat-file -e "${baseline}^{commit}" 2>/dev/null; then
  echo "check-proto: the v1 baseline commit $baseline is not in this clone (a shallow clone?)" >&2
  exit 1
fi
"$BUF" breaking proto --against ".git#ref=${baseline},subdir=proto"
echo "check-proto: buf breaking passed against v1 (${baseline:0:12})"
