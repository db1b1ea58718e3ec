#!/bin/sh
# Generate a development CA and TLS certificates for linecrew's secured Zenoh
# profile (mutual TLS + access control), then render the matching Zenoh
# configs.
#
#   deploy/tls/gen-dev-ca.sh [N_UAVS [OUT_DIR]]      (defaults: 3, deploy/tls/out)
#
# OUT_DIR receives:
#   ca.pem, ca.key                  the dev CA (ca.key never leaves this machine)
#   router.pem, router.key          server cert, SAN localhost, 127.0.0.1, ::1, router
#   https.pem, https.key            the gateway's HTTPS server cert, SAN localhost,
#                                   127.0.0.1, ::1 (HTTPS_SANS="DNS:ops.example" adds)
#   <identity>.pem, <identity>.key  client certs, CN = identity:
#                                   gs, gateway, sim, operator, uav-1 .. uav-N
#   zenoh/router.json5, zenoh/client-<identity>.json5
#                                   configs with absolute paths into OUT_DIR
#                                   (deploy/zenoh/secure/render.py)
#   mavlink/uav-K.key               each vehicle's MAVLink 2 signing passphrase
#                                   (agent --mavlink-key, sim --mavlink-keys)
#
# Idempotent: the CA and every existing certificate are kept; only what is
# missing is created (a larger N adds the new UAVs, signed by the same CA).
# FORCE=1 starts over with a new CA. Extra server names for the router:
# ROUTER_SANS="DNS:gs.example,IP:10.0.0.2" (delete router.pem to reissue it).
# Keys are mode 0600 for the user who runs this: a container running as
# another user needs them readable (chown, or a copy per container).
# Dev use only: keys are unencrypted and the CA key lives next to them.
set -eu

N=${1:-3}
OUT=${2:-$(dirname "$0")/out}
DAYS=${DAYS:-825}
HERE=$(cd "$(dirname "$0")" && pwd)
PYTHON=${PYTHON:-python3}

case $N in
'' | *[!0-9]*)
    echo "usage: $0 [N_UAVS [OUT_DIR]]" >&2
    exit 2
    ;;
esac
command -v openssl >/dev/null || {
    echo "$0: openssl not found" >&2
    exit 1
}

umask 077
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
if [ "${FORCE:-0}" = 1 ]; then
    rm -f "$OUT"/*.pem "$OUT"/*.key "$OUT"/*.srl "$OUT"/zenoh/*.json5 "$OUT"/mavlink/*.key
fi

newkey() { # PKCS#8 EC P-256 key, what rustls reads
    openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null
}

if [ ! -s "$OUT/ca.pem" ] || [ ! -s "$OUT/ca.key" ]; then
    rm -f "$OUT"/*.pem "$OUT"/*.key "$OUT"/*.srl # a new CA invalidates every cert
    newkey "$OUT/ca.key"
    openssl req -x509 -new -key "$OUT/ca.key" -sha256 -days "$DAYS" \
        -subj "/O=linecrew dev/CN=linecrew dev CA" \
        -addext "basicConstraints=critical,CA:TRUE" \
        -addext "keyUsage=critical,keyCertSign,cRLSign" \
        -addext "subjectKeyIdentifier=hash" \
        -out "$OUT/ca.pem"
    echo "created dev CA $OUT/ca.pem"
fi

# issue NAME EXTENSIONS: a leaf certificate NAME.pem / NAME.key, CN = NAME
issue() {
    name=$1
    ext=$2
    [ -s "$OUT/$name.pem" ] && [ -s "$OUT/$name.key" ] && return 0
    newkey "$OUT/$name.key"
    extfile="$OUT/.$name.ext"
    printf '%s\n' "$ext" >"$extfile"
    openssl req -new -key "$OUT/$name.key" -subj "/O=linecrew dev/CN=$name" -out "$OUT/.$name.csr"
    openssl x509 -req -in "$OUT/.$name.csr" -CA "$OUT/ca.pem" -CAkey "$OUT/ca.key" \
        -CAcreateserial -sha256 -days "$DAYS" -extfile "$extfile" -out "$OUT/$name.pem" 2>/dev/null
    rm -f "$extfile" "$OUT/.$name.csr"
    echo "issued $OUT/$name.pem"
}

LEAF="basicConstraints=critical,CA:FALSE
keyUsage=critical,digitalSignature
authorityKeyIdentifier=keyid"
SANS="DNS:localhost,DNS:router,IP:127.0.0.1,IP:::1${ROUTER_SANS:+,$ROUTER_SANS}"

issue router "$LEAF
extendedKeyUsage=serverAuth
subjectAltName=$SANS"
issue https "$LEAF
extendedKeyUsage=serverAuth
subjectAltName=DNS:localhost,IP:127.0.0.1,IP:::1${HTTPS_SANS:+,$HTTPS_SANS}"

client() {
    issue "$1" "$LEAF
extendedKeyUsage=clientAuth
subjectAltName=DNS:$1"
}
for identity in gs gateway sim operator; do
    client "$identity"
done
i=1
mkdir -p "$OUT/mavlink"
while [ "$i" -le "$N" ]; do
    client "uav-$i"
    key="$OUT/mavlink/uav-$i.key"
    [ -s "$key" ] || openssl rand -hex 24 >"$key"
    i=$((i + 1))
done
chmod 644 "$OUT"/*.pem
chmod 755 "$OUT"

"$PYTHON" "$HERE/../zenoh/secure/render.py" --tls-dir "$OUT" --uavs "$N" --out "$OUT/zenoh"
chmod 755 "$OUT/zenoh" && chmod 644 "$OUT"/zenoh/*.json5
echo "certificates in $OUT, zenoh configs in $OUT/zenoh"
