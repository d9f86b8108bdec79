#!/usr/bin/env bash
# Checks the layering of the core (server/core/CMakeLists.txt) and of the service
# (server/service/CMakeLists.txt): every #include of a core or service header points to the
# file's own layer or one it may use, no source file sits outside a layer's folder, the core
# includes nothing of the service, headers under a layer's internal/ folder are included only from
# inside that layer, the core includes no gRPC or Protobuf, and (given the deformd
# binary and the eval library) deformd defines none of the functions the eval library defines.
# Exits 1 naming each violation.
set -euo pipefail
cd "$(dirname "$0")/.."
DEFORMD="${1:-}"
EVAL_LIBRARY="${2:-}"

# One layered tree: every #include "<prefix>/<layer>/..." in a file under <root>/<layer>/ must name
# a layer that $2's table allows for the file's own layer. A file outside every layer's folder
# fails too.
status=0
check_layers() {  # ROOT PREFIX TABLE-NAME (an associative array: layer -> the layers it may use)
  local root=$1 prefix=$2 file layer target used
  local -n allowed=$3
  while IFS= read -r -d '' file; do
    layer=$(echo "${file#"$root"/}" | cut -s -d/ -f1)
    if [ -z "$layer" ] || [ -z "${allowed[$layer]+set}" ]; then
      [ "$(basename "$file")" = CMakeLists.txt ] && continue
      echo "check-layers: $file is in no layer of $root (its CMakeLists.txt and this script list them)"
      status=1; continue
    fi
    while IFS= read -r target; do
      used=$(echo "$target" | cut -d/ -f2)
      case " ${allowed[$layer]} " in
        *" $used "*) ;;
        *) echo "check-layers: $file includes $target ($prefix/$layer may not use $used)"; status=1 ;;
      esac
    done < <(grep -oE "#include \"$prefix/[a-z_]+/[^\"]+\"" "$file" | sed -E 's/#include "(.*)"/\1/')
  done < <(find "$root" \( -name '*.h' -o -name '*.cc' \) -print0 | sort -z)
}

# The core's layers (server/core/CMakeLists.txt), itself included in each.
declare -A CORE_LAYERS=(
  [base]="base"
  [geometry]="base geometry"
  [io]="base geometry io"
  [solver]="base solver"
  [model]="base geometry solver model"
  [constraints]="base geometry solver model constraints"
  [eval]="base geometry solver model constraints eval"
  [codec]="base codec"
)
check_layers server/core core CORE_LAYERS
# The service's layers (server/service/CMakeLists.txt); each may include the core and the proto.
declare -A SERVICE_LAYERS=(
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
  [contact]="base metrics access workers registry transport messages context contact"
  [rpc]="base metrics access workers registry transport messages context load deform contact rpc"
)
check_layers server/service service SERVICE_LAYERS

# The numerical core: no gRPC, no Protobuf, nothing of the service.
while IFS= read -r hit; do
  echo "check-layers: ${hit%%:*} (numerical core) includes gRPC, Protobuf or the service: ${hit#*:}"
  status=1
done < <(grep -rnE '#include <(grpc|grpcpp|google/protobuf)/|\.pb\.h"|#include "service/' \
  server/core 2>/dev/null || true)

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
