#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The table of `make bench-dem` (tests/bench/dem.sh) from its JSON lines:
one row per scene (seeds pooled: mean and sample standard deviation), the
column model's relative error against the DEM, and the rows where it is
within 5, 10 and 30 %. Usage: dem_report.py FILE.jsonl COMMAND DATE SECONDS [NOTE]."""
import json
import math
import statistics
import sys


def scene_key(r):
    return (r["group"], r["beta"], r["rotation"], r["layers"], r["k_over_m"], r["mu_roll"],
            r["restitution_floor"])


def main():
    path, command, date, seconds = sys.argv[1:5]
    note = sys.argv[5] if len(sys.argv) > 5 else ""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    scenes = {}
    for r in rows:
        scenes.setdefault(scene_key(r), []).append(r)
    out = []
    out.append(f"`{command}`, {date}, {seconds} s wall on one core (nice 15){note}, "
               f"{sum(r['dem_cpu_seconds'] for r in rows):.0f} s of DEM CPU in all the rows.")
    out.append("")
    out.append("| group | β (°) | sense | depth (d) | grains | k/m (1/s²) | μ_roll | e | seeds | "
               "v DEM (m/s) | v column (m/s) | column − DEM | DEM CPU s per s |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    classes = {5: [], 10: [], 30: [], "more": []}
    for key, rs in scenes.items():
        group, beta, rot, layers, kom, mu_roll, e = key
        v = [r["v_dem"] for r in rs]
        mean = statistics.fmean(v)
        sd = statistics.stdev(v) if len(v) > 1 else float("nan")
        col = rs[0]["v_column"]
        rel = (col - mean) / abs(mean) if mean else float("inf")
        cost = statistics.fmean(r["dem_cpu_seconds"] / (r["periods"] * 2 * math.pi / r["deck_omega"])
                                for r in rs)
        vdem = f"{mean:+.4f}" + (f" ± {sd:.4f}" if len(v) > 1 else "")
        out.append(f"| {group} | {beta:.0f} | {rot} | {layers} | {rs[0]['grains']} | {kom:.3g} | "
                   f"{mu_roll:g} | {e:g} | {len(v)} | {vdem} | {col:+.4f} | {100 * rel:+.1f} % | "
                   f"{cost:.1f} |")
        tag = f"{group} β {beta:.0f}° {rot}, {layers} d, k/m {kom:.3g}, μ_roll {mu_roll:g}, e {e:g}"
        a = abs(rel)
        classes[5 if a <= 0.05 else 10 if a <= 0.10 else 30 if a <= 0.30 else "more"].append(tag)
    out.append("")
    out.append("Depth (d) is the bed's depth in mean grain diameters at packing 0.6, and the column "
               "model's layers; ± is the standard deviation over packing seeds.")
    out.append("")
    for c, label in ((5, "within 5 %"), (10, "within 10 % (not 5 %)"), (30, "within 30 % (not 10 %)"),
                     ("more", "off by more than 30 %")):
        out.append(f"- {label}: " + ("; ".join(classes[c]) if classes[c] else "none"))
    print("\n".join(out))


if __name__ == "__main__":
    main()
