#!/bin/sh
# A Python base image made from Debian's archive, for machines that reach no container
# registry (ours): debootstrap a minimal Debian with python3 and its venv module, then
# `podman import` the tree. It stands in for the Containerfile's default base,
# docker.io/library/python:3.11-slim-bookworm: the same Debian release and the same
# Python minor version (Debian's 3.11.2 instead of python.org's build).
#
#   sh scripts/make_base_image.sh [NAME]      default NAME: localhost/otonav-base:bookworm
#
# An existing NAME is kept (REBUILD=1 makes it again). SUITE and MIRROR choose the Debian
# release and mirror; PODMAN the podman command. Needs root (debootstrap, chroot) and
# about 300 MB in TMPDIR (default /var/tmp) while it runs; takes about a minute.
set -eu

name=${1:-localhost/otonav-base:bookworm}
suite=${SUITE:-bookworm}
mirror=${MIRROR:-http://deb.debian.org/debian}
podman=${PODMAN:-podman}
PATH="$PATH:/usr/sbin:/sbin"

# shellcheck disable=SC2086  # $podman may carry options
if [ "${REBUILD:-0}" != 1 ] && $podman image exists "$name"; then
    echo "make_base_image: $name exists (REBUILD=1 makes it again)"
    exit 0
fi
if [ "$(id -u)" != 0 ]; then
    echo "make_base_image: debootstrap needs root" >&2
    exit 1
fi

root=$(mktemp -d "${TMPDIR:-/var/tmp}/otonav-base.XXXXXX")
# --one-file-system: never follow a /proc or /sys that an interrupted debootstrap left
# mounted inside the tree into the host's.
cleanup() {
    umount "$root/proc" "$root/sys" 2>/dev/null || true
    rm -rf --one-file-system "$root" "$root.log"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

start=$(date +%s)
echo "make_base_image: debootstrap $suite (minbase + python3, python3-venv, ca-certificates) from $mirror"
if ! debootstrap --variant=minbase --include=python3,python3-venv,ca-certificates \
    "$suite" "$root" "$mirror" >"$root.log" 2>&1; then
    echo "make_base_image: debootstrap failed:" >&2
    tail -n 20 "$root.log" >&2
    exit 1
fi

# Trust what the host trusts. A machine whose HTTPS goes through an intercepting proxy
# (ours) keeps its extra CAs in /usr/local/share/ca-certificates; without them pip in
# the build cannot reach PyPI. pip reads its own certifi bundle, not the system store,
# so PIP_CERT below points it at the system bundle (which then includes them).
if ls /usr/local/share/ca-certificates/*.crt >/dev/null 2>&1; then
    cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
    chroot "$root" update-ca-certificates >/dev/null 2>&1
fi

# What no container needs: downloaded packages, package lists, docs, man pages and
# translations (275 MB -> 133 MB when measured). apt still works after `apt-get update`,
# as in the official slim images.
rm -rf "$root"/var/cache/apt/archives/*.deb "$root"/var/cache/apt/*.bin \
    "$root"/var/lib/apt/lists/* "$root"/usr/share/doc/* "$root"/usr/share/man/* \
    "$root"/usr/share/locale/* "$root"/usr/share/info/*

# shellcheck disable=SC2086  # $podman may carry options
tar --numeric-owner -C "$root" -c . | $podman import \
    --change 'ENV=PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'ENV=LANG=C.UTF-8' \
    --change 'ENV=PIP_CERT=/etc/ssl/certs/ca-certificates.crt' \
    --change 'CMD=["python3"]' \
    - "$name" >/dev/null
echo "make_base_image: $name made in $(($(date +%s) - start)) s"
