/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * run_coupled.c - `convsim run --set feed_model=liggghts`: the machine
 * of the options coupled to a LIGGGHTS bed (couple.h) every
 * --coupling-steps machine steps, with progress on stderr and a JSON
 * summary on stdout: the transport velocity and the balances of momentum
 * and energy between machine and bed. The bed is dem_bed_spec_default's,
 * `layers` mean diameters deep. Linked into convsim-mpi where LIGGGHTS is
 * installed (the Makefile), to which the plain convsim hands such a run
 * (cli/handover.h).
 *
 * Under `mpirun -n N` LIGGGHTS runs the bed on the N ranks (its domain
 * split along the cell); every rank integrates the same machine (the core
 * is deterministic and cheap) and sets the same load, since the bed's
 * totals are LIGGGHTS's global reductions; rank 0 alone prints.
 *
 * dt = 0 stands for a machine step of DEM_COUPLED_DT (couple.h), as in
 * the daemon.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "cli.h"
#include "couple.h"
#include "decimal.h"
#include "dem.h"

static void run_summary(const cli_opts *o, const dem_coupled *c, const dem_bed_spec *spec, int ranks,
			int failed, double cpu, double wall)
{
	dem_coupled_status st;
	sim_status ms;
	dem_coupled_get(c, &st);
	sim_get_status(dem_coupled_machine(c), &ms);
	printf("{\n  \"preset\": \"%s\",\n  \"feed_model\": \"liggghts\",\n", o->preset);
	printf("  \"duration\": %.17g,\n  \"transient\": %.17g,\n", st.t, o->sc.transient);
	printf("  \"coupling_steps\": %d,\n  \"coupling_interval\": %.17g,\n", o->coupling_steps,
	       st.interval);
	printf("  \"grains\": %d,\n  \"bed_scale\": %.17g,\n", spec->grains, st.scale);
	printf("  \"mpi_ranks\": %d,\n", ranks);
	printf("  \"transport_velocity\": %.17g,\n", st.transport_velocity);
	printf("  \"rotor_speed\": %.17g,\n", ms.rotor_speed);
	printf("  \"balance\": {\"weight\": %.17g, \"load_mean_y\": %.17g, ", st.weight, st.load_mean_y);
	printf("\"impulse_machine\": [%.17g, %.17g], \"impulse_bed\": [%.17g, %.17g], ",
	       st.impulse_machine[0], st.impulse_machine[1], st.impulse_bed[0], st.impulse_bed[1]);
	printf("\"work_machine\": %.17g, \"work_bed\": %.17g, \"bed_energy\": %.17g, ", st.work_machine,
	       st.work_bed, st.bed_energy);
	printf("\"bed_dissipated\": %.17g, \"coupling_energy_error\": %.17g, ",
	       st.work_bed - st.bed_energy, st.work_machine + st.work_bed);
	printf("\"machine_residual\": %.17g, \"machine_input\": %.17g},\n", st.machine_residual,
	       ms.e_input);
	printf("  \"intervals\": %ld,\n  \"dem_cpu_seconds\": %.17g,\n", st.intervals, st.dem_cpu_seconds);
	printf("  \"cpu_seconds\": %.17g,\n  \"wall_seconds\": %.17g,\n", cpu, wall);
	printf("  \"error\": %s", failed ? "true" : "null");
	cli_put_feed_pick(stdout, o);
	printf("\n}\n");
}

int cli_run_coupled(const cli_opts *o)
{
	if (o->out) {
		fprintf(stderr, "convsim run: --out is not offered with feed_model=liggghts (the summary "
				"only)\n");
		return 2;
	}
	char msg[300];
	int mpi_on = 0, rank = 0, ranks = 1;
	MPI_Comm world = MPI_COMM_WORLD;
	MPI_Initialized(&mpi_on);
	if (!mpi_on)
		MPI_Init(NULL, NULL);
	MPI_Comm_rank(world, &rank);
	MPI_Comm_size(world, &ranks);
	dem_bed_spec spec;
	dem_bed_spec_default(&o->p, (double)o->sc.layers, &spec);
	/* CONVSIM_DEM_GRAINS=N: a bed of N grains in the same cell in place of
	 * `layers` diameters' worth (the cost bench's beds past 64 layers) */
	const char *grains = getenv("CONVSIM_DEM_GRAINS");
	if (grains && *grains) {
		double n; /* decimal.h's rule: not ' 5', +5x or 0x5 */
		if (!sim_decimal(grains, &n) || n < 1 || n > 1000000 || n != floor(n)) {
			if (rank == 0)
				fprintf(stderr, "convsim run: CONVSIM_DEM_GRAINS must be an integer in [1, "
						"1000000], got '%s'\n", grains);
			MPI_Finalize();
			return 2;
		}
		spec.grains = (int)n;
	}
	double w0 = cli_now(), c0 = dem_cpu_now();
	sim_method m = o->m;
	if (m.dt == 0.0)
		m.dt = DEM_COUPLED_DT;
	dem_coupled *c = dem_coupled_new(&o->p, &o->sc, &m, &spec, o->coupling_steps,
					 o->sc.transient, ranks > 1 ? &world : NULL, msg, sizeof msg);
	if (!c) {
		if (rank == 0)
			fprintf(stderr, "convsim run: %s\n", msg);
		MPI_Finalize();
		return 2;
	}
	cli_progress pr;
	cli_progress_start(&pr, "run", o->quiet || rank > 0, 1.0);
	int failed = 0;
	for (int i = 1; i <= 100 && !failed; i++) {
		double t = o->duration * i / 100;
		failed = dem_coupled_advance(c, t, NULL, msg, sizeof msg) != 0;
		cli_progress_update(&pr, t, o->duration, "s simulated", "");
	}
	double wall = cli_now() - w0, cpu = dem_cpu_now() - c0;
	char done[96];
	snprintf(done, sizeof done, "%g s simulated in %.1f s", o->duration, wall);
	cli_progress_end(&pr, done, 0);
	if (rank == 0) {
		run_summary(o, c, &spec, ranks, failed, cpu, wall);
		if (failed)
			fprintf(stderr, "convsim run: %s\n", msg);
	}
	dem_coupled_free(c);
	MPI_Finalize();
	return failed ? 1 : 0;
}

void cli_liggghts_here(const cli_opts *o, sim_feed_liggghts *lg)
{
	dem_bed_spec bed;
	dem_bed_spec_default(&o->p, (double)o->sc.layers, &bed);
	*lg = (sim_feed_liggghts){
		.available = 1,
		.cost = dem_bed_spec_cost(&bed),
		.max_cost = o->max_dem_cost,
		.limit = "--max-dem-cost",
	};
}
