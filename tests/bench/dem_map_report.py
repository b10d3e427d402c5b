#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The DEM map's report (tests/bench/results/dem_map.md) from its CSV.

    dem_map_report.py [CSV]

Prints Markdown: what of the planned map exists, the map's table (v and
the seeds' spread), the convergence checks (stiffness, cell width, the
mirror, the window's halves, the overlap), and the cost. Only reads.
"""
import csv
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dem_map  # noqa: E402  (the plan and the CSV's key)
from dem_points import OVERLAP, chosen, points, rungs  # noqa: E402  (which row is a point's value)
import provenance  # noqa: E402  (the machine, as provenance.sh names it)

TOL = 0.02    # the relative change a check allows


def f(x):
    return float(x)


def rel(a, b):
    """(a - b) / |b|, or None where b is 0."""
    return (a - b) / abs(b) if b else None


def pct(x):
    return "n/a" if x is None else "%+.1f %%" % (100 * x)


def seeds_apart(a, b):
    """|v_a - v_b| in units of the two rows' combined standard error (each
    row's seeds' standard deviation over the root of 3)."""
    se = ((f(a["v_dem_sd"]) ** 2 + f(b["v_dem_sd"]) ** 2) / 3) ** 0.5
    return abs(f(a["v_dem"]) - f(b["v_dem"])) / se if se > 0 else float("inf")


machine = provenance.cores


def peak_of(rows, r, mats):
    """The largest |v| of r's bed (material, depth, drive) over its map
    points so far: the scale a change near v = 0 is judged against, as the
    model's errors are."""
    vs = [abs(f(x["v_dem"])) for x in points(rows, r["material"], int(r["layers"]), r["drive"], mats)]
    return max(vs) if vs else None


def of_peak(a, b, peak):
    """(a - b) in % of the bed's peak, as text."""
    return "n/a" if not peak else "%+.1f %%" % (100 * (a - b) / peak)


