#!/usr/bin/env bash
# The gRPC port's TLS against the BCP 195 profile that DICOM PS3.15 (Annex B, "BCP 195 RFC 8996,
# 9325 TLS Secure Transport Connection Profile") asks of medical devices: a real deformd serving
# an ECDSA P-256 and then an RSA 2048 certificate, scanned by sslscan (Debian's, run as a tool, not
# linked) and asked by openssl s_client which protocol it chooses. Prints the conformance table
# (docs/tls-profile.md holds a copy) and exits non-zero when a row fails.
#
#   scripts/check-tls-profile.sh [DEFORMD]      (default build/server/deformd/deformd)
set -euo pipefail
cd "$(dirname "$0")/.."
DEFORMD="${1:-build/server/deformd/deformd}"
[ -x "$DEFORMD" ] || { echo "check-tls-profile: no deformd at $DEFORMD (build first)" >&2; exit 1; }
scripts/install-deps.sh scripts/packages/checks.txt >/dev/null

WORK=$(mktemp -d)
server_pid=""
cleanup() {
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT

bash scripts/make-test-certificates.sh "$WORK/ec" >/dev/null
mkdir -p "$WORK/rsa"
openssl req -x509 -newkey rsa:2048 -nodes -keyout "$WORK/rsa/server.key" \
  -out "$WORK/rsa/server.pem" -days 30 -subj /CN=localhost \
  -addext "subjectAltName=DNS:localhost,IP:127.0.0.1" 2>/dev/null

# Scans deformd serving KIND's certificate into $WORK/KIND.xml and $WORK/KIND.protocol.
scan() {  # KIND
  "$DEFORMD" --listen 127.0.0.1:0 --tls-cert "$WORK/$1/server.pem" \
    --tls-key "$WORK/$1/server.key" >"$WORK/$1.log" 2>&1 &
  server_pid=$!
  local address=""
  for _ in $(seq 1 100); do
    address=$(sed -n 's/.*listening on \(127\.0\.0\.1:[0-9]*\) (TLS).*/\1/p' "$WORK/$1.log")
    [ -n "$address" ] && break
    sleep 0.1
  done
  [ -n "$address" ] || { cat "$WORK/$1.log" >&2; echo "check-tls-profile: deformd did not start" >&2; exit 1; }
  sslscan --no-colour --xml="$WORK/$1.xml" "$address" >/dev/null 2>&1 ||
    { echo "check-tls-profile: sslscan failed against $address" >&2; exit 1; }
  # The protocol a client offering every version is given.
  openssl s_client -connect "$address" -brief </dev/null 2>&1 |
    sed -n 's/^Protocol version: *//p' >"$WORK/$1.protocol" || true
  kill "$server_pid"
  wait "$server_pid" 2>/dev/null || true
  server_pid=""
}
scan ec
scan rsa

python3 - "$WORK" <<'PY'
import sys
import xml.etree.ElementTree as ET

work = sys.argv[1]
# RFC 9325 section 4.2: TLS 1.2 suites with forward secrecy and AEAD (AES-GCM; ChaCha20-Poly1305,
# also AEAD with ephemeral keys, is accepted here and named in the table). RFC 8446: any TLS 1.3
# suite.
TLS12 = {
    "ECDHE-ECDSA-AES128-GCM-SHA256", "ECDHE-ECDSA-AES256-GCM-SHA384",
    "ECDHE-RSA-AES128-GCM-SHA256", "ECDHE-RSA-AES256-GCM-SHA384",
    "DHE-RSA-AES128-GCM-SHA256", "DHE-RSA-AES256-GCM-SHA384",
    "ECDHE-ECDSA-CHACHA20-POLY1305", "ECDHE-RSA-CHACHA20-POLY1305",
}
TLS13 = {"TLS_AES_128_GCM_SHA256", "TLS_AES_256_GCM_SHA384", "TLS_CHACHA20_POLY1305_SHA256",
         "TLS_AES_128_CCM_SHA256"}

def rows(kind):
    test = ET.parse(f"{work}/{kind}.xml").getroot().find("ssltest")
    enabled = {(p.get("type"), p.get("version")): p.get("enabled") == "1"
               for p in test.findall("protocol")}
    ciphers = [(c.get("sslversion"), c.get("cipher")) for c in test.findall("cipher")]
    reneg = test.find("renegotiation")
    heartbleed = [h.get("vulnerable") == "1" for h in test.findall("heartbleed")]
    pk = test.find("certificates/certificate/pk")
    signature = test.findtext("certificates/certificate/signature-algorithm", "")
    chosen = open(f"{work}/{kind}.protocol").read().strip()
    tls12 = sorted(c for v, c in ciphers if v == "TLSv1.2")
    tls13 = sorted(c for v, c in ciphers if v == "TLSv1.3")
    bits = int(pk.get("bits", "0"))
    key_ok = (pk.get("type") == "EC" and bits >= 128) or (pk.get("type") == "RSA" and bits >= 2048)
    return [
        ("SSL 2.0 and 3.0 refused", not enabled[("ssl", "2")] and not enabled[("ssl", "3")], ""),
        ("TLS 1.0 and 1.1 refused (RFC 8996)",
         not enabled[("tls", "1.0")] and not enabled[("tls", "1.1")], ""),
        ("TLS 1.2 accepted", enabled[("tls", "1.2")], ""),
        ("TLS 1.3 accepted and chosen when offered", enabled[("tls", "1.3")] and chosen == "TLSv1.3",
         f"chosen: {chosen or 'none'}"),
        ("TLS 1.2 suites: ephemeral keys and AEAD only (RFC 9325 4.2)",
         bool(tls12) and all(c in TLS12 for c in tls12), ", ".join(tls12)),
        ("TLS 1.3 suites: RFC 8446's", bool(tls13) and all(c in TLS13 for c in tls13),
         ", ".join(tls13)),
        ("no renegotiation, or only secure renegotiation",
         reneg.get("supported") == "0" or reneg.get("secure") == "1", ""),
        ("not vulnerable to Heartbleed", not any(heartbleed), ""),
        ("key: EC of 256 bits or more, or RSA of 2048 or more", key_ok,
         f"{pk.get('type')} {pk.get('curve_name', '')} {bits} bits".replace("  ", " ")),
        ("certificate signed with SHA-256 or stronger",
         any(h in signature.lower() for h in ("sha256", "sha384", "sha512")), signature),
    ]

ec, rsa = rows("ec"), rows("rsa")
print("| BCP 195 (RFC 8996, RFC 9325) | ECDSA P-256 certificate | RSA 2048 certificate |")
print("|---|---|---|")
failed = 0
for (name, ok_ec, note_ec), (_, ok_rsa, note_rsa) in zip(ec, rsa):
    cell = lambda ok, note: ("yes" if ok else "**NO**") + (f": {note}" if note else "")
    print(f"| {name} | {cell(ok_ec, note_ec)} | {cell(ok_rsa, note_rsa)} |")
    failed += (not ok_ec) + (not ok_rsa)
if failed:
    print(f"check-tls-profile: FAILED: {failed} rows", file=sys.stderr)
    sys.exit(1)
print("check-tls-profile: PASSED")
PY
