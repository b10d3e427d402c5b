/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * estimator.c - transport velocity (docs/MODEL.md "Observables"): the mean feed
 * displacement is sampled at the excitation period boundaries, i.e. where
 * the rotor's angle relative to the trough, phi - alpha, crosses a multiple
 * of 2 pi (located within the step on cubic Hermite interpolants); the
 * estimate is the slope between the first boundary after the transient and
 * the latest one, so the periodic part of the motion cancels exactly.
 */
#include <math.h>
#include <string.h>

#include "estimator.h"
#include "feed.h"
#include "ode.h"

/* phi - alpha and its rate, the mean feed position and its rate, the
 * drive's input energy, and the velocity of the trough's centre of mass
 * (V, 2). */
static void period_probe(const model *md, const double *y, const double q[NQ_FULL],
			 const double qd[NQ_FULL], double *psi, double *psid, double *X, double *Xd,
			 double *E, double V[2])
{
	*psi = q[Q_PHI] - q[Q_ALPHA];
	*psid = qd[Q_PHI] - qd[Q_ALPHA];
	*X = md->nf > 0 ? feed_mean_xi(md, y, -1) : 0.0;
	*Xd = feed_mean_xi_rate(md, y);
	*E = y[2 * md->npos + ACC_IN];
	V[0] = qd[Q_X];
	V[1] = qd[Q_Y];
}

void estimator_init(estimator *e, const model *md, const model_ctl *ctl, double t,
		    const double *y, double start)
{
	*e = (estimator){0};
	double q[NQ_FULL], qd[NQ_FULL], V[2];
	model_full_coords(md, ctl, t, y, q, qd);
	period_probe(md, y, q, qd, &e->psi_prev, &e->psid_prev, &e->X_prev, &e->Xd_prev,
		     &e->E_prev, V);
	estimator_restart(e, start);
}

void estimator_restart(estimator *e, double start)
{
	e->pending = 1;
	e->start = start;
}

/* Keep boundary (tb, Xb) as a batch edge if it is a stride-th one. */
static void record(estimator *e, double tb, double Xb)
{
	if (e->n_bound % e->stride != 0)
		return;
	if (e->n_rec == EST_RECORDS) {
		for (int i = 0; i < EST_RECORDS / 2; i++) {
			e->rec_t[i] = e->rec_t[2 * i];
			e->rec_X[i] = e->rec_X[2 * i];
		}
		e->n_rec = EST_RECORDS / 2;
		e->stride *= 2;
		if (e->n_bound % e->stride != 0)
			return;
	}
	e->rec_t[e->n_rec] = tb;
	e->rec_X[e->n_rec++] = Xb;
}

/* The error bar's parts from the batch edges (the records and the latest
 * boundary), kept in e->bar: they change only at a boundary. The batch
 * velocities v_i at their mid-times c_i are fitted by a straight line
 * (least squares); its slope times the window's length is the drift D,
 * the scatter s of the residuals gives the standard error of the mean
 * s / sqrt(n) and of the drift. See estimate. */
static void error_bar(estimator *e)
{
	double t[EST_RECORDS + 1], X[EST_RECORDS + 1];
	int n = e->n_rec;
	memcpy(t, e->rec_t, sizeof(double) * (size_t)n);
	memcpy(X, e->rec_X, sizeof(double) * (size_t)n);
	if (e->tb_last > t[n - 1]) {
		t[n] = e->tb_last;
		X[n++] = e->Xb_last;
	}
	int nb = n - 1;
	e->bar.uncertainty = NAN;
	if (nb < 4)
		return;
	double cm = 0.0, vm = 0.0, vi[EST_RECORDS], ci[EST_RECORDS];
	for (int i = 0; i < nb; i++) {
		vi[i] = (X[i + 1] - X[i]) / (t[i + 1] - t[i]);
		ci[i] = 0.5 * (t[i] + t[i + 1]);
		cm += ci[i] / nb;
		vm += vi[i] / nb;
	}
	double scc = 0.0, scv = 0.0;
	for (int i = 0; i < nb; i++) {
		scc += (ci[i] - cm) * (ci[i] - cm);
		scv += (ci[i] - cm) * (vi[i] - vm);
	}
	double slope = scv / scc, ss = 0.0;
	for (int i = 0; i < nb; i++) {
		double r = vi[i] - vm - slope * (ci[i] - cm);
		ss += r * r;
	}
	double s = sqrt(ss / (nb - 2)), window = t[n - 1] - t[0];
	double se = s / sqrt((double)nb);
	e->bar.se_drift = s / sqrt(scc) * window;
	e->bar.drift = slope * window;
	e->bar.uncertainty = sqrt(se * se + 0.25 * e->bar.drift * e->bar.drift);
}

static void on_boundary(estimator *e, double tb, double Xb, double Eb)
{
	if (e->pending) {
		if (tb + 1e-12 < e->start)
			return;
		e->pending = 0;
		e->n_bound = 0;
		e->tb_first = e->tb_last = tb;
		e->Xb_first = e->Xb_last = Xb;
		e->Eb_first = e->Eb_last = Eb;
		e->n_rec = 0;
		e->stride = 1;
		e->speed_max = 0.0;
		record(e, tb, Xb);
		e->bar.uncertainty = NAN;
		return;
	}
	e->tb_prev = e->tb_last;
	e->Xb_prev = e->Xb_last;
	e->tb_last = tb;
	e->Xb_last = Xb;
	e->Eb_last = Eb;
	e->n_bound++;
	record(e, tb, Xb);
	error_bar(e);
}

