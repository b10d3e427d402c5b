#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# `make mutate`: proves that `make test` can fail. Each mutation below is a
# deliberate fault in the code (a factor, a sign, a skipped term, a unit);
# for each, a copy of the working tree gets the fault, is built, and runs
# the test groups until the first one fails (FAIL_FAST). A mutation that no
# test notices "survives" and makes this script exit 1. Loopback only,
# bounded (each copy's tests stop at the first failing group). Prints a
# table: mutation, where, the first failing group. A fault that does not
# apply (its text moved) stops the script with exit 2: it would test
# nothing. `tests/mutate.sh --check` checks that every fault applies
# without building; ONLY=N tests/mutate.sh runs the N-th alone.
set -u
cd "$(dirname "$0")/.."
root=$PWD
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# name | file | sed expression (must change the file)
mutations=(
	"the feed's position read at the step's end, not at the boundary|core/estimator.c|s|on_boundary(e, t0 + u \\* H, ode_hermite(e->X_prev, e->Xd_prev, X, Xd, H, u),|on_boundary(e, t0 + u * H, X,|"
	"transport velocity scaled by 1.5|core/estimator.c|s|out->transport_velocity = (e->Xb_last - e->Xb_first) / span;|out->transport_velocity = 1.5 * (e->Xb_last - e->Xb_first) / span;|"
	"feed's moment applied at G, not at the deck points|core/deck.c|s|Q\[Q_ALPHA\] += -Rd\[1\] \* F\[0\] + Rd\[0\] \* F\[1\];|Q[Q_ALPHA] += 0.0 * (-Rd[1] * F[0] + Rd[0] * F[1]);|"
	"friction ignored|core/feed.c|s|mu = md->p.mu, R2|mu = 0.0 * md->p.mu, R2|"
	"restitution ignored (unloading as loading)|core/feed.c|s|R2 = md->p.R \* md->p.R;|R2 = 1.0;|"
	"friction work booked at the end-of-sub-step velocity|core/feed.c|s|sum_vx = xid\[j\] + vt\[j\];|sum_vx = 2.0 * vt[j];|"
	"a degree passed as a radian (beta's scale)|core/params.c|s|\"deg\", 0, 180, NULL, RAD_PER_DEG,|\"deg\", 0, 180, NULL, 1,|"
	"the drive's reaction on the trough with the wrong sign|core/model.c|s|rhs\[Q_ALPHA\] -= dt->torque - dt->drag + dt->load;|rhs[Q_ALPHA] += dt->torque - dt->drag + dt->load;|"
	# faults that change nothing on the preset (p = 1, k_x = k_y, h = 0,
	# c = 0, l1 = l2, Coulomb friction): tests/unit/test_beyond_preset.c
	"the contact exponent p ignored (k delta for k delta^p)|core/feed.c|s|: k_c \* pow(delta, p);|: k_c * delta;|"
	"the settled stack's compressions ignore p|core/feed.c|s|pow(load / md->p.k_c, 1.0 / md->p.p)|load / md->p.k_c|"
	"the vertical spring using k_x|core/model.c|s|double Fy = -p->k_y \* u\[1\]|double Fy = -p->k_x * u[1]|"
	"friction measured against the deck, not the layer below (the feed's right-hand side)|core/feed.c|s|prev_xid = xid\[e\];|prev_xid = dvel[0];|"
	"the regularised law's friction measured against the deck, not the layer below (dem)|core/feed.c|s|double below = j == 0 ? dv1\[0\] : xid\[j - 1\];|double below = dv1[0];|"
	"the eliminator offset c ignored in the eliminators' geometry|core/model_points.h|s|double cs = md->p.c + q\[qs\]|double cs = q[qs]|"
	"the eliminator offset c ignored in the preload|core/setup.c|s|(p->c + s\([12]\))|(0.0 + s\1)|"
	"the lever arm h with the wrong sign|core/model.c|s|double Pb\[2\] = {i == 0 ? p->l1 : -p->l2, -p->h};|double Pb[2] = {i == 0 ? p->l1 : -p->l2, p->h};|"
	"the mean rotor speed one period off|core/estimator.c|s|sense \* 2.0 \* M_PI \* e->n_bound / span|sense * 2.0 * M_PI * (e->n_bound + 1) / span|"
	"the shadow's Richardson estimate divided by r + 1, not r - 1|core/shadow.c|s|/ (r - 1.0);|/ (r + 1.0);|"
	"the shadow as fine as its instance (no step error measured)|core/shadow.c|s|m.substeps = (s->cfg.substeps + 1) / 2;|m.substeps = s->cfg.substeps;|"
	"the contact period without the Hertzian tangent stiffness|core/defaults.c|s|if (p->p != 1.0) {|if (0) {|"
	"the default feed step blind to the contact period|core/defaults.c|s|return fmin(hmax, sim_contact_period(p, s) / CONTACT_STEPS)|return fmin(hmax, hmax + 0.0 * sim_contact_period(p, s))|"
	"no refinement of a measurement's steps|core/measure.c|s|^#define MEASURE_REFINEMENTS 3$|#define MEASURE_REFINEMENTS 0|"
	# faults the preset's symmetric machine and the dem method hide:
	# tests/unit/test_power.c (power balance at every state, Kloss
	# against drag and load, what is shown) and test_energy_balance.c
	"the ideal drive's torque net of bearing drag and load torque|core/model.c|s|double s = -rhs\[Q_PHI\];|double s = -rhs[Q_PHI] - dt->drag + dt->load;|"
	"the bearing drag linear in the speed|core/model.c|s|dt->drag = p->b_phi \* dt->omega \* fabs(dt->omega);|dt->drag = p->b_phi * dt->omega;|"
	"the load torque's power booked as an input|core/model.c|s|- dt->load \* dt->omega;|+ dt->load * dt->omega;|"
	"eliminator 1 on eliminator 2's spring|core/model.c|s|rhs\[Q_S1\] += -p->k_s1|rhs[Q_S1] += -p->k_s2|"
	"the trough's inertia without the point masses' x arms|core/model.c|s|M\[Q_ALPHA\]\[Q_ALPHA\] += m \* (ja\[0\] \* ja\[0\] + ja\[1\] \* ja\[1\]);|M[Q_ALPHA][Q_ALPHA] += m * ja[1] * ja[1];|"
	"the guides' turn left out of the kinetic energy|core/model.c|s|v\[0\] += cs \* cf.beta_d \* Rup\[0\];|v[0] += 0.0;|"
	"the feed's contact power halved (rk4, dopri5, euler)|core/feed.c|s|\*contact += Fn \* ddot;|*contact += 0.5 * Fn * ddot;|"
	"the observed feed force on the deck with the wrong sign of friction|core/feed.c|s|			F\[k\]\[0\] = -T;|			F[k][0] = T;|"
	"a deck point's velocity with the wrong sign of its arm|core/deck.c|s|vel\[0\] = qd\[Q_X\] - qd\[Q_ALPHA\] \* Rd\[1\];|vel[0] = qd[Q_X] + qd[Q_ALPHA] * Rd[1];|"
	"a deck point's tangential acceleration with the wrong sign|core/deck.c|s|out\[2\]\[b\]\[1\] = a\[1\] + add \* r\[0\]|out[2][b][1] = a[1] - add * r[0]|"
	"the axle's centripetal acceleration left out (axle off G)|core/model_points.h|s|k->a\[1\] = -ad2 \* Rw\[1\] - e|k->a[1] = - e|"
	"the spring sets' damping on the wrong arm velocity|core/model.c|s|double vx = qd\[Q_X\] - qd\[Q_ALPHA\] \* RP\[1\]|double vx = qd[Q_X] + qd[Q_ALPHA] * RP[1]|"
	"a ramp retargeted while moving brakes twice as early|core/ramp.c|s|double stop = v \* fabs(v) / (2.0 \* amax);|double stop = v * fabs(v) / amax;|"
	"the power shown as half the torque times the speed|core/sim_status.c|s|st->power = ev.torque \* ev.rotor_speed + 0.0;|st->power = 0.5 * ev.torque * ev.rotor_speed + 0.0;|"
	"the mean torque unsigned (ccw)|core/estimator.c|s|out->torque_mean = out->power_mean / out->rotor_speed_mean + 0.0;|out->torque_mean = out->power_mean / fabs(out->rotor_speed_mean) + 0.0;|"
	"the error bar's scatter over n, not n - 2 degrees of freedom|core/estimator.c|s|sqrt(ss / (nb - 2))|sqrt(ss / nb)|"
	"the slip mode's step bound without the bearing drag's slope|core/setup.c|s|+ 2.0 \* p->b_phi \* p->omega_ss;|+ 0.0 * p->b_phi * p->omega_ss;|"
	"dopri5's error estimate halved|core/ode_dopri5.c|s|err = sqrt(err / (double)w->nerr);|err = 0.5 * sqrt(err / (double)w->nerr);|"
	"dem's step bound on the machine's own modes at twice its stability region's radius|core/ode_split.c|s|.radius_limit = RK4_RADIUS_LIMIT,|.radius_limit = 2.0 * RK4_RADIUS_LIMIT,|"
	"the mean feed rate over one column's elements (full model)|core/feed.c|s|return md->nf > 0 ? s / md->nf : 0.0;|return md->nf > 0 ? s / md->L : 0.0;|"
	"the contacts' elastic energy as if p = 1|core/feed.c|s|(md->p.p + 1.0);|2.0;|"
	"the period shown from the first boundary, not the last period|core/estimator.c|s|out->period = e->tb_last - e->tb_prev;|out->period = e->tb_last - e->tb_first;|"
	"the deck point shown from G's height, not its rest (h_d)|core/sim_status.c|s|st->deck\[1\] -= md->dk.h_d;|st->deck[1] -= 0.0;|"
	"steady blind to the drift (only the bar's size)|core/estimator.c|s|fabs(e->bar.drift) <= 3.0 \* e->bar.se_drift|1|"
	"the drift's standard error over the centres' sum of squares, not its root|core/estimator.c|s|e->bar.se_drift = s / sqrt(scc) \* window;|e->bar.se_drift = s / scc * window;|"
	# the symmetric reduction where the machine is not symmetric:
	# tests/unit/test_asymmetry.c
	"the symmetric reduction blind to unequal eliminator dampers|core/setup.c|s|p->b_s1 == p->b_s2 \&\&|1 \&\&|"
	# the ideal drive's speed ramp: tests/unit/test_machine.c
	"the ideal drive's speed ramp always speeding up|core/ramp.c|s|push(r, \&t, \&b, \&v, copysign(amax, dv), fabs(dv) / amax);|push(r, \&t, \&b, \&v, amax, fabs(dv) / amax);|"
	# the machine step's a-priori error term, which the preset's own period
	# hides: tests/unit/test_measure_point.c
	"the machine step's error term in the preset's period, not the machine's|core/sim_status.c|s|s->cfg.dt \* 32.0 \* s->md.p.omega_ss / (2.0 \* M_PI)|s->cfg.dt * 32.0 * 157.08 / (2.0 * M_PI)|"
	# the DEM map's interpolation in beta away from midway:
	# tests/unit/test_model_check.c
	"the model check's weights between two map points swapped|core/model_check.c|s|double d = (1 - w) \* d_lo + w \* d_hi,|double d = w * d_lo + (1 - w) * d_hi,|"
	# the regularised friction law's width (rk4, dopri5, euler):
	# tests/unit/test_feed.c
	"the regularised friction's width doubled|core/feed.c|s|return tanh(v / md->sc.friction_eps);|return tanh(v / (2.0 * md->sc.friction_eps));|"
	# the deck points the core shows (sim_deck_points): tests/unit/test_feed.c
	"the deck points shown from the trough's centre, not each one's rest|core/sim_status.c|s|deck_point(dk, dk->d\[k\], \&R0, zero, zero, rest, vel);|deck_point(dk, 0.0, \&R0, zero, zero, rest, vel);|"
	# each column's displacement from its own origin, where the columns
	# are integrated apart (a rocking machine): tests/unit/test_feed.c
	"each column's displacement from the first column's origin|core/sim_status.c|s|- s->X0k\[c\];|- s->X0k[0];|"
	# the counter-clockwise steady start's rotor speed, on a rotor too heavy
	# for the settling to hide it: tests/unit/test_power.c
	"the steady start's motor speed blind to the sense of rotation|core/steady.c|s|tau = (double)ctl->rotation \* need;|tau = need;|"
	# faults the unit tests caught when they were planted, kept as
	# representatives: a load step's contacts (test_disturb.c), the deck
	# load's moment with h_d != 0 (test_deck_load.c), the yielding deck's
	# turn on a rocking machine (test_feed.c)
	"a load step's contacts scaled by the inverse ratio|core/disturb.c|s|pow(m_n / md->p.m_n, 1.0 / md->p.p)|pow(md->p.m_n / m_n, 1.0 / md->p.p)|"
	"the deck load's moment with the wrong sign of its x part|core/model.c|s|rhs\[Q_ALPHA\] += rx \* L\[1\] - ry \* L\[0\] + L\[2\];|rhs[Q_ALPHA] += rx * L[1] + ry * L[0] + L[2];|"
	"the yielding deck's vertical give with the wrong sign of the turn|core/feed.c|s|(B\[1\]\[q\] + Rd\[0\] \* B\[2\]\[q\])|(B[1][q] - Rd[0] * B[2][q])|"
	# the machine's modes with the rotor at rest only: a light trough's
	# damper across the unbalance's arm (tests/unit/test_hard_machine.c)
	"the machine's step bound read with the rotor at one angle|core/setup.c|s|a < (r_phi < 0 ? 1 : RATE_ROTOR_ANGLES)|a < 1|"
	# a load that turns a standing rotor backwards, and a steady start on
	# an orbit the motor cannot drive (tests/unit/test_power.c)
	"the load torque constant whatever way the rotor turns|core/model.c|s|fmin(p->M_load, 2.0 \* p->M_ut / p->slip_ut \* dt->omega)|fmin(p->M_load, (double)ctl->rotation * 1e300)|"
	"the steady start on an orbit the motor cannot drive|core/steady.c|s|if (!md->phi_prescribed \&\& !isfinite(next))|if (0)|"
	# a curve's tol_met judged with the run's peak estimate alone
	# (tests/unit/test_measure_point.c, tests/http/jobs.test.mjs)
	# a fast machine's step with one feed sub-step and no shadow
	# (tests/unit/test_measure_point.c)
	"a fast machine's sub-steps below the shadow's least|core/defaults.c|s|if (n < SIM_SHADOW_SUBSTEPS \&\& om|if (n < 1 \&\& om|"
	"a curve's own peak allowing tol times it everywhere|core/study.c|s|tol \* (v >= 0.3 \* peak ? v : peak)|tol * (v >= 0.3 * peak ? peak : peak)|"
	# a hard-thrown feed measured over the steady start's first window
	# (tests/unit/test_measure_point.c)
	"a feed thrown hard measured from the steady start on|core/measure.c|s|int late = early \&\& fmax|int late = 0 \&\& fmax|"
	# its later window at the scene's own feed step, which may pick a
	# motion its shadow agrees with (tests/unit/test_measure_point.c)
	"a hard-thrown feed's later window at the scene's own sub-steps|core/measure.c|s|^#define MEASURE_LATE_FINE 4$|#define MEASURE_LATE_FINE 1|"
	# at twice them, where the feed step's error stalls between its shadow
	# and it: tol no longer met there (tests/unit/test_measure_point.c)
	"a hard-thrown feed's later window at twice the scene's sub-steps|core/measure.c|s|^#define MEASURE_LATE_FINE 4$|#define MEASURE_LATE_FINE 2|"
	# and its check at half the machine step (tests/unit/test_measure_point.c)
	"a hard-thrown feed's later window not checked at half the machine step|core/measure.c|s|if (fine \&\& own_steps \&\& attempt == 0|if (0 \&\& fine \&\& own_steps \&\& attempt == 0|"
	# a feed thrown beyond the check's threshold not run again at twice
	# its sub-steps, its shadow stalling with it (tests/unit/test_measure_point.c)
	"a thrown feed not checked at twice its sub-steps|core/measure.c|s|^#define MEASURE_CHECK_THROW 4.2$|#define MEASURE_CHECK_THROW 5.5|"
)
# --check: only that every fault applies (each to a copy of its file), no
# builds; ONLY=N: run the N-th mutation (1-based) alone.
check=0
[ "${1:-}" = "--check" ] && check=1
# A fault whose text is no longer in its file tests nothing: stop loudly.
apply_fault() { # file-in-a-copy from to name
	local before
	before=$(sha1sum "$1")
	sed -i "s|$2|$3|" "$1"
	if [ "$(sha1sum "$1")" = "$before" ]; then
		printf 'mutate: the fault "%s" does not apply to %s: its text is not there; re-aim it\n' \
			"$4" "${1#"$work"/tree/}" >&2
		exit 2
	fi
}
if [ "$check" = 1 ]; then
	mkdir -p "$work/tree"
	for m in "${mutations[@]}"; do
		IFS='|' read -r name file _ from to _ <<<"$m"
		mkdir -p "$work/tree/$(dirname "$file")"
		cp "$file" "$work/tree/$file"
		apply_fault "$work/tree/$file" "$from" "$to" "$name"
		printf 'applies: %s (%s)\n' "$name" "$file"
	done
	echo "mutate --check: all ${#mutations[@]} faults apply"
	exit 0
