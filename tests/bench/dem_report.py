#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The tables of `make bench-dem` (tests/bench/dem.sh) from its JSON lines.

Table 1: the preset's curve on the 4-diameter bed and its stiffness ladder,
one row per angle and sense: the DEM's v at each rung (seeds pooled: mean
and sample standard deviation), the change between each two neighbouring
rungs of the ladder on seed 1, the column model's v at the curve's rung and
at every ladder rung but the first, and its relative error at every rung; a
rung absent from the rows (the ladder-top part not run) drops its columns. Table 2: every other scene (depth, rolling friction, ...), one row
each, seeds pooled. Then the scenes where the column model is within 5, 10
and 30 %. Usage: dem_report.py FILE.jsonl COMMAND DATE SECONDS [NOTE];
dem_report.py --bed4-csv FILE.jsonl writes the curve's points for the fit."""
import json
import math
import statistics
import sys


def scene_key(r):
    return (r["group"], r["beta"], r["rotation"], r["layers"], r["k_over_m"], r["mu_roll"],
            r["restitution_floor"], r.get("tangential", "spring"))


def pooled(rs):
    """Mean and sample standard deviation (NaN for one run) of v_dem."""
    v = [r["v_dem"] for r in rs]
    return statistics.fmean(v), (statistics.stdev(v) if len(v) > 1 else float("nan")), len(v)


def fmt(mean, sd, n):
    return f"{mean:+.4f}" + (f" ± {sd:.4f}" if n > 1 else "")


def rel(col, dem):
    return (col - dem) / abs(dem) if dem else float("inf")


def cost(rs):
    return statistics.fmean(r["dem_cpu_seconds"] / (r["periods"] * 2 * math.pi / r["deck_omega"])
                            for r in rs)


def bed4_csv(path):
    """The curve's points for `convsim fit --data` (docs/dem.md "Calibrated
    to a bed"): the seeds' mean v at each angle and sense, and one sigma for
    all, the root mean square of the seeds' standard deviations."""
    curve = {}
    for line in open(path):
        if line.strip():
            r = json.loads(line)
            if r["group"] == "curve":
                curve.setdefault((round(r["beta"]), r["rotation"]), []).append(r["v_dem"])
    sds = [statistics.stdev(v) for v in curve.values() if len(v) > 1]
    sigma = math.sqrt(statistics.fmean([s * s for s in sds])) if sds else 0.0013
    print("beta,rotation,v,sigma")
    for beta, rot in sorted(curve, key=lambda br: (br[1] != "cw", br[0])):
        print(f"{beta},{rot},{statistics.fmean(curve[(beta, rot)]):.6f},{sigma:.4f}")


