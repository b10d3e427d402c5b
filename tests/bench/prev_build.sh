# SPDX-License-Identifier: GPL-3.0-or-later
# The previous build a bench compares with (sourced, after BUILD and PREV
# are set): `prev_build NAME PROGRAM` sets prev to PROGRAM (convsim,
# convsimd) of commit PREV, exported with git archive into
# $BUILD/prev-PREV/src once and built there (`make build/PROGRAM`) when it
# is not yet; the benches that compare with the same commit share the tree
# (one builds convsim, another convsimd in it). NAME names the bench in
# the message. LAST_RELEASE is the last stop's final commit, the previous
# build of the benches that compare with the release before this one
# (realtime.sh, realtime_over.sh, targets.sh): one place to move it on.
LAST_RELEASE=a9a256a
prev_build() { # bench name, program
	local dir="$BUILD/prev-$PREV"
	prev="$dir/src/build/$2"
	[ -x "$prev" ] && return 0
	echo "$1: building the previous build ($PREV) in $dir" >&2
	mkdir -p "$dir/src"
	[ -f "$dir/src/Makefile" ] || git archive "$PREV" | tar -x -C "$dir/src"
	make -C "$dir/src" --no-print-directory -j2 "build/$2" > "$dir/make.log" 2>&1 ||
		{ tail -20 "$dir/make.log" >&2; exit 1; }
}
# `daemon_beside_previous NAME`: tests/bench/NAME.mjs with this build's
# daemon beside the previous one (PREV_CONVSIMD when set, else PREV's,
# built by prev_build), its table written to $out/NAME.md and stamped
# with the machine and build (provenance.sh); the caller appends its notes.
daemon_beside_previous() { # bench name
	prev=${PREV_CONVSIMD:-}
	[ -n "$prev" ] || prev_build "$1" convsimd
	. tests/bench/provenance.sh
	local line
	line=$(provenance)
	CONVSIMD="$BUILD/convsimd" OLD="$prev" OLD_NAME=previous node "tests/bench/$1.mjs" > "$out/$1.md"
	stamp "$out/$1.md" "$line"
}
