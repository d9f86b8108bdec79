#!/usr/bin/env bash
# Checks the layering of the core (server/core/CMakeLists.txt) and of the service
# (server/service/CMakeLists.txt): every #include of a core or service header points to the
# file's own layer or one it may use, no source file sits at the top of server/service, the core
# includes nothing of the service, headers under a layer's internal/ folder are included only from
# inside that layer, the core includes no gRPC or Protobuf, and (given the deformd
# binary and the eval library) deformd defines none of the functions the eval library defines.
# Exits 1 naming each violation.
set -euo pipefail
cd "$(dirname "$0")/.."
DEFORMD="${1:-}"
EVAL_LIBRARY="${2:-}"

# layer -> the layers it may include (itself included)
declare -A ALLOWED=(
  [base]="base"
  [geometry]="base geometry"
  [io]="base geometry io"
  [solver]="base solver"
  [model]="base geometry solver model"
  [eval]="base geometry solver model eval"
  [codec]="base codec"
)
status=0
while IFS= read -r -d '' file; do
  layer=$(echo "$file" | cut -d/ -f3)
  while IFS= read -r target; do
    used=$(echo "$target" | cut -d/ -f2)
    case " ${ALLOWED[$layer]} " in
      *" $used "*) ;;
      *) echo "check-layers: $file includes $target ($layer may not use $used)"; status=1 ;;
    esac
  done < <(grep -oE '#include "core/[a-z_]+/[^"]+"' "$file" | sed -E 's/#include "(.*)"/\1/')
  if grep -qE '#include <(grpc|grpcpp|google/protobuf)/|\.pb\.h"' "$file"; then
    echo "check-layers: $file (numerical core) includes gRPC or Protobuf"; status=1
  fi
done < <(find server/core \( -name '*.h' -o -name '*.cc' \) -print0 | sort -z)

# The service's layers -> the service layers each may include (itself included); every service
# layer may include the core and the proto.
declare -A SERVICE_ALLOWED=(
  [base]="base"
  [metrics]="base metrics"
  [access]="base access"
  [workers]="base workers"
  [registry]="base access workers registry"
  [transport]="base transport"
  [messages]="base access workers registry messages"
  [context]="base metrics access workers registry context"
  [load]="base metrics access workers registry transport messages context load"
  [deform]="base metrics access workers registry transport messages context deform"
  [rpc]="base metrics access workers registry transport messages context load deform rpc"
)
while IFS= read -r -d '' file; do
  layer=$(echo "$file" | cut -d/ -f3)
  if [ "$(echo "$file" | tr -cd / | wc -c)" -lt 3 ]; then
    echo "check-layers: $file sits at the top of server/service (put it in a layer's folder)"
    status=1; continue
  fi
  if [ -z "${SERVICE_ALLOWED[$layer]+set}" ]; then
    echo "check-layers: $file is in server/service/$layer, which is no layer" \
      "(server/service/CMakeLists.txt and this script list them)"; status=1; continue
  fi
  while IFS= read -r target; do
    used=$(echo "$target" | cut -d/ -f2)
    case " ${SERVICE_ALLOWED[$layer]} " in
      *" $used "*) ;;
      *) echo "check-layers: $file includes $target (service/$layer may not use $used)"; status=1 ;;
    esac
  done < <(grep -oE '#include "service/[^"]+"' "$file" | sed -E 's/#include "(.*)"/\1/')
done < <(find server/service \( -name '*.h' -o -name '*.cc' \) -print0 | sort -z)
while IFS= read -r hit; do
  echo "check-layers: ${hit%%:*} (numerical core) includes the service: ${hit#*:}"; status=1
done < <(grep -rnE '#include "service/' server/core 2>/dev/null || true)

# internal/ headers: only from their own layer's folder.
while IFS= read -r hit; do
  file=${hit%%:*}
  echo "check-layers: $file includes another layer's internal header: ${hit#*:}"; status=1
done < <(grep -rnE '#include "core/[a-z_]+/internal/' server client tests bench 2>/dev/null || true)

if [ -n "$DEFORMD" ]; then
  [ -f "$EVAL_LIBRARY" ] || { echo "check-layers: give the eval library after deformd"; exit 2; }
  symbols=$(nm -C --defined-only "$DEFORMD" 2>/dev/null | awk '$2 ~ /^[TW]$/ { $1 = ""; $2 = ""; print }')
  if ! grep -q 'deform::DeformationModel::Build' <<<"$symbols"; then
    echo "check-layers: $DEFORMD has no symbol table to check (stripped?)"; status=1
  fi
  # Every function the evaluation layer defines must be absent from deformd.
  eval_symbols=$(nm -C --defined-only "$EVAL_LIBRARY" | awk '$2 == "T" { $1 = ""; $2 = ""; print }')
  linked=$(grep -Fxf <(sort -u <<<"$eval_symbols") <(sort -u <<<"$symbols") || true)
  if [ -n "$linked" ]; then
    echo "check-layers: $DEFORMD links evaluation code (core/eval):"
    head -5 <<<"$linked"; status=1
  fi
fi
[ "$status" = 0 ] && echo "check-layers: ok"
exit "$status"
