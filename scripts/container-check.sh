#!/usr/bin/env bash
# Builds the deformd image for real without a Docker engine (podman + a base image made by
# mmdebstrap; the shipped programs only, through the host's ccache), runs it the way
# docker/compose.yaml does (read-only root file system, every capability dropped,
# no-new-privileges, the port from DEFORMD_PORT, a phantom preloaded through DEFORMD_PRELOAD, an
# extra deformd flag after the image), checks that it listens on 0.0.0.0
# despite the extra flag, waits for its health check (which follows DEFORMD_PORT), load-tests it,
# checks that it runs as non-root and exits cleanly on SIGTERM, validates the compose file, and
# prints the image size. Exits non-zero on any failure with the reason on its last line.
#
# DEFORM_IMAGE (default localhost/deformd:check) and DEFORM_CHECK_PORT (default 50051) let two
# checks run side by side. DEFORM_IMAGE_FROM_BUILD=BUILD_DIR checks the image of an existing
# build instead (docker/Dockerfile's target `prebuilt`, staged by scripts/stage-prebuilt-image.sh:
# nothing compiled) with the same checks, and also that its deformd serves the browser viewer's
# page from the image (--http on 127.0.0.1:DEFORM_CHECK_PORT+1). CI (.ci/run) checks the full
# build's image.
set -uo pipefail
cd "$(dirname "$0")/.."

IMAGE="${DEFORM_IMAGE:-localhost/deformd:check}"
CONTAINER="deformd-check-$$"
PORT="${DEFORM_CHECK_PORT:-50051}"  # given to the container as DEFORMD_PORT
FROM_BUILD="${DEFORM_IMAGE_FROM_BUILD:-}"
HTTP_PORT=$((PORT + 1))
BASE_IMAGE="docker.io/library/debian:bookworm-slim"
WORK="$(mktemp -d)"

fail() {
  echo "container-check: FAILED: $*"
  exit 1
}
cleanup() {
  podman --runtime runc rm -f "$CONTAINER" >/dev/null 2>&1 || true
  rm -rf "$WORK"
}
trap cleanup EXIT
step() { echo "container-check: $*"; }

step "installing podman, runc, mmdebstrap and docker-compose if missing"
missing=()
for p in podman runc mmdebstrap docker-compose uidmap; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
      "${missing[@]}" >/dev/null || fail "could not install ${missing[*]}"
fi
PODMAN=(podman --runtime runc)
# Podman's default limits (1,048,576 open files) need CAP_SYS_RESOURCE to raise, which sandboxed
# machines like this one lack; explicit limits at or below the host's start everywhere.
RUN_FLAGS=(--network host --ulimit nofile=16384:16384 --ulimit nproc=16384:16384)

for port in "$PORT" ${FROM_BUILD:+"$HTTP_PORT"}; do
  if ss -ltn 2>/dev/null | grep -q ":$port "; then
    fail "port $port is in use on this host (the container runs with host networking)"
  fi
done

if ! "${PODMAN[@]}" image exists "$BASE_IMAGE"; then
  step "making the base image $BASE_IMAGE with mmdebstrap"
  mmdebstrap --variant=minbase --quiet bookworm "$WORK/base.tar" ||
    fail "mmdebstrap could not make a bookworm base"
  "${PODMAN[@]}" import "$WORK/base.tar" "$BASE_IMAGE" >/dev/null ||
    fail "podman could not import the base image"
fi

EXTRA_FLAGS=(--log-level debug)
build_start=$(date +%s)
if [ -n "$FROM_BUILD" ]; then
  # The existing build's programs and viewer files in the same runtime stage: nothing compiled.
  step "building $IMAGE from the build in $FROM_BUILD (target prebuilt)"
  scripts/stage-prebuilt-image.sh "$FROM_BUILD" "$WORK/context" >"$WORK/build.log" 2>&1 || {
    cat "$WORK/build.log"
    fail "could not stage the build in $FROM_BUILD"
  }
  "${PODMAN[@]}" build --isolation chroot --network host --format docker --target prebuilt \
    -f docker/Dockerfile -t "$IMAGE" "$WORK/context" >>"$WORK/build.log" 2>&1 || {
    tail -40 "$WORK/build.log"
    fail "image build failed (log above)"
  }
  EXTRA_FLAGS+=(--http "127.0.0.1:$HTTP_PORT")
else
  # The builder stage compiles the shipped programs only (DEFORM_IMAGE_TESTS=0: .ci/run has run the
  # suite on these sources with this compiler before) through the host's ccache, mounted at /ccache.
  CCACHE_HOST_DIR="${DEFORM_IMAGE_CCACHE:-$(ccache -k cache_dir 2>/dev/null || echo "$HOME/.cache/ccache")}"
  mkdir -p "$CCACHE_HOST_DIR" || fail "could not make the ccache directory $CCACHE_HOST_DIR"
  step "building $IMAGE (the shipped programs, through the ccache in $CCACHE_HOST_DIR)"
  "${PODMAN[@]}" build --isolation chroot --network host --format docker \
    --build-arg DEFORM_IMAGE_TESTS=0 --volume "$CCACHE_HOST_DIR:/ccache" \
    -f docker/Dockerfile -t "$IMAGE" . >"$WORK/build.log" 2>&1 || {
    tail -40 "$WORK/build.log"
    fail "image build failed (log above)"
  }
