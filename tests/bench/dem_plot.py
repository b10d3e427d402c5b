#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The plot of `make bench-dem`: v from LIGGGHTS against v from the column
model, one mark per scene of tests/bench/results/dem.jsonl (seeds pooled,
bars: their standard deviation; the ladder's rungs in one colour), the
diagonal and the 10 % and 30 % bands.
Writes SVG to stdout. Usage: dem_plot.py FILE.jsonl COMMAND DATE."""
import json
import statistics
import sys

W, H, M = 560, 560, 60
LO, HI = -0.2, 0.2
COLOURS = {"curve": "#1f77b4", "ladder": "#17becf", "depth": "#d62728", "stiffness": "#2ca02c",
           "rolling": "#9467bd", "restitution": "#8c564b", "tangential": "#ff7f0e"}


def sx(v):
    return M + (v - LO) / (HI - LO) * (W - 2 * M)


def sy(v):
    return H - M - (v - LO) / (HI - LO) * (H - 2 * M)


def main():
    path, command, date = sys.argv[1:4]
    scenes = {}
    for line in open(path):
        if line.strip():
            r = json.loads(line)
            if r["group"] == "one-grain":  # the drive's check, not a scene of the plot
                continue
            key = (r["group"], r["beta"], r["rotation"], r["layers"], r["k_over_m"], r["mu_roll"],
                   r["restitution_floor"], r.get("tangential", "spring"))
            scenes.setdefault(key, []).append(r)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H + 40}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H + 40}" fill="white"/>',
           f'<clipPath id="frame"><rect x="{M}" y="{M}" width="{W - 2 * M}" height="{H - 2 * M}"/></clipPath>']
    for f in (1.0, 1.1, 1 / 1.1, 1.3, 1 / 1.3):
        dash = "" if f == 1.0 else ' stroke-dasharray="4 3"'
        out.append(f'<line x1="{sx(LO)}" y1="{sy(LO * f)}" x2="{sx(HI)}" y2="{sy(HI * f)}" stroke="#999"{dash} clip-path="url(#frame)"/>')
    out.append(f'<line x1="{sx(LO)}" y1="{sy(0)}" x2="{sx(HI)}" y2="{sy(0)}" stroke="#ccc"/>')
    out.append(f'<line x1="{sx(0)}" y1="{sy(LO)}" x2="{sx(0)}" y2="{sy(HI)}" stroke="#ccc"/>')
    out.append(f'<rect x="{M}" y="{M}" width="{W - 2 * M}" height="{H - 2 * M}" fill="none" stroke="black"/>')
    for t in (-0.2, -0.1, 0.0, 0.1, 0.2):
        out.append(f'<text x="{sx(t)}" y="{H - M + 16}" text-anchor="middle">{t:+.1f}</text>')
        out.append(f'<text x="{M - 6}" y="{sy(t) + 4}" text-anchor="end">{t:+.1f}</text>')
    out.append(f'<text x="{W / 2}" y="{H - M + 34}" text-anchor="middle">v, column model (m/s)</text>')
    out.append(f'<text x="16" y="{H / 2}" text-anchor="middle" transform="rotate(-90 16 {H / 2})">v, LIGGGHTS (m/s)</text>')
    for key, rs in scenes.items():
        v = [r["v_dem"] for r in rs]
        mean = statistics.fmean(v)
        sd = statistics.stdev(v) if len(v) > 1 else 0.0
        col = rs[0]["v_column"]
        c = COLOURS.get(key[0], "black")
        if sd > 0:
            out.append(f'<line x1="{sx(col)}" y1="{sy(mean - sd)}" x2="{sx(col)}" y2="{sy(mean + sd)}" stroke="{c}"/>')
        out.append(f'<circle cx="{sx(col)}" cy="{sy(mean)}" r="4" fill="{c}"><title>{key[0]} beta {key[1]:.0f} {key[2]} '
                   f'{key[3]} d k/m {key[4]:.0e}: DEM {mean:+.4f}, column {col:+.4f}</title></circle>')
    y = M + 14
    for g, c in COLOURS.items():
        out.append(f'<circle cx="{M + 12}" cy="{y - 4}" r="4" fill="{c}"/><text x="{M + 22}" y="{y}">{g}</text>')
        y += 16
    out.append(f'<text x="{M + 12}" y="{y + 4}">dashed: column model 10 % and 30 % off</text>')
    out.append(f'<text x="{M}" y="{M - 20}">`{command}`, {date}: the DEM bed against the column model</text>')
    out.append('</svg>')
    print("\n".join(out))


if __name__ == "__main__":
    main()
