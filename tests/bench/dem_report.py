#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The tables of `make bench-dem` (tests/bench/dem.sh) from its JSON lines.

Table 1: the preset's curve on the 4-diameter bed and its stiffness ladder,
one row per angle and sense: the DEM's v at each rung (seeds pooled: mean
and sample standard deviation), the change between the last two rungs on
seed 1, and the column model's relative error at the first and the last
rung. Table 2: every other scene (depth, rolling friction, ...), one row
each, seeds pooled. Then the scenes where the column model is within 5, 10
and 30 %. Usage: dem_report.py FILE.jsonl COMMAND DATE SECONDS [NOTE]."""
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


def main():
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
        head = [f"v DEM {kom0:.0e}"] + [f"v DEM {x:.0e}" for x in rungs]
        tail = []
        if len(rungs) >= 2:
            tail = [f"{rungs[-2]:.0e} → {rungs[-1]:.0e} (seed 1)"]
        out.append("| β (°) | sense | " + " | ".join(head + tail) +
                   f" | v column {kom0:.0e} | column − DEM {kom0:.0e}" +
                   (f" | v column {rungs[-1]:.0e} | column − DEM {rungs[-1]:.0e}" if rungs else "") +
                   " |")
        out.append("|" + "---|" * (2 + len(head) + len(tail) + 2 + (2 if rungs else 0)))
        for (beta, rot) in sorted(curve, key=lambda br: (br[1] != "cw", br[0])):
            rs0 = curve[(beta, rot)]
            m0 = pooled(rs0)
            cells = [fmt(*m0)]
            lad = ladder.get((beta, rot), {})
            for x in rungs:
                cells.append(fmt(*pooled(lad[x])) if x in lad else "")
            if tail:
                s1 = [next((r["v_dem"] for r in lad.get(x, []) if r["seed"] == 1), float("nan"))
                      for x in rungs[-2:]]
                cells.append(f"{100 * (s1[1] - s1[0]) / abs(s1[0]):+.1f} %")
            col0 = rs0[0]["v_column"]
            r0 = rel(col0, m0[0])
            cells += [f"{col0:+.4f}", f"{100 * r0:+.1f} %"]
            classify(f"β {beta:.0f}° {rot}, 4 d, k/m {kom0:.3g}", r0)
            if rungs:
                for x in rungs:
                    if x in lad:
                        rx = rel(lad[x][0]["v_column"], pooled(lad[x])[0])
                        classify(f"β {beta:.0f}° {rot}, 4 d, k/m {x:.3g}", rx)
                if rungs[-1] in lad:
                    last = lad[rungs[-1]]
                    cells += [f"{last[0]['v_column']:+.4f}",
                              f"{100 * rel(last[0]['v_column'], pooled(last)[0]):+.1f} %"]
                else:
                    cells += ["", ""]
            out.append(f"| {beta:.0f} | {rot} | " + " | ".join(cells) + " |")
        n = {k: len(rs) for k, rs in scenes.items()}
        out.append("")
        out.append(f"The 4-diameter bed ({next(rs[0]['grains'] for k, rs in scenes.items() if k[0] == 'curve')} "
                   f"grains); v in m/s; ± is the standard deviation over packing seeds "
                   f"({max(n[k] for k in n if k[0] == 'curve')} at {kom0:.0e}"
                   + (f", {max(n[k] for k in n if k[0] == 'ladder' and k[4] == rungs[-1])} at {rungs[-1]:.0e}"
                      if rungs else "") + "); k/m in 1/s².")
        out.append("")
    # table 2: every other scene
    out.append("| group | β (°) | sense | depth (d) | grains | k/m (1/s²) | μ_roll | e | tangential | seeds | "
               "v DEM (m/s) | v column (m/s) | column − DEM | DEM CPU s per s |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for key, rs in scenes.items():
        group, beta, rot, layers, kom, mu_roll, e, tang = key
        if group in ("curve", "ladder"):
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
    for c, label in ((5, "within 5 %"), (10, "within 10 % (not 5 %)"), (30, "within 30 % (not 10 %)"),
                     ("more", "off by more than 30 %")):
        out.append(f"- {label} ({len(classes[c])}): " + ("; ".join(classes[c]) if classes[c] else "none"))
    print("\n".join(out))


if __name__ == "__main__":
    main()
