#!/bin/sh
# Make sure `make image` / `make test-image` can build and run containers on a Debian box
# where nothing was installed by hand (CI's fresh machines): Debian's podman, the runc
# runtime (crun, podman's first choice, fails on these machines' hybrid cgroups; the
# Makefile passes --runtime runc), and debootstrap with Debian's archive key for the
# base image (scripts/make_base_image.sh). Installs what is missing with apt-get when we
# are root or have password-less sudo. Unlike ensure_xvfb.sh this one fails (exit 1)
# when it cannot install: nothing after it can work without podman.
set -eu

missing=""
command -v podman >/dev/null 2>&1 || missing="$missing podman"
{ command -v runc >/dev/null 2>&1 || [ -x /usr/sbin/runc ]; } || missing="$missing runc"
{ command -v debootstrap >/dev/null 2>&1 || [ -x /usr/sbin/debootstrap ]; } || missing="$missing debootstrap"
[ -f /usr/share/keyrings/debian-archive-keyring.gpg ] || missing="$missing debian-archive-keyring"
[ -z "$missing" ] && exit 0

if [ "$(id -u)" = 0 ]; then
    sudo=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    sudo="sudo -n"
else
    echo "ensure_podman: need$missing but am not root and have no password-less sudo; install them by hand (apt-get install$missing)" >&2
    exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "ensure_podman: need$missing but there is no apt-get here; install them by hand" >&2
    exit 1
fi

export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
# shellcheck disable=SC2086  # word splitting of $sudo and $missing is intended
if { $sudo apt-get install -y -qq --no-install-recommends $missing ||
    { $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends $missing; }; } \
    >"$log" 2>&1; then
    echo "ensure_podman: installed$missing"
    rm -f "$log"
else
    echo "ensure_podman: apt-get install$missing failed:" >&2
    tail -n 10 "$log" >&2
    rm -f "$log"
    exit 1
fi
