/*
 * estimator.c - transport velocity (MODEL.md "Observables"): the mean feed
 * displacement is sampled at the excitation period boundaries, i.e. where
 * the rotor's angle relative to the trough, phi - alpha, crosses a multiple
 * of 2 pi (located within the step on cubic Hermite interpolants); the
 * estimate is the slope between the first boundary after the transient and
 * the latest one, so the periodic part of the motion cancels exactly.
 */
#include <math.h>

#include "estimator.h"
#include "feed.h"
#include "ode.h"

/* phi - alpha and its rate, and the mean feed position and its rate. */
static void period_probe(const model *md, const model_ctl *ctl, double t, const double *y,
			 double *psi, double *psid, double *X, double *Xd)
{
	double q[NQ_FULL], qd[NQ_FULL];
	model_full_coords(md, ctl, t, y, q, qd);
	*psi = q[Q_PHI] - q[Q_ALPHA];
	*psid = qd[Q_PHI] - qd[Q_ALPHA];
	*X = md->nf > 0 ? feed_mean_xi(md, y, -1) : 0.0;
	*Xd = feed_mean_xi_rate(md, y);
}

void estimator_probe(estimator *e, const model *md, const model_ctl *ctl, double t,
		     const double *y)
{
	period_probe(md, ctl, t, y, &e->psi_prev, &e->psid_prev, &e->X_prev, &e->Xd_prev);
}

void estimator_init(estimator *e, const model *md, const model_ctl *ctl, double t,
		    const double *y, double start)
{
	*e = (estimator){0};
	estimator_probe(e, md, ctl, t, y);
	estimator_restart(e, start);
}

void estimator_restart(estimator *e, double start)
{
	e->pending = 1;
	e->start = start;
}

static void on_boundary(estimator *e, double tb, double Xb)
{
	if (e->pending) {
		if (tb + 1e-12 < e->start)
			return;
		e->pending = 0;
		e->n_bound = 0;
		e->tb_first = e->tb_last = tb;
		e->Xb_first = e->Xb_last = Xb;
		return;
	}
	e->tb_prev = e->tb_last;
	e->Xb_prev = e->Xb_last;
	e->tb_last = tb;
	e->Xb_last = Xb;
	e->n_bound++;
}

void estimator_step(estimator *e, const model *md, const model_ctl *ctl, double t0, double t1,
		    const double *y)
{
	double psi, psid, X, Xd;
	period_probe(md, ctl, t1, y, &psi, &psid, &X, &Xd);
	double H = t1 - t0;
	double n0 = floor(e->psi_prev / (2 * M_PI)), n1 = floor(psi / (2 * M_PI));
	if (n0 != n1 && H > 0.0) {
		int up = n1 > n0;
		for (double nb = up ? n0 + 1 : n0; up ? nb <= n1 : nb > n1; nb += up ? 1 : -1) {
			double target = nb * 2 * M_PI, lo = 0.0, hi = 1.0;
			for (int it = 0; it < 60; it++) {
				double mid = 0.5 * (lo + hi);
				double v = ode_hermite(e->psi_prev, e->psid_prev, psi, psid, H, mid);
				if ((v < target) == up)
					lo = mid;
				else
					hi = mid;
			}
			double u = 0.5 * (lo + hi);
			on_boundary(e, t0 + u * H, ode_hermite(e->X_prev, e->Xd_prev, X, Xd, H, u));
		}
	}
	e->psi_prev = psi;
	e->psid_prev = psid;
	e->X_prev = X;
	e->Xd_prev = Xd;
}

void estimator_read(const estimator *e, estimate *out)
{
	if (!e->pending && e->n_bound >= 1) {
		out->transport_velocity = (e->Xb_last - e->Xb_first) / (e->tb_last - e->tb_first);
		out->transport_periods = e->n_bound;
		out->feed_velocity = (e->Xb_last - e->Xb_prev) / (e->tb_last - e->tb_prev);
		out->period = e->tb_last - e->tb_prev;
	} else {
		out->transport_velocity = NAN;
		out->transport_periods = 0;
		out->feed_velocity = NAN;
		out->period = NAN;
	}
}
