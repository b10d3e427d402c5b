/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The `grains` candidate of `make fast-feed-check` (docs/feed-models.md
 * "What was tried"): a reduced bed on a recorded deck orbit, outside core/.
 *
 *   fast_feed_bed ORBIT.csv E_LO E_HI MU N [T0 T1]
 *
 * ORBIT.csv: a one-way convsim run's trajectory (`-o FILE.csv -r 4000`);
 * its columns t, deck_x and deck_y are read. The bed is N grains, each a
 * point mass on the deck, not acting on each other:
 *   - free flight under gravity;
 *   - an impact on the deck whose normal restitution is drawn anew at each
 *     impact, uniform in [E_LO, E_HI]: a grain of a bed lands on the deck
 *     or on grains at a random spot and keeps a random share of its
 *     rebound. A Coulomb impulse MU times the normal one acts against the
 *     slip, at most what stops it;
 *   - riding on the deck while it presses on it (g + the deck's vertical
 *     acceleration > 0), sticking while friction can hold it, else
 *     sliding with Coulomb friction MU.
 * v is the grains' mean displacement over [T0, T1] (1 and 3 s by default:
 * the DEM's window) over the time. Each grain has its own fixed random
 * sequence, so a run is reproducible. The step is half the orbit's.
 * Prints "v cpu_s" (the CPU of the integration, not of reading the file). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define G 9.81
#define LINE 8192

struct orbit {
    double *x, *y, h, t0; /* deck position samples, their step and first time */
    double *vx, *vy, *ax, *ay; /* velocity and acceleration at the samples */
    int n;
};

struct deck {
    double x, y, vx, vy, ax, ay;
};

/* Index of column NAME in a CSV header, -1 if absent. */
static int column(const char *header, const char *name)
{
    char buf[LINE];
    int i = 0;
    snprintf(buf, sizeof buf, "%s", header);
    for (char *tok = strtok(buf, ",\n"); tok; tok = strtok(NULL, ",\n"), i++)
        if (strcmp(tok, name) == 0)
            return i;
    return -1;
}

static int orbit_read(const char *path, struct orbit *o)
{
    FILE *f = fopen(path, "r");
    char line[LINE];
    int cap = 1 << 16, ct, cx, cy;
    double t0 = 0;
    if (!f || !fgets(line, sizeof line, f))
        return -1;
    ct = column(line, "t");
    cx = column(line, "deck_x");
    cy = column(line, "deck_y");
    o->x = malloc(sizeof(double) * cap);
    o->y = malloc(sizeof(double) * cap);
    o->n = 0;
    while (ct >= 0 && cx >= 0 && cy >= 0 && fgets(line, sizeof line, f)) {
        double v[3] = {0, 0, 0};
        char *p = line;
        int last = ct > cx ? (ct > cy ? ct : cy) : (cx > cy ? cx : cy);
        for (int i = 0; p && i <= last; i++, p = strchr(p, ','), p = p ? p + 1 : p) {
            if (i == ct)
                v[0] = strtod(p, NULL);
            if (i == cx)
                v[1] = strtod(p, NULL);
            if (i == cy)
                v[2] = strtod(p, NULL);
        }
        if (o->n == cap) {
            cap *= 2;
            o->x = realloc(o->x, sizeof(double) * cap);
            o->y = realloc(o->y, sizeof(double) * cap);
        }
        if (o->n == 0)
            o->t0 = t0 = v[0];
        if (o->n == 1)
            o->h = v[0] - t0;
        o->x[o->n] = v[1];
        o->y[o->n] = v[2];
        o->n++;
    }
    fclose(f);
    return o->n > 4 && o->h > 0 ? 0 : -1;
}

/* Velocity and acceleration at the samples, from central differences. */
static void orbit_derive(struct orbit *o)
{
    double h = o->h, *X = o->x, *Y = o->y;
    o->vx = calloc(o->n, sizeof(double));
    o->vy = calloc(o->n, sizeof(double));
    o->ax = calloc(o->n, sizeof(double));
    o->ay = calloc(o->n, sizeof(double));
    for (int i = 1; i < o->n - 1; i++) {
        o->vx[i] = (X[i + 1] - X[i - 1]) / (2 * h);
        o->vy[i] = (Y[i + 1] - Y[i - 1]) / (2 * h);
        o->ax[i] = (X[i + 1] - 2 * X[i] + X[i - 1]) / (h * h);
        o->ay[i] = (Y[i + 1] - 2 * Y[i] + Y[i - 1]) / (h * h);
    }
}

/* The deck at time t: every quantity linear between samples. */
static struct deck deck_at(const struct orbit *o, double t)
{
    struct deck d;
    double s = (t - o->t0) / o->h, w;
    int i = (int)s;
    if (i < 1)
        i = 1;
    if (i > o->n - 3)
        i = o->n - 3;
    w = s - i;
#define LERP(a) ((a)[i] + w * ((a)[i + 1] - (a)[i]))
    d.x = LERP(o->x);
    d.y = LERP(o->y);
    d.vx = LERP(o->vx);
    d.vy = LERP(o->vy);
    d.ax = LERP(o->ax);
    d.ay = LERP(o->ay);
#undef LERP
    return d;
}

