#!/usr/bin/env bash
# The machine zoo's converged references (tests/bench/zoo/machines.tsv):
# v(beta) at beta = 0..180 deg every 10 deg, both senses, for every
# machine, by two runs far finer than any default and with a longer
# window than the default's 4 s: an 8-s window after the steady start,
#   A: dem, machine step 1.25e-4 s, 40 feed sub-steps (h = 3.1e-6 s),
#   B: dem, machine step 6.25e-5 s, 80 feed sub-steps (h = 7.8e-7 s),
# both without feed events (the former dem: nothing located, no yielding
# deck), so the reference shares no step rule with what it checks. B is
# the reference; |B - A| shows it converged (dem is first order in both
# steps here, so |B - A| bounds B's own step error). Writes
# tests/bench/zoo/ref.tsv: machine beta_deg rotation v_ref v_A d_AB.
# Takes 10 to 20 min of CPU (`make bench-zoo-ref`; not part of make bench,
# whose zoo.sh reads the committed table).
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
THREADS=${THREADS:-2}
out=${1:-tests/bench/zoo/ref.tsv}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fine() { # machine name, label, settings...
	local name=$1 label=$2; shift 2
	"$BUILD/convsim" sweep -q --beta 0:180:10 --rotation cw,ccw --duration 8 --threads "$THREADS" \
		--format csv "$@" > "$tmp/$name.$label.csv"
}
printf 'machine\tbeta_deg\trotation\tv_ref\tv_A\td_AB\n' > "$tmp/ref.tsv"
grep -v '^#' tests/bench/zoo/machines.tsv | while IFS=$'\t' read -r name sets _; do
	[ -n "$name" ] || continue
	args=()
	for kv in $sets; do [ "$kv" = - ] || args+=(--set "$kv"); done
	fine "$name" A "${args[@]}" --set dt=1.25e-4 --set substeps=40 --set feed_events=false
	fine "$name" B "${args[@]}" --set dt=6.25e-5 --set substeps=80 --set feed_events=false
	paste -d, "$tmp/$name.A.csv" "$tmp/$name.B.csv" | awk -F, -v m="$name" 'NR > 1 {
		printf "%s\t%s\t%s\t%.8g\t%.8g\t%+.3g\n", m, $1, $2, $9, $3, $9 - $3 }' >> "$tmp/ref.tsv"
	echo "zoo_ref: $name done" >&2
done
mv "$tmp/ref.tsv" "$out"
