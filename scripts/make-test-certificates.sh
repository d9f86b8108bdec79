#!/usr/bin/env bash
# Makes a throw-away certificate authority and certificates for trying TLS and mutual TLS locally
# and for the tests (openssl, scripts/packages/build.txt). NOT for production: keys unencrypted,
# valid 30 days.
#
#   scripts/make-test-certificates.sh DIR [SERVER_NAME]
#
# Writes into DIR (created 0700): ca.pem/ca.key (the CA), server.pem/server.key (for SERVER_NAME,
# default localhost, plus 127.0.0.1 and ::1), client.pem/client.key (a client certificate signed
# by the CA, CN deform-client), and other-ca.pem with other-client.pem/other-client.key (a second
# CA and a client it signed, which a server trusting ca.pem must refuse), and expired.pem with
# expired.key (a server certificate of the CA for the same names, valid only in January 2020, which
# deformd must refuse to serve). Exits non-zero with the reason on stderr.
set -euo pipefail
dir=${1:?usage: make-test-certificates.sh DIR [SERVER_NAME]}
name=${2:-localhost}
mkdir -p "$dir"
chmod 700 "$dir"
cd "$dir"
umask 077
ec=(-newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes)
make_ca() {  # name
  openssl req -x509 "${ec[@]}" -keyout "$1.key" -out "$1.pem" -days 30 -subj "/CN=deformd test $1" \
    2>/dev/null
}
sign() {  # name ca common-name extensions
  openssl req "${ec[@]}" -keyout "$1.key" -out "$1.csr" -subj "/CN=$3" 2>/dev/null
  printf '%s\n' "$4" >"$1.ext"
  openssl x509 -req -in "$1.csr" -CA "$2.pem" -CAkey "$2.key" -CAcreateserial -out "$1.pem" \
    -days 30 -extfile "$1.ext" 2>/dev/null
  rm -f "$1.csr" "$1.ext"
}
make_ca ca
make_ca other-ca
sign server ca "$name" "subjectAltName=DNS:$name,DNS:localhost,IP:127.0.0.1,IP:::1
extendedKeyUsage=serverAuth"
sign client ca deform-client "extendedKeyUsage=clientAuth"
sign other-client other-ca deform-other-client "extendedKeyUsage=clientAuth"
# A certificate outside its validity needs explicit dates, which only `openssl ca` sets.
dated() {  # name ca start end extensions
  mkdir -p "$1-ca"
  : >"$1-ca/index.txt"
  echo 1000 >"$1-ca/serial"
  printf '%s\n' "[ca]" "default_ca = dated" "[dated]" 'dir = '"$1"'-ca' \
    'database = $dir/index.txt' 'new_certs_dir = $dir' 'serial = $dir/serial' \
    "default_md = sha256" "policy = anything" "unique_subject = no" \
    "[anything]" "commonName = supplied" >"$1-ca/ca.cnf"
  printf '%s\n' "$5" >"$1.ext"
  openssl req "${ec[@]}" -keyout "$1.key" -out "$1.csr" -subj "/CN=$name" 2>/dev/null
  openssl ca -batch -config "$1-ca/ca.cnf" -cert "$2.pem" -keyfile "$2.key" -in "$1.csr" \
    -out "$1.pem" -startdate "$3" -enddate "$4" -extfile "$1.ext" -notext 2>/dev/null
  rm -rf "$1-ca" "$1.csr" "$1.ext"
}
dated expired ca 20200101000000Z 20200201000000Z "subjectAltName=DNS:$name,DNS:localhost,IP:127.0.0.1,IP:::1
extendedKeyUsage=serverAuth"
rm -f ./*.srl
echo "certificates in $dir"