struct grain {
    double x, y, vx, vy;
    int riding; /* on the deck (not in flight) */
    int stuck;  /* riding without slip */
    unsigned long long rng;
};

struct model {
    double e_lo, e_hi, mu;
};

static double uniform(struct grain *g)
{
    g->rng ^= g->rng << 13;
    g->rng ^= g->rng >> 7;
    g->rng ^= g->rng << 17;
    return (double)(g->rng >> 11) / 9007199254740992.0;
}

/* Horizontal motion while riding: stick while friction can hold the grain
 * to the deck, else slide against the slip. */
static void ride_x(struct grain *g, const struct deck *d, double n, double mu, double dt)
{
    double u = g->vx - d->vx;
    if (g->stuck) {
        if (fabs(d->ax) <= mu * n) {
            g->vx = d->vx;
            return;
        }
        g->stuck = 0;
        u = d->ax > 0 ? -1e-12 : 1e-12;
    }
    double vx = g->vx - mu * n * (u > 0 ? 1 : -1) * dt;
    if ((vx - d->vx) * u <= 0) { /* the slip ends inside the step */
        g->vx = d->vx;
        g->stuck = 1;
    } else {
        g->vx = vx;
    }
}

/* An impact: restitution drawn in [e_lo, e_hi], a Coulomb impulse against
 * the slip, at most what stops it; a rebound too slow to leave (under
 * 2 mm/s) leaves the grain riding. */
static void impact(struct grain *g, const struct deck *d, const struct model *m)
{
    double un = g->vy - d->vy, ut = g->vx - d->vx;
    double e = m->e_lo + (m->e_hi - m->e_lo) * uniform(g);
    double jt = m->mu * (1 + e) * -un;
    if (fabs(ut) <= jt)
        g->vx = d->vx;
    else
        g->vx -= jt * (ut > 0 ? 1 : -1);
    g->vy = d->vy - e * un;
    g->y = d->y;
    if (-e * un < 2e-3) {
        g->riding = 1;
        g->vy = d->vy;
        g->stuck = g->vx == d->vx;
    }
}

static void step(struct grain *g, const struct orbit *o, const struct model *m, double t,
                 double dt)
{
    struct deck d = deck_at(o, t + dt);
    if (g->riding) {
        double n = G + d.ay;
        if (n > 0) {
            ride_x(g, &d, n, m->mu, dt);
            g->x += g->vx * dt;
            g->y = d.y;
            g->vy = d.vy;
            return;
        }
        g->riding = g->stuck = 0; /* the deck falls faster than g: lift-off */
    }
    g->vy -= G * dt;
    g->x += g->vx * dt;
    g->y += g->vy * dt;
    if (g->y <= d.y && g->vy < d.vy)
        impact(g, &d, m);
}

/* Mean velocity of n grains over [t0, t1]; every grain starts at rest on
 * the deck at t = 0. */
static double bed_velocity(const struct orbit *o, const struct model *m, int n, double t0,
                           double t1)
{
    double dt = o->h / 2, sum = 0;
    long s0 = lround(t0 / dt), s1 = lround(t1 / dt);
    for (int k = 0; k < n; k++) {
        struct deck d = deck_at(o, o->t0);
        struct grain g = {d.x, d.y, d.vx, d.vy, 1, 1, 0x9E3779B97F4A7C15ULL * (k + 1)};
        double xa = g.x;
        for (long s = 0; s < s1; s++) {
            if (s == s0)
                xa = g.x;
            step(&g, o, m, o->t0 + s * dt, dt);
        }
        sum += (g.x - xa) / ((s1 - s0) * dt);
    }
    return sum / n;
}

int main(int argc, char **argv)
{
    struct orbit o;
    struct model m;
    double t0 = 1, t1 = 3;
    if (argc != 6 && argc != 8) {
        fprintf(stderr, "usage: fast_feed_bed ORBIT.csv E_LO E_HI MU N [T0 T1]\n");
        return 2;
    }
    if (orbit_read(argv[1], &o) != 0) {
        fprintf(stderr, "fast_feed_bed: no t, deck_x, deck_y rows in %s\n", argv[1]);
        return 2;
    }
    m.e_lo = atof(argv[2]);
    m.e_hi = atof(argv[3]);
    m.mu = atof(argv[4]);
    int n = atoi(argv[5]);
    if (argc == 8) {
        t0 = atof(argv[6]);
        t1 = atof(argv[7]);
    }
    if (t1 > (o.n - 4) * o.h)
        t1 = (o.n - 4) * o.h;
    if (n < 1 || t0 < 0 || t1 <= t0) {
        fprintf(stderr, "fast_feed_bed: N >= 1 and 0 <= T0 < T1 within the orbit\n");
        return 2;
    }
    clock_t c0 = clock();
    orbit_derive(&o);
    double v = bed_velocity(&o, &m, n, t0, t1);
    printf("%.9g %.6f\n", v, (double)(clock() - c0) / CLOCKS_PER_SEC);
    free(o.x);
    free(o.y);
    free(o.vx);
    free(o.vy);
    free(o.ax);
    free(o.ay);
    return 0;
}
