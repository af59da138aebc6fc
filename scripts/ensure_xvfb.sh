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
[ -z "$missing" ] && exit 0

if [ "$(id -u)" = 0 ]; then
    sudo=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    sudo="sudo -n"
else
    echo "ensure_xvfb: need$missing but am not root and have no password-less sudo; install them by hand (apt-get install$missing)"
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "ensure_xvfb: need$missing but there is no apt-get here; install them by hand"
    exit 0
fi

export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
# shellcheck disable=SC2086  # word splitting of $sudo and $missing is intended
if { $sudo apt-get install -y -qq --no-install-recommends $missing ||
    { $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends $missing; }; } \
    >"$log" 2>&1; then
    echo "ensure_xvfb: installed$missing"
else
    echo "ensure_xvfb: apt-get install$missing failed (see below); the GUI tests will fail"
    tail -n 5 "$log"
fi
rm -f "$log"
exit 0