fi
step "image built in $(($(date +%s) - build_start)) s"

step "checking the runtime image holds no compiler and no -dev package"
inventory=$("${PODMAN[@]}" run --rm "${RUN_FLAGS[@]}" --entrypoint /bin/sh "$IMAGE" -c \
  'for c in gcc g++ cc c++ clang ld; do command -v $c; done
   dpkg-query -W -f="\${Package}\n" | grep -- "-dev$"
   echo inventory-complete') || fail "could not run a shell in the runtime image"
case "$inventory" in
  *inventory-complete) ;;
  *) fail "the runtime image inventory did not complete: $inventory" ;;
esac
leftovers=$(printf '%s\n' "$inventory" | grep -v '^inventory-complete$' || true)
[ -z "$leftovers" ] || fail "runtime image contains build tools or -dev packages: $leftovers"

step "starting the container hardened (read-only, no capabilities, no-new-privileges) with ${EXTRA_FLAGS[*]}"
"${PODMAN[@]}" run -d --name "$CONTAINER" "${RUN_FLAGS[@]}" --read-only --cap-drop=ALL \
  --security-opt=no-new-privileges -e DEFORMD_PORT="$PORT" -e DEFORMD_PRELOAD=phantom:500 \
  "$IMAGE" "${EXTRA_FLAGS[@]}" >/dev/null || fail "container did not start"

step "waiting for the health check to pass"
healthy=0
for _ in $(seq 1 60); do
  if "${PODMAN[@]}" healthcheck run "$CONTAINER" >/dev/null 2>&1; then healthy=1; break; fi
  sleep 1
done
[ "$healthy" = 1 ] || {
  "${PODMAN[@]}" logs "$CONTAINER" 2>&1 | tail -20
  fail "health check did not pass within 60 s"
}

step "checking that the extra flag kept the listen address and the preload"
logs=$("${PODMAN[@]}" logs "$CONTAINER" 2>&1)
printf '%s\n' "$logs" | grep -q "listening on 0.0.0.0:$PORT " ||
  fail "deformd does not listen on 0.0.0.0:$PORT: $(printf '%s\n' "$logs" | grep listening)"
printf '%s\n' "$logs" | grep -q "\[debug\]" || fail "the extra --log-level debug was not applied"
"${PODMAN[@]}" exec "$CONTAINER" deformd-healthcheck >/dev/null ||
  fail "the health check script does not reach port $PORT"

if [ -n "$FROM_BUILD" ]; then
  step "checking that deformd serves the viewer's page from the image"
  page=$(curl -sf "http://127.0.0.1:$HTTP_PORT/") || fail "no page on 127.0.0.1:$HTTP_PORT"
  printf '%s\n' "$page" | grep -q 'viewer.js' || fail "the page served is not the viewer's"
  curl -sf -o /dev/null "http://127.0.0.1:$HTTP_PORT/vendor/three.module.js" ||
    fail "the viewer's libraries are not served"
fi

step "checking the server process runs as non-root"
uid=$("${PODMAN[@]}" exec "$CONTAINER" awk '/^Uid:/ {print $2}' /proc/1/status)
[ -n "$uid" ] && [ "$uid" != 0 ] || fail "deformd runs as uid '${uid}'"

step "load-testing the container for 5 s (8 streams at 90 Hz on the phantom)"
"${PODMAN[@]}" exec "$CONTAINER" deform-loadtest --target "127.0.0.1:$PORT" --streams 8 \
  --rate 90 --duration 5 --json --fail-on-errors >"$WORK/load.json" ||
  fail "load test failed or counted errors: $(cat "$WORK/load.json")"
cat "$WORK/load.json"

step "sending SIGTERM and waiting up to 5 s for a clean exit"
start=$(date +%s.%N)
"${PODMAN[@]}" kill --signal TERM "$CONTAINER" >/dev/null || fail "could not signal the container"
code=$(timeout 6 "${PODMAN[@]}" wait "$CONTAINER") || fail "container still running 5 s after SIGTERM"
elapsed=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
[ "$code" = 0 ] || fail "deformd exited with code $code after SIGTERM"
step "exited 0 after SIGTERM in ${elapsed} s"

step "validating docker/compose.yaml"
docker-compose -f docker/compose.yaml config -q || fail "docker/compose.yaml is invalid"

size=$("${PODMAN[@]}" image inspect --format '{{.Size}}' "$IMAGE")
step "runtime image $IMAGE: $((size / 1000000)) MB"
echo "container-check: PASSED"
