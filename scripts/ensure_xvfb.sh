#!/bin/sh
# Make sure the GUI smoke tests can run on a headless Debian box: a virtual X server
# (xvfb-run, from Debian's `xvfb`; it needs `xauth`) and a screenshot tool (`xwd`, from
# `x11-apps`). Installs what is missing with apt-get when we are root or have
# password-less sudo; otherwise prints one line and exits 0 (the GUI tests then fail
# with a message saying what is missing: they never skip).
set -eu

missing=""
command -v xvfb-run >/dev/null 2>&1 || missing="$missing xvfb"
command -v xauth >/dev/null 2>&1 || missing="$missing xauth"
command -v xwd >/dev/null 2>&1 || missing="$missing x11-apps"
# shellcheck disable=SC2086  # one word per package
exec sh "$(dirname "$0")/apt_missing.sh" ensure_xvfb warn "the GUI tests will fail" $missing
