#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The paper's case of docs/calibration.md (`make bench-calibration`, or
# alone: bash tests/bench/calibration.sh [OUTDIR]): the czubak2016 model
# fitted to the paper's clockwise peaks (38 and 128 deg), e alone, then e
# with each second parameter of physical meaning from 4 starts, e with mu
# from the default start alone, and the v(beta) curves of the preset's fit
# (czubak2016 and the fitted e, m_n, every 10 deg). Writes
# $OUTDIR/calibration.md (default tests/bench/results); a few minutes of
# two cores, at nice 10.
. "$(dirname "$0")/preamble.sh"
. tests/bench/provenance.sh
prov=$(provenance)
peaks="--peaks cw:38,cw:128"
fit() { # NAME ARGS...: one fit into $work/NAME.json
	local name=$1; shift
	echo "calibration: convsim fit $peaks $*" >&2
	nice -n 10 "$cli" fit $peaks "$@" --threads 2 -q > "$work/$name.json"
}
fit e --free e:0.005:0.04 --curve-step 0
seconds="m_n:0.25:1 mu:0.1:1.5 omega_ss:110:200 k_c:1e5:1e7 R:0.01:0.5"
for s in $seconds; do
	step=0
	[ "${s%%:*}" = m_n ] && step=10 # the preset's run: its curve is table 4
	fit "two_${s%%:*}" --free "e:0.005:0.04,$s" --starts 4 --curve-step "$step"
done
fit mu_one --free e:0.005:0.04,mu:0.1:1.5 --curve-step 0
fit preset --preset czubak2016-fit --free e,m_n --max-iter 1 --curve-step 0
python3 tests/bench/calibration_report.py "$work" "$prov" "$seconds" > "$out/calibration.md"
cat "$out/calibration.md"
