/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * feed_chain.h - the exact impulse solve of one column's chain of layers
 * over a DEM sub-step (an active-set method on the bonded, loading and
 * unloading contacts) and its event-driven friction variant. Static
 * functions included by feed.c only, where they were, so that they are
 * inlined into its sub-step exactly as before.
 */
#ifndef CONVSIM_FEED_CHAIN_H
#define CONVSIM_FEED_CHAIN_H

#include <math.h>
#include <string.h>

enum { BOND = 0, HI = 1, LO = 2 };

/* Exact solve of one column's impulses over a sub-step (a convex problem:
 * minimise sum m/2 (v_j - vs_j)^2 + sum max(lo_j s_j, hi_j s_j) with
 * s_j = v_{j-1} - v_j and v_{-1} = v0, the deck's velocity). Contact j
 * (between layer j-1, or the deck, and layer j) is BOND (s = 0, impulse in
 * [lo, hi]), HI (impulse hi, s >= 0) or LO (impulse lo, s <= 0). Bonded
 * runs of layers move as one cluster; the modes are switched until they
 * are consistent (active-set method, warm-started from mode[]). Writes the
 * impulses P (on layer j from below) and the new velocities v. */
/* The velocities v and impulses P of the column for the contact modes
 * mode as they stand (no switching): bonded runs move as one cluster,
 * every other contact carries its fixed impulse (HI: hi, LO: lo). Always
 * inlined into its solves: called, it cost the full scene a few per cent. */
static inline __attribute__((always_inline)) void
chain_clusters(int L, double m, const double *restrict vs, double v0, const double *restrict lo,
	       const double *restrict hi, double *restrict P, double *restrict v,
	       const signed char *restrict mode)
{
	/* clusters: a run of layers a..b bonded above a, resting on
	 * the fixed impulse of contact a (or riding with the deck),
	 * with the fixed impulse of contact b + 1 on top */
	for (int a = 0; a < L;) {
		double sum = vs[a];
		int b = a;
		while (b + 1 < L && mode[b + 1] == BOND)
			sum += vs[++b];
		double Ptop = b + 1 < L ? (mode[b + 1] == HI ? hi[b + 1] : lo[b + 1]) : 0.0;
		if (a == 0 && mode[0] == BOND) {
			/* rides with the deck */
			double Pj = Ptop;
			for (int j = b; j >= 0; j--) {
				Pj += m * (v0 - vs[j]);
				P[j] = Pj;
				v[j] = v0;
			}
		} else {
			double Pbot = mode[a] == HI ? hi[a] : lo[a];
			double n = (double)(b - a + 1);
			double vc = (m * sum + Pbot - Ptop) / (n * m);
			/* the running impulse in a register: the chain is
			 * serial, so no store-to-load round trip per layer */
			double Pj = Pbot;
			for (int j = a; j < b; j++) {
				P[j] = Pj;
				v[j] = vc;
				Pj -= m * (vc - vs[j]);
			}
			P[b] = Pj;
			v[b] = vc;
		}
		a = b + 1;
	}
}

/* The mode a bonded contact with impulse P takes: HI or LO where P is
 * beyond its bound by more than the tolerance, HI where the bounds are
 * equal (a fixed impulse, or no contact), else BOND. */
static inline __attribute__((always_inline)) signed char bond_mode(double P, double lo, double hi)
{
	if (hi == lo)
		return HI;
	double tolP = 1e-12 * (fabs(hi) + fabs(lo)) + 1e-300;
	return P > hi + tolP ? HI : P < lo - tolP ? LO : BOND;
}

/* The mode a slipping contact (mode m, HI or LO) takes at the relative
 * velocity s: BOND where it has stopped or reversed, HI where its bounds
 * are equal. */
static inline __attribute__((always_inline)) signed char slip_mode(signed char m, double s,
								  double lo, double hi)
{
	if (hi == lo)
		return HI;
	if (m == HI)
		return s < -1e-13 ? BOND : HI;
	return s > 1e-13 ? BOND : LO;
}

/* Contact j to mode nm, the modes on entry copied at a solve's first
 * switch (where entry is asked for). */
static inline __attribute__((always_inline)) void
switch_mode(int L, signed char *restrict mode, signed char *restrict entry, int *switched, int j,
	    signed char nm)
{
	if (!*switched && entry)
		memcpy(entry, mode, (size_t)L);
	*switched = 1;
	mode[j] = nm;
}

/* A bonded contact j with impulse p to its consistent mode; within its
 * bounds it stays (bond_mode's tolerance is needed only outside them).
 * Returns 1 where it switched. */
