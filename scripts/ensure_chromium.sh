#!/bin/sh
# Make sure the docs screenshot check (make test-docs) can run on a headless Debian box:
# Debian's `chromium`. Installs it with apt-get when we are root or have password-less
# sudo; otherwise prints one line and exits 0 (the check then fails saying what is
# missing: it never skips).
set -eu

missing=""
command -v chromium >/dev/null 2>&1 || missing="$missing chromium"
[ -z "$missing" ] && exit 0

if [ "$(id -u)" = 0 ]; then
    sudo=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    sudo="sudo -n"
else
    echo "ensure_chromium: need$missing but am not root and have no password-less sudo; install them by hand (apt-get install$missing)"
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "ensure_chromium: need$missing but there is no apt-get here; install them by hand"
    exit 0
fi

export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
# shellcheck disable=SC2086  # word splitting of $sudo and $missing is intended
if { $sudo apt-get install -y -qq --no-install-recommends $missing ||
    { $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends $missing; }; } \
    >"$log" 2>&1; then
    echo "ensure_chromium: installed$missing"
else
    echo "ensure_chromium: apt-get install$missing failed (see below); the docs screenshot check will fail"
    tail -n 5 "$log"
fi
rm -f "$log"
exit 0
