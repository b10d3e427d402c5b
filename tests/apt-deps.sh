#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Installs the Debian packages of $NEEDS ("FILE:PACKAGE ..." pairs) whose
# FILE is missing, saying which and why ($WHY). apt-get needs root: as root
# it runs directly, otherwise through sudo if there is one; without either
# it prints the command to run and fails. Used by the Makefile's deps rules.
# Two of them at once (make -j) take turns on a lock: apt-get refuses to run
# beside another, and the second then finds what the first installed.
set -u
if [ -z "${CONVSIM_APT_LOCKED:-}" ] && command -v flock >/dev/null 2>&1; then
	CONVSIM_APT_LOCKED=1 exec flock "${TMPDIR:-/tmp}/convsim-apt-deps.lock" sh "$0"
fi
missing=""
for pair in $NEEDS; do
	f=${pair%%:*}; p=${pair##*:}
	[ -e "$f" ] || missing="$missing $p"
done
[ -n "$missing" ] || exit 0
echo "convsim needs Debian packages$missing $WHY."
echo "Installing them with apt-get, which needs root (it writes to /usr and the package database)."
if [ "$(id -u)" -eq 0 ]; then
	sudo=""
elif command -v sudo >/dev/null 2>&1; then
	sudo="sudo"
	echo "Not root: using sudo (it may ask for your password)."
else
	echo "Not root and no sudo: run as root" >&2
	echo "  apt-get update && apt-get install -y$missing" >&2
	echo "then run make again." >&2
	exit 1
fi
echo "+ ${sudo:+$sudo }apt-get update && ${sudo:+$sudo }apt-get install -y$missing"
$sudo apt-get -o DPkg::Lock::Timeout=600 update -q &&
	$sudo env DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 install -y -q $missing