def main():
    if sys.argv[1] == "--bed4-csv":
        bed4_csv(sys.argv[2])
        return
    path, command, date, seconds = sys.argv[1:5]
    note = sys.argv[5] if len(sys.argv) > 5 else ""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    scenes = {}
    for r in rows:
        scenes.setdefault(scene_key(r), []).append(r)
    out = [f"`{command}`, {date}, {seconds} s wall on one core (nice 15){note}, "
           f"{sum(r['dem_cpu_seconds'] for r in rows):.0f} s of DEM CPU in all the rows.", ""]
    classes = {5: [], 10: [], 30: [], "more": []}

    def classify(tag, r):
        a = abs(r)
        classes[5 if a <= 0.05 else 10 if a <= 0.10 else 30 if a <= 0.30 else "more"].append(tag)

    # table 1: the curve and its ladder, by angle and sense
    curve = {(k[1], k[2]): rs for k, rs in scenes.items() if k[0] == "curve"}
    ladder = {}
    for k, rs in scenes.items():
        if k[0] == "ladder":
            ladder.setdefault((k[1], k[2]), {})[k[4]] = rs
    rungs = sorted({k[4] for k in scenes if k[0] == "ladder"})
    if curve:
        kom0 = next(k[4] for k in scenes if k[0] == "curve")
        allr = [kom0] + rungs
        head = [f"v DEM {x:.0e}" for x in allr]
        steps = list(zip(rungs, rungs[1:]))
        tail = [f"{a:.0e} → {b:.0e} (seed 1)" for a, b in steps]
        at = [kom0] + (rungs[1:] if len(rungs) >= 2 else rungs)
        cols = [f"v column {x:.0e}" for x in at]
        diffs = [f"column − DEM {x:.0e}" for x in allr]
        out.append("| β (°) | sense | " + " | ".join(head + tail + cols + diffs) + " |")
        out.append("|" + "---|" * (2 + len(head) + len(tail) + len(cols) + len(diffs)))
        seeds_at = {x: 0 for x in allr}
        for (beta, rot) in sorted(curve, key=lambda br: (br[1] != "cw", br[0])):
            by = {kom0: curve[(beta, rot)], **ladder.get((beta, rot), {})}
            cells = [fmt(*pooled(by[x])) if x in by else "" for x in allr]
            for x in allr:
                seeds_at[x] = max(seeds_at[x], len(by.get(x, [])))
            for a, b in steps:
                s1 = [next((r["v_dem"] for r in by.get(x, []) if r["seed"] == 1), None) for x in (a, b)]
                cells.append(f"{100 * (s1[1] - s1[0]) / abs(s1[0]):+.1f} %" if None not in s1 else "")
            cells += [f"{by[x][0]['v_column']:+.4f}" if x in by else "" for x in at]
            for x in allr:
                if x not in by:
                    cells.append("")
                    continue
                rx = rel(by[x][0]["v_column"], pooled(by[x])[0])
                cells.append(f"{100 * rx:+.1f} %")
                classify(f"β {beta:.0f}° {rot}, 4 d, k/m {x:.3g}", rx)
            out.append(f"| {beta:.0f} | {rot} | " + " | ".join(cells) + " |")
        out.append("")
        out.append(f"The 4-diameter bed ({curve[next(iter(curve))][0]['grains']} grains); v in m/s; "
                   "± is the standard deviation over packing seeds ("
                   + ", ".join(f"{seeds_at[x]} at {x:.0e}" for x in allr) + "); k/m in 1/s².")
        out.append("")
    # table 2: every other scene
    out.append("| group | β (°) | sense | depth (d) | grains | k/m (1/s²) | μ_roll | e | tangential | seeds | "
               "v DEM (m/s) | v column (m/s) | column − DEM | DEM CPU s per s |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for key, rs in scenes.items():
        group, beta, rot, layers, kom, mu_roll, e, tang = key
        if group in ("curve", "ladder", "one-grain"):
            continue
        mean, sd, nn = pooled(rs)
        col = rs[0]["v_column"]
        r = rel(col, mean)
        out.append(f"| {group} | {beta:.0f} | {rot} | {layers} | {rs[0]['grains']} | {kom:.3g} | "
                   f"{mu_roll:g} | {e:g} | {tang} | {nn} | {fmt(mean, sd, nn)} | {col:+.4f} | "
                   f"{100 * r:+.1f} % | {cost(rs):.1f} |")
        classify(f"{group} β {beta:.0f}° {rot}, {layers} d, k/m {kom:.3g}, μ_roll {mu_roll:g}, e {e:g}, "
                 f"{tang}", r)
    out.append("")
    out.append("Depth (d) is the bed's depth in mean grain diameters at packing 0.6, and the column "
               "model's layers; ± is the standard deviation over packing seeds.")
    out.append("")
    # table 3: one grain under the formula drive and held accelerations
    one = [r for r in rows if r["group"] == "one-grain"]
    if one:
        form = next((r["v_dem"] for r in one if not r["intervals"]), None)
        out.append("| drive | intervals a period | DEM steps a LIGGGHTS run | v DEM (m/s) | against the formula |")
        out.append("|---|---|---|---|---|")
        for r in sorted(one, key=lambda r: r["intervals"]):
            n = r["intervals"]
            period = 2 * math.pi / r["deck_omega"]
            steps = period / (n if n else 1) / r["dem_dt"]
            against = "" if not n or form is None else f"{100 * (r['v_dem'] - form) / form:+.2f} %"
            out.append(f"| {'held' if n else 'formula'} | {n if n else '-'} | {steps:.0f} | "
                       f"{r['v_dem']:.5f} | {against} |")
        out.append("")
        out.append("One grain of 4 mm, rotation frozen, the preset's contacts (k/m 2e+06), 30° clockwise.")
        out.append("")
    for c, label in ((5, "within 5 %"), (10, "within 10 % (not 5 %)"), (30, "within 30 % (not 10 %)"),
                     ("more", "off by more than 30 %")):
        out.append(f"- {label} ({len(classes[c])}): " + ("; ".join(classes[c]) if classes[c] else "none"))
    print("\n".join(out))


if __name__ == "__main__":
    main()