def ladder(rows, mats, w):
    """The points whose map rung overlapped more than the bound: every rung
    run there, the one that gives the point its value (dem_points.chosen)
    and its change to the next stiffer rung, the convergence the map asks."""
    e_map = mats["map"]["youngs_map"]
    over = [r for r in rows if r["role"] == "map" and f(r["overlap_max_rel"]) > OVERLAP and
            f(r["cell_width_d"]) == dem_map.WIDTH]
    w("### Stiffer rungs where the map's overlapped")
    w("")
    if not over:
        w("No map point overlapped more than %.0f %% of a diameter." % (100 * OVERLAP))
        w("")
        return
    es = sorted({e_map} | {f(x) for x in dem_map.rungs_above(mats)})
    w("At these points the overlap passed %.0f %% of a diameter at the map's E = %g Pa, so they "
      "run the stiffer rungs %s Pa; the point's value is the softest rung within the bound "
      "(bold), converged where its v is within %.0f %% of the next stiffer rung's (\"seeds\": "
      "the change in units of the two rows' combined standard error; \"of the bed's peak\": the "
      "change in %% of the largest |v| of the bed's map points so far, the scale of the model's "
      "errors, since near v = 0 any relative change is large). LIGGGHTS refuses E above "
      "1e9 Pa without `hard_particles`, so %g Pa has no stiffer rung." %
      (100 * OVERLAP, e_map, " and ".join("%g" % e for e in es[1:]), 100 * TOL, es[-1]))
    w("")
    w("| material | depth | drive | beta | " + " | ".join("v at %g Pa (overlap)" % e for e in es) +
      " | change to the next rung | of the bed's peak | seeds | within %.0f %% |" % (100 * TOL))
    w("|---|---|---|---|" + "---|" * len(es) + "---|---|---|---|")
    n_ok = n = n_close = n_pending = 0
    for m in over:
        point = (m["material"], int(m["layers"]), m["drive"], f(m["beta_deg"]))
        at = {f(r["youngs_pa"]): r for r in rungs(rows, *point)}
        c = chosen(rows, *point, mats=mats)
        cells = []
        for e in es:
            r = at.get(e)
            if not r:
                cells.append("")
                continue
            t = "%+.4f (%.2f %%)" % (f(r["v_dem"]), 100 * f(r["overlap_max_rel"]))
            cells.append("**%s**" % t if r is c else t)
        nxt = [e for e in es if c and e > f(c["youngs_pa"]) and e in at]
        change = z = None
        peak_change = ""
        if c and nxt:
            b = at[nxt[0]]
            change = rel(f(c["v_dem"]), f(b["v_dem"]))
            z = seeds_apart(c, b)
            peak_change = of_peak(f(c["v_dem"]), f(b["v_dem"]), peak_of(rows, m, mats))
        ok = change is not None and abs(change) < TOL
        # a stiffer rung the plan runs here that has no row yet: pending
        pending = any(e not in at for e in es[1:])
        n += 1
        n_ok += ok
        n_close += z is not None and z < 2
        n_pending += change is None and pending
        w("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" %
          (m["material"], m["layers"], m["drive"], m["beta_deg"], " | ".join(cells), pct(change),
           peak_change, "" if z is None else "%.1f" % z,
           "yes" if ok else ("no" if change is not None else
                             "stiffer rungs pending" if pending else "no stiffer rung")))
    w("")
    w("Within %.0f %% of the next rung: %d of these %d points; the two rungs not told apart by "
      "three seeds (within 2 standard errors): %d; stiffer rungs still to run: %d." %
      (100 * TOL, n_ok, n, n_close, n_pending))
    w("")


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else dem_map.CSV
    rows = dem_map.read_rows(path)
    mats = dem_map.materials()
    plan = dem_map.plan()
    by_key = {}
    for r in rows:
        by_key[dem_map.key(r["material"], r["layers"], r["drive"], r["beta_deg"], r["rotation"],
                           r["e_scale"], r["cell_width_d"])] = r
    e_map = mats["map"]["youngs_map"]
    out = []
    w = out.append
    builds = sorted({r["build"] for r in rows})
    dates = sorted(r["date"] for r in rows)
    w("# The DEM reference map")
    w("")
    w("`make bench-dem-map` (tests/bench/dem_map.sh; parts: `DEM_MAP_PARTS=\"...\"`), "
      "report by tests/bench/dem_map_report.py on %s. Build: %s. Rows measured %s to %s, "
      "at nice 19, one LIGGGHTS process at a time (from 2026-12-01, a point's three seeds at "
      "once: `DEM_MAP_JOBS=3`, each seed's CPU its own process's) on this report's machine, %s, "
      "shared with "
      "other work. Data: tests/bench/results/dem_map.csv (one row a point; the command of each "
      "row in its `command` column)." % (time.strftime("%Y-%m-%d", time.gmtime()),
                                         ", ".join("`%s`" % b[:12] for b in builds) or "none yet",
                                         dates[0] if dates else "-", dates[-1] if dates else "-",
                                         machine()))
    w("")
    # what exists
    total = sum(len(p) for _, p in plan)
    done_all = 0
    w("## What exists")
    w("")
    w("| part | rows done | rows planned | CPU h so far |")
    w("|---|---|---|---|")
    map_planned = map_done = 0
    names = []
    for name, _ in plan:
        if name not in names:
            names.append(name)
    for name in names:
        points = [p for n, ps in plan if n == name for p in ps]
        d = [by_key.get(dem_map.point_key(p, mats)) for p in points]
        n = sum(1 for x in d if x)
        done_all += n
        cpu = sum(f(x["cpu_s"]) for x in d if x) / 3600
        w("| %s | %d | %d | %.2f |" % (name, n, len(points), cpu))
        for p, x in zip(points, d):
            if p["role"] == "map":
                map_planned += 1
                map_done += 1 if x else 0
    w("| all | %d | %d | %.2f |" % (done_all, total, sum(f(r["cpu_s"]) for r in rows) / 3600))
    w("")
    w("Map points done: %d of %d (%.0f %%); the checks' rows are the others. Each map point is "
      "beta clockwise; the machine is mirror-symmetric (checked below), so counter-clockwise "
      "at 180 - beta is the same speed the other way." %
      (map_done, map_planned, 100.0 * map_done / map_planned if map_planned else 0))
    w("")
    w("Check rows done: %d of %d; rows at a stiffer rung than the plan's, where 2e+08 Pa "
      "overlapped more than 1 %% of a diameter: %d; last row %s." %
      (done_all - map_done, total - map_planned, len(rows) - done_all,
       max(r["date"] for r in rows)[:10] if rows else "-"))
    w("")
    # the map's tables
    w("## The map: v (m/s), mean of 3 seeds ± their standard deviation")
    w("")
    w("As a plot, every bed with the paper's column model beside it: [dem_map.svg](dem_map.svg) "
      "(tests/bench/dem_map_plot.py).")
    w("")
    maprows = [r for r in rows if r["role"] == "map"]
    for mat in mats["materials"]:
        for drive in dem_map.DRIVES:
            sel = [r for r in maprows if r["material"] == mat and r["drive"] == drive]
            if not sel:
                continue
            depths = sorted({int(r["layers"]) for r in sel})
            w("### %s, drive `%s`" % (mat, drive))
            w("")
            w("| beta cw (deg) | " + " | ".join("%d grains deep" % d for d in depths) + " |")
            w("|---|" + "---|" * len(depths))
            for b in dem_map.BETAS:
                cells = []
                for d in depths:
                    r = chosen(rows, mat, d, drive, b)
                    if not r:
                        cells.append("")
                        continue
                    mark = "" if r["role"] == "map" else " ᵏ"
                    if f(r["overlap_max_rel"]) > OVERLAP:
                        mark += " !"
                    cells.append("%+.4f ± %.4f%s" % (f(r["v_dem"]), f(r["v_dem_sd"]), mark))
                w("| %d | %s |" % (b, " | ".join(cells)))
            w("")
            w("ᵏ: the point's overlap passed 1 %% of a diameter at E = %g Pa, so its value is the "
              "next rung's (%g Pa); !: the overlap passes 1 %% at every rung run." %
              (e_map, mats["map"]["youngs_ladder"][2]))
            w("")
    # checks
    w("## Convergence checks")
    w("")
    w("Each check row is a map point run again with one thing changed, three seeds; the change "
      "is (v_check - v_map) / |v_map|, the bound %.0f %%; \"seeds\" is the change in units of the "
      "two points' combined standard error (each point's seeds' standard deviation over the root of "
      "3): where it is below 2 the two rows are not told apart by three seeds, whatever the "
      "change in %%; \"of the bed's peak\" is the change in %% of the largest |v| of the bed's "
      "map points so far." % (100 * TOL))
    w("")

    def base_of(r):
        m = mats["materials"][r["material"]]
        return by_key.get(dem_map.key(r["material"], r["layers"], r["drive"], r["beta_deg"], "cw",
                                      e_map / m["youngs_real"], dem_map.WIDTH))

    ladder(rows, mats, w)
    for role, title, what in (("stiffness", "Stiffness", "youngs_pa"),
                              ("cell", "Cell width across the deck", "cell_width_d")):
        sel = [r for r in rows if r["role"] == role]
        w("### %s" % title)
        w("")
        if not sel:
            w("No rows yet.")
            w("")
            continue
        w("| material | depth | drive | beta | %s | v_map | v_check | change | of the bed's peak | seeds | overlap map / check (of d) | within %.0f %% | within 2 standard errors |" %
          ("E (Pa) map -> check" if role == "stiffness" else "width (d) map -> check", 100 * TOL))
        w("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in sel:
            b = base_of(r)
            if not b:
                w("| %s | %s | %s | %s | -> %s | (map row not yet) | %+.4f | | | | %s | | |" %
                  (r["material"], r["layers"], r["drive"], r["beta_deg"], r[what], f(r["v_dem"]),
                   r["overlap_max_rel"]))
                continue
            c = rel(f(r["v_dem"]), f(b["v_dem"]))
            z = seeds_apart(r, b)
            w("| %s | %s | %s | %s | %s -> %s | %+.4f | %+.4f | %s | %s | %.1f | %s / %s | %s | %s |" %
              (r["material"], r["layers"], r["drive"], r["beta_deg"], b[what], r[what], f(b["v_dem"]),
               f(r["v_dem"]), pct(c), of_peak(f(r["v_dem"]), f(b["v_dem"]), peak_of(rows, b, mats)), z, b["overlap_max_rel"], r["overlap_max_rel"],
               "yes" if c is not None and abs(c) < TOL else "no", "yes" if z < 2 else "no"))
        w("")
    sel = [r for r in rows if r["role"] == "mirror"]
    w("### Mirror: counter-clockwise at beta against clockwise at 180 - beta")
    w("")
    if sel:
        w("| material | depth | drive | beta ccw | v ccw | v cw at 180 - beta | sum / mean |v| |")
        w("|---|---|---|---|---|---|---|")
        for r in sel:
            m = mats["materials"][r["material"]]
            b = by_key.get(dem_map.key(r["material"], r["layers"], r["drive"], 180 - f(r["beta_deg"]),
                                       "cw", e_map / m["youngs_real"], dem_map.WIDTH))
            if b:
                s = f(r["v_dem"]) + f(b["v_dem"])
                w("| %s | %s | %s | %s | %+.4f | %+.4f | %s |" %
                  (r["material"], r["layers"], r["drive"], r["beta_deg"], f(r["v_dem"]), f(b["v_dem"]),
                   pct(s / (0.5 * (abs(f(r["v_dem"])) + abs(f(b["v_dem"])))))))
        w("")
    else:
        w("No rows yet.")
        w("")
    w("### Steady window and overlap (every row)")
    w("")
    if rows:
        steady = [r for r in rows if abs(f(r["v_second_half"]) - f(r["v_first_half"])) <=
                  max(f(r["v_dem_sd"]), 1e-4)]
        # the paired test: each seed's second half minus its first, their
        # mean against its standard error (the runs file's seeds)
        halves = {}
        for rec in dem_map.finished_seeds(rows[0]["build"]).items():
            k, by_seed = rec
            d = [x["out"]["v_second_half"] - x["out"]["v_first_half"] for x in by_seed.values()]
            if len(d) >= 2:
                halves[k] = (statistics.fmean(d), statistics.stdev(d) / len(d) ** 0.5)

        def paired(r):
            return halves.get(dem_map.key(r["material"], r["layers"], r["drive"], r["beta_deg"],
                                          r["rotation"], r["e_scale"], r["cell_width_d"]))

        drifting = [r for r in rows if paired(r) and abs(paired(r)[0]) > 2 * max(paired(r)[1], 1e-5)]
        big = [r for r in rows if f(r["overlap_max_rel"]) > OVERLAP]
        w("Window %s s after a 1-s transient (50 periods of the 25-Hz drive), split at its middle "
          "period. Rows whose halves differ by no more than the seeds' standard deviation: %d of %d. "
          "Largest overlap (grain on grain or into the deck, sampled 40 times a period over the "
          "whole run after the settling) over all rows: %.2f %% of a mean diameter; rows above "
          "%.0f %%: %d." % (rows[0]["window_s"], len(steady), len(rows),
                            100 * max(f(r["overlap_max_rel"]) for r in rows), 100 * OVERLAP, len(big)))
        w("")
        w("The halves' difference has its own noise, so the rows are also tested in pairs: each "
          "seed's second half minus its first, the mean of the three against twice its standard "
          "error. Rows that drift by that test: %d of %d." % (len(drifting), len(rows)))
        w("")
        drift = [r for r in rows if r not in steady or r in drifting]
        if drift:
            w("| material | depth | drive | beta | rotation | role | E (Pa) | v first half | v second half | seeds' sd | within the seeds' sd | paired drift / its standard error |")
            w("|---|---|---|---|---|---|---|---|---|---|---|---|")
            for r in drift:
                pr = paired(r)
                w("| %s | %s | %s | %s | %s | %s | %s | %+.4f | %+.4f | %.4f | %s | %s |" %
                  (r["material"], r["layers"], r["drive"], r["beta_deg"], r["rotation"], r["role"],
                   r["youngs_pa"], f(r["v_first_half"]), f(r["v_second_half"]), f(r["v_dem_sd"]),
                   "yes" if r in steady else "no",
                   "%+.4f / %.4f" % pr if pr else "n/a"))
            w("")
        if big:
            w("Rows above the overlap bound: " + ", ".join(
                "%s %s grains %s deg %s, drive %s (%s E %s: %.2f %%)" %
                (r["material"], r["layers"], r["beta_deg"], r["rotation"], r["drive"], r["role"],
                 r["youngs_pa"],
                 100 * f(r["overlap_max_rel"])) for r in big) + ".")
            w("")
    # cost
    w("## Cost")
    w("")
    if rows:
        w("CPU seconds a row (three seeds, 3 s simulated each with the machine's run and the "
          "settling), by material, depth and Young's modulus:")
        w("")
        w("| material | depth | grains | E (Pa) | rows | CPU s a row (median) |")
        w("|---|---|---|---|---|---|")
        groups = {}
        for r in rows:
            groups.setdefault((r["material"], int(r["layers"]), r["grains"], f(r["youngs_pa"])), []).append(f(r["cpu_s"]))
        for (m, d, g, e), c in sorted(groups.items()):
            w("| %s | %d | %s | %g | %d | %.0f |" % (m, d, g, e, len(c), statistics.median(c)))
        w("")
        w("Total so far: %.2f CPU hours for %d rows." % (sum(f(r["cpu_s"]) for r in rows) / 3600, len(rows)))
    else:
        w("No rows yet.")
    w("")
    print("\n".join(out))


if __name__ == "__main__":
    main()
