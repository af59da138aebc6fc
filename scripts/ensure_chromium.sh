#!/bin/sh
# Make sure the docs screenshot check (make test-docs) can run on a headless Debian box:
# Debian's `chromium`. Installs it with apt-get when we are root or have password-less
# sudo; otherwise prints one line and exits 0 (the check then fails saying what is
# missing: it never skips).
set -eu

missing=""
command -v chromium >/dev/null 2>&1 || missing="$missing chromium"
# shellcheck disable=SC2086  # one word per package
exec sh "$(dirname "$0")/apt_missing.sh" ensure_chromium warn "the docs screenshot check will fail" $missing
