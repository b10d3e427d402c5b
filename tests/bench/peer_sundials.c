/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peer_sundials.c - SUNDIALS' CVODE and ARKODE (ERKStep) as core
 * integrator descriptors (peer.h; Hindmarsh et al., "SUNDIALS: Suite of
 * nonlinear and differential/algebraic equation solvers", ACM TOMS 31,
 * 2005; the CVODE and ARKODE user guides of SUNDIALS 6.4): one internal
 * step per call (CV_ONE_STEP / ARK_ONE_STEP), the stop time set to the
 * caller's t_max, scalar rtol with an absolute tolerance vector that
 * leaves the energy accumulators out (peer_atol_vector), largest step
 * 2e-3 s, the libraries' defaults otherwise (CVODE: at most 7 error-test
 * and 10 convergence failures in one step, then a failure; no smallest
 * step). cvode-adams: Adams-Moulton with the fixed-point iteration;
 * cvode-bdf: BDF with Newton and the dense direct solver on CVODE's own
 * difference-quotient Jacobian; arkode-erk: ERKStep's default explicit
 * table of order 4. Dense output (CVodeGetDky, ERKStepGetDky) serves
 * interpolation. A reset re-initialises the solver from the caller's state
 * at the next step.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "peer.h"

#define PEER_HMAX 2e-3

enum { K_CVODE_ADAMS, K_CVODE_BDF, K_ARKODE_ERK };

typedef struct sun_peer {
	peer_ws pw; /* first: peer_of reads it */
	int kind;
	SUNContext ctx;
	void *mem;
	N_Vector y, atol, tmp;
	SUNMatrix A;
	SUNLinearSolver LS;
	SUNNonlinearSolver NLS;
} sun_peer;

static int sun_rhs(realtype t, N_Vector y, N_Vector ydot, void *user_data)
{
	sun_peer *w = user_data;
	double *dy = N_VGetArrayPointer(ydot);
	dyn_rhs(w->pw.sys, t, N_VGetArrayPointer(y), dy);
	for (int i = 0; i < w->pw.nerr; i++)
		if (!isfinite(dy[i]))
			return 1; /* recoverable: the solver retries a shorter step */
	return 0;
}

static void sun_error(int code, const char *module, const char *function, char *msg,
		      void *user_data)
{
	sun_peer *w = user_data;
	snprintf(w->pw.msg, sizeof w->pw.msg, "%s %s (%d): %s", module, function, code, msg);
}

static void sun_peer_free(void *p)
{
	sun_peer *w = p;
	if (!w)
		return;
	if (w->mem && w->kind == K_ARKODE_ERK)
		ERKStepFree(&w->mem);
	else if (w->mem)
		CVodeFree(&w->mem);
	if (w->LS)
		SUNLinSolFree(w->LS);
	if (w->A)
		SUNMatDestroy(w->A);
	if (w->NLS)
		SUNNonlinSolFree(w->NLS);
	if (w->y)
		N_VDestroy(w->y);
	if (w->atol)
		N_VDestroy(w->atol);
	if (w->tmp)
		N_VDestroy(w->tmp);
	if (w->ctx)
		SUNContext_Free(&w->ctx);
	free(w);
}

/* The CVODE solver of kind K_CVODE_ADAMS or K_CVODE_BDF; 0 or -1. */
static int cvode_setup(sun_peer *w)
{
	int adams = w->kind == K_CVODE_ADAMS;
	w->mem = CVodeCreate(adams ? CV_ADAMS : CV_BDF, w->ctx);
	if (!w->mem || CVodeInit(w->mem, sun_rhs, 0.0, w->y) || CVodeSetUserData(w->mem, w) ||
	    CVodeSVtolerances(w->mem, w->pw.rtol, w->atol) ||
	    CVodeSetErrHandlerFn(w->mem, sun_error, w) || CVodeSetMaxStep(w->mem, PEER_HMAX) ||
	    CVodeSetMaxHnilWarns(w->mem, -1))
		return -1;
	if (adams) {
		w->NLS = SUNNonlinSol_FixedPoint(w->y, 0, w->ctx);
		return w->NLS && !CVodeSetNonlinearSolver(w->mem, w->NLS) ? 0 : -1;
	}
	w->A = SUNDenseMatrix(w->pw.n, w->pw.n, w->ctx);
	w->LS = w->A ? SUNLinSol_Dense(w->y, w->A, w->ctx) : NULL;
	return w->LS && !CVodeSetLinearSolver(w->mem, w->LS, w->A) ? 0 : -1;
}

