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
# shellcheck disable=SC2086  # one word per package
exec sh "$(dirname "$0")/apt_missing.sh" ensure_podman fail "the container targets cannot run" $missing
