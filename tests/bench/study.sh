#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The study target (`make bench`, or alone: bash tests/bench/study.sh
# [OUTDIR]): a 20 x 37 study (mu 0.1..2 by 0.1 x beta 0..180 deg by 5) on
# 2 cores, with each point's steps chosen per point (the "any machine"
# estimate), must take under 30 s of wall time. Timed for the clockwise
# sense, for both senses (the mirror reduction runs half of them), and
# for both senses under `mpirun -n 2` with one thread per rank where
# convsim has MPI and mpirun exists. Each REPEAT times (default 3: the
# machine is shared); the table gives every run's wall time and the CPU
# time (user + sys) of the fastest, and the command.
. "$(dirname "$0")/preamble.sh"
. tests/bench/provenance.sh
prov=$(provenance)
study="sweep --vary mu=0.1:2:0.1 --beta 0:180:5"
# mpirun as root wants to be told (Open MPI); more ranks than cores need --oversubscribe
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
{
	echo "# Design studies: a 20 x 37 study on 2 cores"
	echo
	echo "$prov"
	echo "Made by \`bash tests/bench/study.sh\` (part of \`make bench\`) on $(nproc) cores, $(date -u +%Y-%m-%d):"
	echo "each command $repeat times (the machine may be shared: the fastest run counts). Target: < 30 s wall."
	echo
	echo "| command | points run + mirror images | wall / s (each run) | CPU / s (user+sys, fastest) | target |"
	echo "|---|---|---|---|---|"
} > "$out/study.md"
row() { # shown command, command...
	local shown=$1 walls="" best="" cpu="" i wall user sys
	shift
	for i in $(seq 1 "$repeat"); do
		/usr/bin/time -f "%e %U %S" -o "$work/time" "$@" -q -f json -o "$work/study.json"
		read -r wall user sys < "$work/time"
		walls="$walls${walls:+, }$wall"
		if [ -z "$best" ] || awk -v a="$wall" -v b="$best" 'BEGIN { exit !(a < b) }'; then
			best=$wall
			cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.1f", u + s }')
		fi
	done
	local counts
	counts=$(python3 -c 'import json, sys
p = json.load(open(sys.argv[1]))["points"]
m = sum(1 for q in p if q["mirrored"])
print(f"{len(p) - m} + {m}")' "$work/study.json")
	local ok
	ok=$(awk -v b="$best" 'BEGIN { print (b < 30 ? "met" : "missed") }')
	echo "| \`$shown\` | $counts | $walls | $cpu | $ok |" >> "$out/study.md"
}
row "convsim $study --rotation cw --threads 2" "$cli" $study --rotation cw --threads 2
row "convsim $study --threads 2" "$cli" $study --threads 2
if command -v mpirun >/dev/null && ldd "$cli" | grep -q libmpi; then
	row "mpirun -n 2 convsim $study --threads 1" mpirun -n 2 --oversubscribe "$cli" $study --threads 1
fi
cat "$out/study.md"