/* Where in the step (u in [0, 1]) the rotor's phase, the cubic Hermite of
 * its ends (p0, v0; p1, v1 over H), passes target, rising if up: Newton's
 * method on the cubic from the chord's estimate, inside the bracket it
 * keeps (a bisection step where Newton would leave it), to the last few
 * ulps; 4 or 5 evaluations where bisection to the same precision took 60
 * (2 % of the defaults' time). */
static double crossing(double p0, double v0, double p1, double v1, double H, double target,
		       int up)
{
	double lo = 0.0, hi = 1.0, u = p1 != p0 ? (target - p0) / (p1 - p0) : 0.5;
	if (!(u > 0.0 && u < 1.0))
		u = 0.5;
	for (int it = 0; it < 64; it++) {
		double f = ode_hermite(p0, v0, p1, v1, H, u) - target;
		if (f == 0.0)
			return u;
		if ((f < 0.0) == up)
			lo = u;
		else
			hi = u;
		/* the cubic's rate in u */
		double u2 = u * u;
		double d = 6.0 * (u2 - u) * (p0 - p1) + (3.0 * u2 - 4.0 * u + 1.0) * H * v0 +
			   (3.0 * u2 - 2.0 * u) * H * v1;
		double next = u - f / d;
		if (!(next > lo && next < hi))
			next = 0.5 * (lo + hi);
		if (fabs(next - u) <= 4e-16 || hi - lo <= 4e-16)
			return next;
		u = next;
	}
	return u;
}

void estimator_step(estimator *e, const model *md, double t0, double t1, const double *y,
		    const double q[NQ_FULL], const double qd[NQ_FULL])
{
	double psi, psid, X, Xd, E, V[2];
	period_probe(md, y, q, qd, &psi, &psid, &X, &Xd, &E, V);
	/* the speed by hypot only where it may raise the maximum: V^2 is
	 * within a few ulps of hypot's square, so the maximum is the same */
	double sm = e->speed_max;
	if (!e->pending && V[0] * V[0] + V[1] * V[1] >= sm * sm * (1.0 - 1e-12))
		e->speed_max = fmax(sm, hypot(V[0], V[1]));
	double H = t1 - t0;
	double n0 = floor(e->psi_prev / (2 * M_PI)), n1 = floor(psi / (2 * M_PI));
	/* a step passes a few periods at most; a phase that jumped by more
	 * (a state read from a damaged checkpoint) starts the estimate over
	 * rather than walking every boundary in between */
	if (fabs(n1 - n0) > EST_STEP_PERIODS) {
		estimator_restart(e, t1);
		n0 = n1;
	}
	if (n0 != n1 && H > 0.0) {
		int up = n1 > n0;
		for (double nb = up ? n0 + 1 : n0; up ? nb <= n1 : nb > n1; nb += up ? 1 : -1) {
			double u = crossing(e->psi_prev, e->psid_prev, psi, psid, H, nb * 2 * M_PI, up);
			on_boundary(e, t0 + u * H, ode_hermite(e->X_prev, e->Xd_prev, X, Xd, H, u),
				    e->E_prev + u * (E - e->E_prev));
		}
	}
	e->psi_prev = psi;
	e->psid_prev = psid;
	e->X_prev = X;
	e->Xd_prev = Xd;
	e->E_prev = E;
}

void estimator_read(const estimator *e, estimate *out)
{
	if (!e->pending && e->n_bound >= 1) {
		double span = e->tb_last - e->tb_first;
		out->transport_velocity = (e->Xb_last - e->Xb_first) / span;
		out->transport_periods = e->n_bound;
		out->feed_velocity = (e->Xb_last - e->Xb_prev) / (e->tb_last - e->tb_prev);
		out->period = e->tb_last - e->tb_prev;
		double sense = e->psid_prev < 0.0 ? -1.0 : 1.0;
		out->rotor_speed_mean = sense * 2.0 * M_PI * e->n_bound / span;
		out->power_mean = (e->Eb_last - e->Eb_first) / span + 0.0;
		out->torque_mean = out->power_mean / out->rotor_speed_mean + 0.0;
		/* steady: see estimate; the trough's speed grows within a period */
		double v = fabs(out->transport_velocity);
		out->uncertainty = e->bar.uncertainty;
		out->steady = !isnan(e->bar.uncertainty) && e->n_bound >= 8 &&
			      (fabs(e->bar.drift) <= 3.0 * e->bar.se_drift ||
			       fabs(e->bar.drift) <= 0.005 * v) &&
			      e->bar.uncertainty <= 0.005 * e->speed_max + 0.01 * v;
	} else {
		out->transport_velocity = NAN;
		out->transport_periods = 0;
		out->feed_velocity = NAN;
		out->period = NAN;
		out->uncertainty = NAN;
		out->steady = 0;
		out->rotor_speed_mean = out->torque_mean = out->power_mean = NAN;
	}
}

double estimator_blocked_bar(const estimator *e, int min_blocks)
{
	double u = e->bar.uncertainty, half = 0.5 * e->bar.drift, se2 = u * u - half * half;
	for (int k = 2; k <= 4 && (e->n_rec - 1) / k >= min_blocks; k *= 2) {
		int nb = (e->n_rec - 1) / k;
		double v[EST_RECORDS], mean = 0.0, span = 0.0, ss = 0.0;
		for (int i = 0; i < nb; i++) {
			double dt = e->rec_t[(i + 1) * k] - e->rec_t[i * k];
			v[i] = (e->rec_X[(i + 1) * k] - e->rec_X[i * k]) / dt;
			mean += v[i] * dt;
			span += dt;
		}
		mean /= span;
		for (int i = 0; i < nb; i++)
			ss += (v[i] - mean) * (v[i] - mean);
		se2 = fmax(se2, ss / (nb - 1) / nb);
	}
	return sqrt(se2 + half * half);
}