static int arkode_setup(sun_peer *w)
{
	w->mem = ERKStepCreate(sun_rhs, 0.0, w->y, w->ctx);
	if (!w->mem || ERKStepSetUserData(w->mem, w) ||
	    ERKStepSVtolerances(w->mem, w->pw.rtol, w->atol) ||
	    ERKStepSetErrHandlerFn(w->mem, sun_error, w) || ERKStepSetMaxStep(w->mem, PEER_HMAX))
		return -1;
	return 0;
}

static void *sun_peer_alloc(const model *md, const sim_method *cfg)
{
	int kind = strcmp(cfg->name, "cvode-adams") == 0 ? K_CVODE_ADAMS
		   : strcmp(cfg->name, "cvode-bdf") == 0  ? K_CVODE_BDF
		   : strcmp(cfg->name, "arkode-erk") == 0 ? K_ARKODE_ERK
							  : -1;
	sun_peer *w = kind >= 0 ? calloc(1, sizeof *w) : NULL;
	if (!w)
		return NULL;
	w->kind = kind;
	w->pw = (peer_ws){.n = md->n, .nerr = 2 * md->npos, .rtol = cfg->rtol,
			  .atol = cfg->atol, .need_init = 1};
	if (SUNContext_Create(NULL, &w->ctx))
		goto fail;
	w->y = N_VNew_Serial(md->n, w->ctx);
	w->atol = N_VNew_Serial(md->n, w->ctx);
	w->tmp = N_VNew_Serial(md->n, w->ctx);
	if (!w->y || !w->atol || !w->tmp)
		goto fail;
	N_VConst(0.0, w->y);
	peer_atol_vector(&w->pw, N_VGetArrayPointer(w->atol));
	if ((kind == K_ARKODE_ERK ? arkode_setup(w) : cvode_setup(w)) != 0)
		goto fail;
	return w;
fail:
	sun_peer_free(w);
	return NULL;
}

/* Failures counted so far: error tests, and for CVODE convergence. */
static uint64_t sun_rejected(const sun_peer *w)
{
	long netf = 0, ncf = 0;
	if (w->kind == K_ARKODE_ERK) {
		ERKStepGetNumErrTestFails(w->mem, &netf);
	} else {
		CVodeGetNumErrTestFails(w->mem, &netf);
		CVodeGetNumNonlinSolvConvFails(w->mem, &ncf);
	}
	return (uint64_t)(netf + ncf);
}

static int sun_peer_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	sun_peer *w = p;
	const int arkode = w->kind == K_ARKODE_ERK;
	w->pw.sys = sys;
	if (w->pw.need_init) {
		memcpy(N_VGetArrayPointer(w->y), y, sizeof(double) * (size_t)w->pw.n);
		int r = arkode ? ERKStepReInit(w->mem, sun_rhs, *t, w->y)
			       : CVodeReInit(w->mem, *t, w->y);
		if (r < 0)
			return SIM_ESTEP;
		w->pw.need_init = 0;
	}
	if (peer_budget_check(&w->pw, *t) != SIM_OK)
		return SIM_ESTEP;
	double tstop = isfinite(t_max) ? t_max : *t + 1e3, tret = *t;
	int r = arkode ? ERKStepSetStopTime(w->mem, tstop) : CVodeSetStopTime(w->mem, tstop);
	if (r == 0)
		r = arkode ? ERKStepEvolve(w->mem, tstop, w->y, &tret, ARK_ONE_STEP)
			   : CVode(w->mem, tstop, w->y, &tret, CV_ONE_STEP);
	w->pw.rejected = sun_rejected(w);
	if (r < 0)
		return SIM_ESTEP; /* the reason is in w->pw.msg (sun_error) */
	memcpy(y, N_VGetArrayPointer(w->y), sizeof(double) * (size_t)w->pw.n);
	*t = tret;
	w->pw.steps++;
	return SIM_OK;
}

static void sun_peer_interpolate(void *p, double t, double *out)
{
	sun_peer *w = p;
	if (w->kind == K_ARKODE_ERK)
		ERKStepGetDky(w->mem, t, 0, w->tmp);
	else
		CVodeGetDky(w->mem, t, 0, w->tmp);
	memcpy(out, N_VGetArrayPointer(w->tmp), sizeof(double) * (size_t)w->pw.n);
}

const ode_method peer_sundials = {
	.info = {.name = "sundials",
		 .order = 0,
		 .adaptive = 1,
		 .doc = "CVODE or ARKODE ERKStep (benchmark peer)"},
	.dense = 1,
	.alloc = sun_peer_alloc,
	.step = sun_peer_step,
	.interpolate = sun_peer_interpolate,
	.reset = peer_reset,
	.free = sun_peer_free,
};