fi
printf '| mutation | file | first failing test group | verdict |\n|---|---|---|---|\n'
survived=0
i=0
for m in "${mutations[@]}"; do
	i=$((i + 1))
	[ -n "${ONLY:-}" ] && [ "$ONLY" != "$i" ] && continue
	IFS='|' read -r name file _ from to _ <<<"$m"
	dir="$work/tree"
	rm -rf "$dir"
	mkdir -p "$dir"
	git ls-files -z | xargs -0 cp --parents -t "$dir"
	ln -s "$root/tests/node_modules" "$dir/tests/node_modules"
	apply_fault "$dir/$file" "$from" "$to" "$name"
	# the DEM tests' binaries too where this tree's build has them: a test
	# group that fails for want of them would count every fault that
	# reaches it as killed
	if ! (cd "$dir" && make -s -j2 BUILD=build-mut build-mut/convsim build-mut/convsimd \
		$(cd "$dir" && ls tests/unit/test_*.c | sed 's|tests/unit/\(.*\)\.c|build-mut/tests/\1|') \
		$(for b in convsim-bed convsim-dem convsim-mpi; do [ -x "$root/${BUILD:-build}/$b" ] && echo "build-mut/$b"; done) \
		>"$work/build.log" 2>&1); then
		printf '| %s | %s | (does not build) | killed |\n' "$name" "$file"
		continue
	fi
	out=$(cd "$dir" && BUILD=build-mut FAIL_FAST=1 bash tests/run.sh 2>&1)
	group=$(printf '%s\n' "$out" | sed -n 's/^failed group: //p' | head -1)
	if [ -n "$group" ]; then
		printf '| %s | %s | %s | killed |\n' "$name" "$file" "$group"
	else
		printf '| %s | %s | none | SURVIVED |\n' "$name" "$file"
		survived=$((survived + 1))
	fi
done
echo
echo "mutate: ${#mutations[@]} mutations, $survived survived"
[ "$survived" -eq 0 ]