static inline __attribute__((always_inline)) int
bond_switch(int L, int j, double p, const double *restrict lo, const double *restrict hi,
	    signed char *restrict mode, signed char *restrict entry, int *switched)
{
	double h = hi[j], l = lo[j];
	if (!(h == l || p > h || p < l))
		return 0;
	signed char nm = bond_mode(p, l, h);
	if (nm == BOND)
		return 0;
	switch_mode(L, mode, entry, switched, j, nm);
	return 1;
}

/* The bonded contacts j0..j1 of a solved cluster checked, bottom first
 * (bond_switch); after L rounds (single) up to the first switch. Returns 1
 * where one switched. */
static inline __attribute__((always_inline)) int
check_bonded(int L, int j0, int j1, const double *restrict lo, const double *restrict hi,
	     const double *restrict P, signed char *restrict mode, signed char *restrict entry,
	     int *switched, int single)
{
	int changed = 0;
	for (int j = j0; j <= j1; j++)
		if (bond_switch(L, j, P[j], lo, hi, mode, entry, switched)) {
			changed = 1;
			if (single)
				break;
		}
	return changed;
}

/* One round of chain_solve: chain_clusters' velocities and impulses for
 * the modes as they stand, each contact checked as its cluster is solved
 * (a cluster's bottom contact first, then its bonded ones as their
 * impulses come) and switched where inconsistent; after L rounds (single)
 * the checks go bottom first, chain_clusters' order, and stop at the first
 * switch. A switch touches only contacts of the cluster being solved or
 * those below it, so every cluster is solved with the modes the round
 * began with, as in a full pass followed by the checks; the fixed impulse
 * on a cluster's top is the one under the next (Pbot), the arithmetic
 * chain_clusters'. Returns whether a contact switched. */
static inline __attribute__((always_inline)) int
chain_round(int L, double m, const double *restrict vs, double v0, const double *restrict lo,
	    const double *restrict hi, double *restrict P, double *restrict v,
	    signed char *restrict mode, signed char *restrict entry, int *switched, int single)
{
	int changed = 0, a = 0, b = 0;
	double below = v0, Pbot = 0.0;
	if (mode[0] == BOND) {
		/* rides with the deck */
		while (b + 1 < L && mode[b + 1] == BOND)
			b++;
		Pbot = b + 1 < L ? (mode[b + 1] == HI ? hi[b + 1] : lo[b + 1]) : 0.0;
		/* its contacts checked as their impulses come, top first:
		 * before the single rounds every contact is checked, so the
		 * order changes nothing */
		double Pj = Pbot;
		for (int j = b; j >= 0; j--) {
			Pj += m * (v0 - vs[j]);
			P[j] = Pj;
			v[j] = v0;
			if (!single && bond_switch(L, j, Pj, lo, hi, mode, entry, switched))
				changed = 1;
		}
		if (single)
			changed = check_bonded(L, 0, b, lo, hi, P, mode, entry, switched, single);
		a = b + 1;
	} else {
		Pbot = mode[0] == HI ? hi[0] : lo[0];
	}
	while (a < L) {
		double sum = vs[a];
		b = a;
		while (b + 1 < L && mode[b + 1] == BOND)
			sum += vs[++b];
		double Ptop = b + 1 < L ? (mode[b + 1] == HI ? hi[b + 1] : lo[b + 1]) : 0.0;
		double n = (double)(b - a + 1);
		double vc = (m * sum + Pbot - Ptop) / (n * m);
		int check = !(changed && single);
		if (check) {
			signed char nm = slip_mode(mode[a], below - vc, lo[a], hi[a]);
			if (nm != mode[a]) {
				switch_mode(L, mode, entry, switched, a, nm);
				changed = 1;
				check = !single;
			}
		}
		/* the bonded contacts a + 1..b checked as their impulses come */
		double Pj = Pbot;
		for (int j = a; j < b; j++) {
			P[j] = Pj;
			v[j] = vc;
			Pj -= m * (vc - vs[j]);
			if (check && bond_switch(L, j + 1, Pj, lo, hi, mode, entry, switched)) {
				changed = 1;
				check = !single;
			}
		}
		P[b] = Pj;
		v[b] = vc;
		below = vc;
		Pbot = Ptop;
		a = b + 1;
	}
	return changed;
}

/* chain_clusters with the modes switched until consistent. With entry
 * (else NULL): returns 1 if a contact that was not bonded on entry ended
 * in another mode (a slipping contact stopped or reversed), entry[] then
 * holding the modes on entry; 0 otherwise (entry[] then unset: the modes
 * are copied only at the first switch, which most solves never make).
 * Inlined into its four calls: called, it cost the curve 3 % more. */
