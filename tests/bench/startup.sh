#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Whole-process cost of the command line against the previous build (part
# of `make bench`; docs/mpi.md "Two binaries", docs/speed.md):
# `convsim --version`, `convsim run --duration 0.01`, the 74-point curve
# (`convsim sweep --beta 0:180:5 --rotation cw,ccw --threads 1`) and a
# trajectory file (5 s at 1 kHz, numbers as text), each a
# whole process, CPU = user + sys from wait4 (tests/bench/cpu_runs.py), the
# previous build's and this one's taking turns in the same minutes. The
# previous build is commit PREV (default: main at the branch point of the
# command line's split and the curve's bar, c3bc9a1), exported with git
# archive and built once into $BUILD/prev-PREV (`make build/convsim`
# there). RUNS (default 30) runs of the short commands, CURVES (default 7)
# of the curve and of the trajectory. The machine may be shared: the least CPU is the least
# disturbed figure, the median the typical one. Writes $1/startup.md.
. "$(dirname "$0")/preamble.sh"
PREV=${PREV:-c3bc9a1}
RUNS=${RUNS:-30}
CURVES=${CURVES:-7}
. tests/bench/prev_build.sh
prev_build startup convsim
libs() { ldd "$1" | grep -c '=>' || true; }
mpi_libs() { ldd "$1" | grep -cE 'libmpi|liggghts' || true; }
short=(run --duration 0.01 -q)
curve=(sweep --beta 0:180:5 --rotation cw,ccw --threads 1 -q)
# a trajectory file: 5 simulated s at 1 kHz, 5,001 rows of numbers as text
traj=(run --duration 5 --sample-rate 1000 -q --out /dev/null)
python3 tests/bench/cpu_runs.py "$RUNS" "$prev" --version -- "$cli" --version \
	-- "$prev" "${short[@]}" -- "$cli" "${short[@]}" -- /usr/bin/true > "$work/short"
python3 tests/bench/cpu_runs.py "$CURVES" "$prev" "${curve[@]}" -- "$cli" "${curve[@]}" > "$work/curve"
python3 tests/bench/cpu_runs.py "$CURVES" "$prev" "${traj[@]}" -- "$cli" "${traj[@]}" > "$work/traj"
# the points measured again at finer steps (their step columns differ from the scene's)
# (of the points run, not the mirror images; the scene's steps: the most common pair)
remeasured() {
	"$1" "${curve[@]}" -f json | python3 -c 'import json, sys, collections
p = [q for q in json.load(sys.stdin)["points"] if not q["mirrored"]]
k = collections.Counter((q["dt"], q["substeps"]) for q in p)
print(f"{len(p) - k.most_common(1)[0][1]} of {len(p)} points run")'
}
row() { # what, command, prev line, new line, unit scale, unit, target
	read -r pb pm pw <<<"$3"
	read -r nb nm nw <<<"$4"
	awk -v w="$1" -v c="$2" -v pb="$pb" -v pm="$pm" -v pw="$pw" -v nb="$nb" -v nm="$nm" -v nw="$nw" \
		-v k="$5" -v u="$6" -v t="$7" 'BEGIN {
		printf "| %s | `%s` | %.*f / %.*f %s | %.*f / %.*f %s | %.2f / %.2f | %.0f / %.0f ms | %s |\n",
			w, c, (k > 1 ? 1 : 3), k * pb, (k > 1 ? 1 : 3), k * pm, u, (k > 1 ? 1 : 3), k * nb,
			(k > 1 ? 1 : 3), k * nm, u, pb / nb, pm / nm, 1e3 * pw, 1e3 * nw,
			t == "" ? "" : (k * nb <= t ? "met (least)" : "missed") (t == "" ? "" : (k * nm <= t ? ", met (median)" : ", missed (median)"))
	}'
}
# this build's commit, and whether the sources differ from it (the results aside)
rev="$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- . ':(exclude)tests/bench/results' || echo ' with uncommitted changes')"
{
	echo "# Start-up and the curve: whole processes, the previous build beside this one"
	echo
	echo "Command: \`bash tests/bench/startup.sh\` (part of \`make bench\`), $(date -u '+%Y-%m-%d %H:%M UTC'),"
	echo "$(nproc) cores ($(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)), load average"
	echo "$(cut -d' ' -f1-3 /proc/loadavg) at the end: the machine was shared with other builds and runs."
	echo "Previous build: $PREV ($prev); this build: $rev ($cli)."
	echo "CPU = user + sys of the whole process (wait4), least / median of $RUNS runs ($CURVES for the"
	echo "curve), the two builds taking turns; wall: median."
	echo
	echo "| what | command | previous CPU, least / median | this build | speed-up least / median | wall, previous / this | target |"
	echo "|---|---|---|---|---|---|---|"
	row "version" "convsim --version" "$(sed -n 1p "$work/short")" "$(sed -n 2p "$work/short")" 1e3 ms ""
	row "a short run" "convsim ${short[*]}" "$(sed -n 3p "$work/short")" "$(sed -n 4p "$work/short")" 1e3 ms 10
	row "the 74-point curve" "convsim ${curve[*]}" "$(sed -n 1p "$work/curve")" "$(sed -n 2p "$work/curve")" 1 s 0.1
	row "a trajectory file" "convsim ${traj[*]}" "$(sed -n 1p "$work/traj")" "$(sed -n 2p "$work/traj")" 1 s ""
	echo
	read -r tb tm _ < <(sed -n 5p "$work/short")
	awk -v b="$tb" -v m="$tm" 'BEGIN { printf "- The floor, any process started here (`/usr/bin/true`): %.1f / %.1f ms.\n", 1e3 * b, 1e3 * m }'
	echo "- Shared libraries (\`ldd\`): previous $(libs "$prev") ($(mpi_libs "$prev") of MPI or LIGGGHTS), this build $(libs "$cli") ($(mpi_libs "$cli"))."
	echo "- Curve points measured again at finer steps (a row's dt or substeps not the scene's): previous $(remeasured "$prev"), this build $(remeasured "$cli")."
} > "$out/startup.md"
cat "$out/startup.md"
