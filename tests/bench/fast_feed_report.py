#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The pages of tests/bench/fast_feed_check.py (`make fast-feed-check`):
tests/bench/results/fast_feed.md and fast_feed.csv from its held-out
predictions."""
import csv
import math
import os
import statistics
import subprocess
import time

import provenance
from fast_feed_check import FAMILIES, GRAINS_N, LAYERED_P, ROOT, TOL, COST_REPEATS, \
    COST_DURATION, LONG_DURATION, err_of

def pct(x):
    return "%+.1f %%" % (100 * x)


def summary(recs, key):
    e = [err_of(r[key]) for r in recs]
    return (sum(x <= TOL for x in e), len(e), max(e), statistics.median(e))


def pct_of(x):
    """An error for a table: its value, or that a run failed."""
    return "%.1f %%" % (100 * x) if math.isfinite(x) else "a run failed"


def build_name():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short=12", "HEAD"], check=True,
                              capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def write_csv(recs, path):
    cols = ["material", "drive", "depth", "beta", "v_dem", "sd", "peak", "v_paper", "err_paper",
            "cpu_paper"]
    for f in FAMILIES:
        cols += [f + "_fit", f + "_v", f + "_err", f + "_err_long", f + "_cpu", f + "_own",
                 f + "_err_own", f + "_all", f + "_err_all"]
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(cols)
        for r in recs:
            w.writerow([("%.6g" % r[c]) if isinstance(r[c], float) else r[c] for c in cols])


def summary_table(recs, w):
    w("| model | points within 5 % | worst | median | CPU / column's (all points, median point) |")
    w("|---|---|---|---|---|")
    rows = [("the paper's column model as it is (R 0.05, mu 0.4, k_c 1e6, layers = depth)",
             "err_paper", None)]
    for f in FAMILIES:
        rows.append(("%s, leave one bed out" % f, f + "_err", f + "_cpu"))
        rows.append(("%s, the same with v over 5 s instead of 2 (window check)" % f,
                     f + "_err_long", None))
        rows.append(("%s fitted on the bed itself (upper bound)" % f, f + "_err_own", None))
        rows.append(("%s, one closure fitted on every bed at once (its ceiling on the map)" % f,
                     f + "_err_all", None))
    for label, key, cpu in rows:
        n, tot, worst, med = summary(recs, key)
        cost = "1" if key == "err_paper" else "-"
        if cpu:
            ran = [r for r in recs if r["cpu_paper"] > 0 and math.isfinite(r[cpu])]
            ratios = [r[cpu] / r["cpu_paper"] for r in ran]
            cost = "%.2f, %.2f" % (sum(r[cpu] for r in ran) / sum(r["cpu_paper"] for r in ran),
                                   statistics.median(ratios))
            if len(ran) < len(recs):
                cost += " (%d failed runs left out)" % (len(recs) - len(ran))
        w("| %s | %d of %d (%.0f %%) | %s | %s | %s |" %
          (label, n, tot, 100.0 * n / tot, pct_of(worst), pct_of(med), cost))


def depth_table(sel, w):
    w("| beta cw | v_DEM ± sd | paper's v | error | " +
      " | ".join("%s v | error" % f for f in FAMILIES) + " |")
    w("|---|---|---|---|" + "---|---|" * len(FAMILIES))
    for r in sel:
        cells = []
        for f in FAMILIES:
            e = r[f + "_err"]
            if not math.isfinite(e):
                cells.append("failed | ✗")
                continue
            cells.append("%.4f | %s%s" % (r[f + "_v"], pct(e), "" if abs(e) <= TOL else " ✗"))
        w("| %g | %.4f ± %.4f | %.4f | %s | %s |" % (r["beta"], r["v_dem"], r["sd"], r["v_paper"],
                                                   pct(r["err_paper"]), " | ".join(cells)))


def material_table(recs, w):
    """Points within TOL, leave one bed out, by material."""
    mats = sorted({r["material"] for r in recs})
    w("| model | " + " | ".join(mats) + " |")
    w("|---|" + "---|" * len(mats))
    for label, key in [("the paper's column model as it is", "err_paper")] + \
            [("%s, leave one bed out" % f, f + "_err") for f in FAMILIES]:
        cells = []
        for m in mats:
            n, tot, _, _ = summary([r for r in recs if r["material"] == m], key)
            cells.append("%d of %d" % (n, tot))
        w("| %s | %s |" % (label, " | ".join(cells)))


machine = provenance.machine


def beds_named(recs):
    """"glass 1, 2, 4 grains deep; wheat 1 ...": the map's beds."""
    mats = sorted({r["material"] for r in recs})
    return "; ".join("%s %s grains deep" % (m, ", ".join(str(d) for d in sorted(
        {r["depth"] for r in recs if r["material"] == m}))) for m in mats)


