#!/bin/sh
# Install Debian packages a make target needs and this machine lacks (the ensure_*.sh
# scripts decide what is missing and call this). Uses apt-get as root or with
# password-less sudo; tries the package lists as they are, then after `apt-get update`.
#
# usage: sh scripts/apt_missing.sh NAME MODE CONSEQUENCE PACKAGE...
#   NAME         the calling script, the prefix of every line printed
#   MODE         "warn": when it cannot install, one line on stdout and exit 0 (the tests
#                that need the packages then fail saying what is missing: they never skip);
#                "fail": the same line on stderr and exit 1 (nothing after it can work)
#   CONSEQUENCE  what fails without the packages, for the warning
set -eu

name=$1 mode=$2 consequence=$3
shift 3
missing=" $*"
[ -z "$*" ] && exit 0

give_up() {  # a line saying why, then apt-get's last lines if any ($2)
    if [ "$mode" = fail ]; then
        printf '%s: %s\n%s' "$name" "$1" "${2:-}" >&2
        exit 1
    fi
    printf '%s: %s; %s\n%s' "$name" "$1" "$consequence" "${2:-}"
    exit 0
}

if [ "$(id -u)" = 0 ]; then
    sudo=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    sudo="sudo -n"
else
    give_up "need$missing but am not root and have no password-less sudo; install them by hand (apt-get install$missing)"
fi
command -v apt-get >/dev/null 2>&1 ||
    give_up "need$missing but there is no apt-get here; install them by hand"

export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
# shellcheck disable=SC2086  # word splitting of $sudo and $missing is intended
if { $sudo apt-get install -y -qq --no-install-recommends $missing ||
    { $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends $missing; }; } \
    >"$log" 2>&1; then
    echo "$name: installed$missing"
    rm -f "$log"
    exit 0
fi
last=$(tail -n 10 "$log")
rm -f "$log"
give_up "apt-get install$missing failed (apt-get's last lines below)" "$last
"