static inline __attribute__((always_inline)) int
chain_solve(int L, double m, const double *restrict vs, double v0, const double *restrict lo,
	    const double *restrict hi, double *restrict P, double *restrict v,
	    signed char *restrict mode, signed char *restrict entry)
{
	int changed = 0, switched = 0;
	for (int iter = 0; iter < 4 * L + 8; iter++) {
		changed = chain_round(L, m, vs, v0, lo, hi, P, v, mode, entry, &switched, iter >= L);
		if (!changed)
			break;
	}
	/* every cluster's bottom already carries its fixed impulse, unless
	 * the iteration stopped on a switch it did not follow */
	if (changed)
		for (int j = 0; j < L; j++)
			if (mode[j] != BOND)
				P[j] = mode[j] == HI ? hi[j] : lo[j];
	int stopped = 0;
	if (switched && entry)
		for (int j = 0; j < L; j++)
			stopped |= entry[j] != BOND && mode[j] != entry[j];
	return stopped;
}

/* Friction of one sub-step with its slip reversals located (the split
 * method's option `friction_events`). The set-valued solve alone applies
 * the friction of a contact's mode at the sub-step's end over the whole
 * sub-step: where a slipping contact stops or reverses inside it, that is
 * a bias of up to 2 mu P_n per event, first order in h (in v: 1.1 % at
 * 155 deg cw with 12 sub-steps). With the normal impulses spread evenly
 * over the sub-step and the deck's velocity linear in it (dv0 at the start
 * of the velocities' interval, dv1 at its end), every relative velocity is
 * linear in time while the modes hold, so the first zero crossing of a
 * slipping contact under the old modes is found exactly; the column is
 * advanced to it, that contact is bonded there, and the rest of the
 * sub-step is solved again from it (stick or slip the other way), at most
 * a few times a sub-step. This is the event location of event-driven
 * schemes (Pfeiffer & Glocker, Multibody Dynamics with Unilateral
 * Contacts, 1996) applied to friction inside Moreau's time-stepping. */
#define FRICTION_MAX_EVENTS 8
static void friction_events(int L, double m, const double *vs, double dv0, double dv1,
			    const double *lo, const double *hi, double *P, double *v,
			    signed char *mode)
{
	signed char old[SIM_MAX_LAYERS];
	double va[SIM_MAX_LAYERS], Pacc[SIM_MAX_LAYERS], los[SIM_MAX_LAYERS], his[SIM_MAX_LAYERS],
		Po[SIM_MAX_LAYERS], vo[SIM_MAX_LAYERS];
	double rest = 1.0, d0 = dv0;
	int stopped = chain_solve(L, m, vs, dv1, lo, hi, P, v, mode, old);
	if (!stopped)
		return; /* no slipping contact stopped: nothing to locate */
	for (int j = 0; j < L; j++) {
		va[j] = vs[j];
		Pacc[j] = 0.0;
		los[j] = lo[j];
		his[j] = hi[j];
	}
	for (int ev = 0;; ev++) {
		if (ev > 0)
			stopped = chain_solve(L, m, va, dv1, los, his, P, v, mode, old);
		if (!stopped || ev == FRICTION_MAX_EVENTS)
			break;
		/* the rest of the sub-step under the old modes: the first
		 * slipping contact whose relative velocity crosses zero */
		chain_clusters(L, m, va, dv1, los, his, Po, vo, old);
		double tmin = 1.0;
		int jmin = -1;
		for (int j = 0; j < L; j++) {
			if (old[j] == BOND)
				continue;
			double s0 = (j == 0 ? d0 : va[j - 1]) - va[j];
			double s1 = (j == 0 ? dv1 : vo[j - 1]) - vo[j];
			/* a reversal, beyond the solve's velocity tolerance at
			 * both ends (a contact at the limit with no relative
			 * motion, as inside a uniform stack sliding as one, has
			 * none to locate: round-off must not place events) */
			if (old[j] == HI ? !(s1 < -1e-13 && s0 > 1e-13) : !(s1 > 1e-13 && s0 < -1e-13))
				continue;
			double t = s0 / (s0 - s1);
			if (t < tmin) {
				tmin = t;
				jmin = j;
			}
		}
		if (jmin < 0 || !(tmin > 0.0))
			break;
		/* advance to it; the contact sticks there, the others keep
		 * their modes; solve the rest */
		for (int j = 0; j < L; j++) {
			va[j] += tmin * (vo[j] - va[j]);
			Pacc[j] += tmin * Po[j];
			los[j] *= 1.0 - tmin;
			his[j] *= 1.0 - tmin;
			mode[j] = old[j];
		}
		mode[jmin] = BOND;
		d0 += tmin * (dv1 - d0);
		rest *= 1.0 - tmin;
	}
	if (rest < 1.0)
		for (int j = 0; j < L; j++)
			P[j] += Pacc[j];
}

#endif
