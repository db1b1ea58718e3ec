#!/usr/bin/env bash
# Build a local Python 3.11 base image (Debian bookworm) without any registry:
# debootstrap from the apt mirror this machine already uses, a venv at
# /opt/venv first on PATH, imported as local/python-base:bookworm.
# Idempotent: does nothing if the image exists (pass --force to rebuild).
# Needs root (debootstrap) and a Docker daemon.
set -euo pipefail

IMAGE="${LINECREW_BASE_IMAGE:-local/python-base:bookworm}"
SUITE="bookworm"
FORCE=0
[[ "${1:-}" == "--force" ]] && FORCE=1

have_image() { docker image inspect "$IMAGE" >/dev/null 2>&1; }

if [[ $FORCE == 0 ]] && have_image; then
    echo "build-base-image: $IMAGE exists, nothing to do"
    exit 0
fi

# One build at a time on this machine (tests and CI may race).
exec 9>/tmp/linecrew-build-base-image.lock
flock 9
if [[ $FORCE == 0 ]] && have_image; then
    echo "build-base-image: $IMAGE exists, nothing to do"
    exit 0
fi

if [[ $(id -u) != 0 ]]; then
    echo "build-base-image: debootstrap needs root" >&2
    exit 1
fi

# The Debian mirror from the apt sources (deb822 or one-line format).
mirror="${LINECREW_DEBIAN_MIRROR:-}"
if [[ -z "$mirror" ]]; then
    mirror=$(
        cat /etc/apt/sources.list.d/*.sources 2>/dev/null |
            awk '/^URIs:/ { for (i = 2; i <= NF; i++) if ($i ~ /\/debian\/?$/) { print $i; exit } }'
    )
fi
if [[ -z "$mirror" ]]; then
    mirror=$(
        cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
            awk '$1 == "deb" { for (i = 2; i <= NF; i++) if ($i ~ /\/debian\/?$/) { print $i; exit } }'
    )
fi
mirror="${mirror:-http://deb.debian.org/debian}"

if ! command -v debootstrap >/dev/null; then
    echo "build-base-image: installing debootstrap"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap >/dev/null ||
        { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap >/dev/null; }
fi

rootfs=$(mktemp -d /tmp/linecrew-rootfs.XXXXXX)
cleanup() {
    # debootstrap mounts /proc and /sys inside the tree: never delete through them.
    awk -v root="$rootfs/" 'index($2, root) == 1 { print $2 }' /proc/mounts | sort -r |
        while read -r mnt; do umount -l "$mnt" || true; done
    rm -rf --one-file-system "$rootfs" "$rootfs.log"
}
trap cleanup EXIT

echo "build-base-image: debootstrap $SUITE from $mirror"
debootstrap --variant=minbase \
    --include=python3,python3-venv,python3-pip,ca-certificates \
    "$SUITE" "$rootfs" "$mirror" >"$rootfs.log" 2>&1 ||
    { tail -n 30 "$rootfs.log" >&2; rm -f "$rootfs.log"; exit 1; }
rm -f "$rootfs.log"

chroot "$rootfs" /usr/bin/python3 -m venv /opt/venv
chroot "$rootfs" /opt/venv/bin/python -c 'import sys; assert sys.version_info[:2] == (3, 11), sys.version'

# Nothing of this host in the image; no package caches.
: >"$rootfs/etc/resolv.conf"
: >"$rootfs/etc/hostname"
rm -rf "$rootfs"/var/cache/apt/archives/*.deb "$rootfs"/var/lib/apt/lists/* "$rootfs"/tmp/*

tar -C "$rootfs" -c . | docker import \
    --change 'ENV PATH=/opt/venv/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'ENV LANG=C.UTF-8' \
    --change 'CMD ["python3"]' \
    - "$IMAGE" >/dev/null
echo "build-base-image: built $IMAGE"