def write_md(recs, runner, path, unpredicted=()):
    out = []
    w = out.append
    w("# A fast feed model against the DEM map (leave one bed out)")
    w("")
    w("`make fast-feed-check` (tests/bench/fast_feed_check.py) on %s, build `%s`, %s; data "
      "tests/bench/results/fast_feed.csv; %d runs of convsim and fast_feed_bed, %d of them this time (the others from "
      "build/fast_feed_cache.json, same sources). Candidates "
      "(docs/feed-models.md): `closure`, the column model with R, mu, k_c and its layers from a "
      "closure in the depth; `ensemble`, the mean of two such columns with different R; "
      "`grains`, %d point-mass grains whose impacts keep a random share of their rebound "
      "(tests/bench/fast_feed_bed.c); `layered`, the ensemble whose restitutions are the bed's: "
      "R_bed = R^(d^P) for a bed d grains deep, P in %s fitted with the rest; `collapse`, two "
      "regimes split at D_c by the bed's dissipation D = (1 - e_pw^2) + (d - 1)(1 - e_pp^2) from "
      "the material's restitutions (dem/materials.json), each an ensemble whose mu is C times "
      "the material's mu_pw. A bed is a material at a depth: each is predicted by a closure "
      "fitted on all the map's other beds, both materials and both drives (leave one bed out: "
      "never on the same material and depth at either drive); no closure has "
      "a constant of its own per material or drive. Map: %d points of its complete beds (%s) from %s. "
      "Error = (v - v_DEM) / the "
      "bed's DEM peak |v|; the target is |error| <= 5 %% at >= 90 %% of the points at <= 3x "
      "the column model's CPU." % (time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                                   build_name(), machine(), runner.total, runner.runs, GRAINS_N,
                                   "/".join("%g" % x for x in LAYERED_P), len(recs),
                                   beds_named(recs),
                                   os.environ.get("DEM_MAP_CSV") or
                                   "tests/bench/results/dem_map.csv"))
    w("")
    if unpredicted:
        w("Not predicted, the only bed in the map so far (no other bed to fit a closure on; its "
          "points are not counted): %s." % ", ".join(
              "%s %d grains deep, drive `%s` (%d points)" % (m, d, dr, n)
              for m, dr, d, n in unpredicted))
        w("")
    w("## Summary")
    w("")
    summary_table(recs, w)
    w("")
    w("The one closure of each family fitted on every bed at once (the ceiling rows: the most "
      "points within 5 %% a single closure of the family gets on the whole map; the fit sees "
      "the points it is counted on, so it is not a prediction): %s." % "; ".join(
          "`%s` %s" % (f, recs[0][f + "_all"]) for f in FAMILIES))
    w("")
    w("Leave one bed out, points within 5 % by material:")
    w("")
    material_table(recs, w)
    w("")
    w("CPU: the candidate's convsim runs (both columns for `ensemble`, `layered` and `collapse`) over the paper's column "
      "model's run at the same point, one-way, each the least of %d runs of %g simulated seconds; "
      "all points: the sums' ratio. For `grains`: the machine alone (convsim, feed=false) plus "
      "fast_feed_bed's integration (timed on the %g-s orbit, scaled to %g s). Single points' "
      "ratios vary by up to about 1.5x between two runs of this tool on a shared machine." %
      (COST_REPEATS, COST_DURATION, LONG_DURATION, COST_DURATION))
    w("")
    for depth in sorted({(r["material"], r["drive"], r["depth"]) for r in recs}):
        sel = [r for r in recs if (r["material"], r["drive"], r["depth"]) == depth]
        w("## %s, drive `%s`, %d grains deep (DEM peak %.4f m/s)" % (depth + (sel[0]["peak"],)))
        w("")
        for f in FAMILIES:
            n, tot, worst, med = summary(sel, f + "_err")
            w("- %s fitted on the other beds: %s; %d of %d within 5 %%, worst %s; fitted "
              "on this bed: %s." % (f, sel[0][f + "_fit"], n, tot, pct_of(worst), sel[0][f + "_own"]))
        w("")
        depth_table(sel, w)
        w("")
    with open(path, "w") as fh:
        fh.write("\n".join(out))
