#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The machine zoo's converged references (tests/bench/zoo/machines.tsv):
# v(beta) at beta = 0..180 deg every 10 deg, both senses, for every
# machine, by runs far finer than any default and with a longer window
# than the default's 4 s (the machine's reference window, 8 s, or longer
# where its feed is chaotic), after the steady start:
#   A: dem, machine step 1.25e-4 s, 40 feed sub-steps (h = 3.1e-6 s),
#   B: dem, machine step 6.25e-5 s, 80 feed sub-steps (h = 7.8e-7 s),
#   C: dem, machine step 3.125e-5 s, 160 sub-steps, only where B and A
#      differ by more than 0.1 % of the peak somewhere,
#   D: dem, machine step 1.5625e-5 s, 320 sub-steps, only where C and B
#      still do,
# all without feed events (the former dem: nothing located, no yielding
# deck), so the reference shares no step rule with what it checks. The
# finest run is the reference; the change from the one before shows it
# converged (dem is first order in both steps here, so that change
# bounds the finest run's own step error). Writes tests/bench/zoo/ref.tsv:
#   machine beta_deg rotation v_ref v_prev d_conv
# (m/s; v_prev the run one level coarser, d_conv = v_ref - v_prev).
# Usage: bash tests/bench/zoo_ref.sh [OUT [MACHINE...]] (`make bench-zoo-ref`;
# not part of make bench, whose zoo.sh reads the committed table). Takes
# one to two hours of CPU on one core for the whole zoo.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
THREADS=${THREADS:-2}
out=${1:-tests/bench/zoo/ref.tsv}
shift || true
only=" $* "
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fine() { # machine name, label, window, settings...
	local name=$1 label=$2 window=$3; shift 3
	"$BUILD/convsim" sweep -q --beta 0:180:10 --rotation cw,ccw --duration "$window" \
		--threads "$THREADS" --format csv "$@" > "$tmp/$name.$label.csv"
}
# two tables side by side: the coarse and the fine velocity's columns
# found by the header (a, b), the rest as the caller's awk says
pair() { # coarse.csv, fine.csv, awk program (after the columns are known)
	paste -d, "$1" "$2" | awk -F, -v m="${4:-}" 'function abs(x) { return x < 0 ? -x : x }
		NR == 1 { for (i = 1; i <= NF; i++) if ($i == "velocity") { if (a) b = i; else a = i }; next }
		'"$3"
}
# the largest |v_fine - v_coarse| over the peak of v_fine
spread() {
	pair "$1" "$2" '{ d = abs($b - $a); if (d > dm) dm = d; if (abs($b) > pk) pk = abs($b) }
		END { printf "%.6f\n", dm / pk }'
}
printf 'machine\tbeta_deg\trotation\tv_ref\tv_prev\td_conv\n' > "$tmp/ref.tsv"
while IFS=$'\t' read -r name sets window _; do
	case $name in '#'* | '') continue ;; esac
	[ "$only" = "  " ] || [[ $only == *" $name "* ]] || continue
	args=()
	for kv in $sets; do [ "$kv" = - ] || args+=(--set "$kv"); done
	fine "$name" A "$window" "${args[@]}" --set dt=1.25e-4 --set substeps=40 --set feed_events=false
	fine "$name" B "$window" "${args[@]}" --set dt=6.25e-5 --set substeps=80 --set feed_events=false
	coarse=A finest=B
	for level in "C 3.125e-5 160" "D 1.5625e-5 320"; do
		read -r next dt n <<<"$level"
		awk -v s="$(spread "$tmp/$name.$coarse.csv" "$tmp/$name.$finest.csv")" \
			'BEGIN { exit !(s > 0.001) }' || break
		fine "$name" "$next" "$window" "${args[@]}" --set dt="$dt" --set substeps="$n" \
			--set feed_events=false
		coarse=$finest finest=$next
	done
	pair "$tmp/$name.$coarse.csv" "$tmp/$name.$finest.csv" \
		'{ printf "%s\t%s\t%s\t%.8g\t%.8g\t%+.3g\n", m, $1, $2, $b, $a, $b - $a }' "$name" \
		>> "$tmp/ref.tsv"
	echo "zoo_ref: $name done ($finest against $coarse)" >&2
done < tests/bench/zoo/machines.tsv
if [ -e "$out" ] && [ "$only" != "  " ]; then
	# one or a few machines: replace their rows in the existing table
	awk -F'\t' 'NR == FNR { if (FNR > 1) redo[$1] = 1; next } FNR == 1 || !($1 in redo)' \
		"$tmp/ref.tsv" "$out" > "$tmp/old.tsv"
	tail -n +2 "$tmp/ref.tsv" >> "$tmp/old.tsv"
	mv "$tmp/old.tsv" "$out"
else
	mv "$tmp/ref.tsv" "$out"
fi
