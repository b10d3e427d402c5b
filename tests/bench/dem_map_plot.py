#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The DEM map's plot (tests/bench/results/dem_map.svg): v against beta,
clockwise, one panel per material and drive, one colour per depth.

    dem_map_plot.py [CSV [MODEL_CHECK_CSV]] > dem_map.svg
    dem_map_plot.py --check     the committed SVG is what the committed CSVs
                                give, and each mark is its point's value

Marks joined by solid lines: the DEM bed, each point its chosen row
(dem_points.chosen: the softest stiffness whose overlap stays within 1 % of
a diameter), the mean of its seeds with a bar of their standard deviation.
Dashed: the paper's column model at the same depth and drive, as the model
check computed it (tests/bench/results/model_check.csv, rows `czubak2016`).
The SVG carries no date of its own: the same data give the same bytes.
"""
import csv
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dem_map  # noqa: E402
from dem_points import chosen  # noqa: E402

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
SVG = os.path.join(RESULTS, "dem_map.svg")
MODEL_CHECK = os.path.join(RESULTS, "model_check.csv")
PW, PH, ML, MT, MB, MR = 420, 260, 56, 30, 40, 14  # a panel and its margins
COLOURS = {1: "#1f77b4", 2: "#ff7f0e", 4: "#2ca02c", 8: "#d62728", 16: "#9467bd"}


def panels(rows, mats):
    """[(material, drive, {depth: [(beta, row)]})] of every material and
    drive with map points, in the materials' and drives' order."""
    out = []
    for mat in mats["materials"]:
        for drive in dem_map.DRIVES:
            depths = sorted({int(r["layers"]) for r in rows if r["material"] == mat and
                             r["drive"] == drive and r["role"] == "map"})
            beds = {}
            for d in depths:
                pts = [(b, chosen(rows, mat, d, drive, b, "cw", mats)) for b in dem_map.BETAS]
                beds[d] = [(b, r) for b, r in pts if r]
            if any(beds.values()):
                out.append((mat, drive, beds))
    return out


def column_model(path):
    """{(material, drive, depth, beta): v_column} of the model check's
    clockwise rows of the paper's preset."""
    out = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            if r["preset"] == "czubak2016" and r["rotation"] == "cw":
                out[(r["material"], r["drive"], int(r["layers"]), float(r["beta_deg"]))] = \
                    float(r["v_column"])
    return out


def panel(x0, y0, mat, drive, beds, col, vlim):
    """One panel's SVG elements, its frame's corner at (x0, y0), v from
    -vlim to vlim."""
    w, h = PW - ML - MR, PH - MT - MB
    sx = lambda b: x0 + ML + b / 180 * w  # noqa: E731
    sy = lambda v: y0 + MT + (vlim - v) / (2 * vlim) * h  # noqa: E731
    out = [f'<rect x="{x0 + ML}" y="{y0 + MT}" width="{w}" height="{h}" fill="none" stroke="black"/>',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(180)}" y2="{sy(0)}" stroke="#ccc"/>',
           f'<text x="{x0 + ML}" y="{y0 + MT - 8}" font-weight="bold">{mat}, drive {drive}</text>']
    for b in range(0, 181, 30):
        out.append(f'<text x="{sx(b)}" y="{y0 + MT + h + 15}" text-anchor="middle">{b}</text>')
    for v in [k / 10 for k in range(-int(vlim * 10), int(vlim * 10) + 1)]:
        out.append(f'<text x="{x0 + ML - 5}" y="{sy(v) + 4:.1f}" text-anchor="end">{v:+.1f}</text>')
    out.append(f'<text x="{x0 + ML + w / 2}" y="{y0 + MT + h + 32}" text-anchor="middle">'
               'beta, clockwise (deg)</text>')
    out.append(f'<text x="{x0 + 14}" y="{y0 + MT + h / 2}" text-anchor="middle" '
               f'transform="rotate(-90 {x0 + 14} {y0 + MT + h / 2})">v (m/s)</text>')
    for d, pts in beds.items():
        c = COLOURS.get(d, "black")
        model = [(b, col[(mat, drive, d, float(b))]) for b, _ in pts if (mat, drive, d, float(b)) in col]
        if len(model) > 1:
            out.append(f'<polyline fill="none" stroke="{c}" stroke-dasharray="5 4" points="' +
                       " ".join(f"{sx(b):.1f},{sy(v):.1f}" for b, v in model) + '"/>')
        if len(pts) > 1:
            out.append(f'<polyline fill="none" stroke="{c}" points="' +
                       " ".join(f"{sx(b):.1f},{sy(float(r['v_dem'])):.1f}" for b, r in pts) + '"/>')
        for b, r in pts:
            v, sd = float(r["v_dem"]), float(r["v_dem_sd"])
            out.append(f'<line x1="{sx(b):.1f}" y1="{sy(v - sd):.1f}" x2="{sx(b):.1f}" '
                       f'y2="{sy(v + sd):.1f}" stroke="{c}"/>')
            out.append(f'<circle cx="{sx(b):.1f}" cy="{sy(v):.1f}" r="3" fill="{c}" '
                       f'data-bed="{mat} {drive} {d}" data-beta="{b}" data-v="{v:.6g}">'
                       f'<title>{mat}, drive {drive}, {d} grains deep, beta {b} cw: '
                       f'DEM {v:+.4f} ± {sd:.4f} m/s, E {float(r["youngs_pa"]):g} Pa</title></circle>')
    return out


def svg(rows, mats, col):
    ps = panels(rows, mats)
    ncol = 2
    nrow = (len(ps) + ncol - 1) // ncol
    top, legend = 40, 26
    W, H = ncol * PW, top + nrow * PH + legend
    builds = sorted({r["build"][:12] for r in rows})
    last = max((r["date"] for r in rows), default="-")[:10]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
           'font-family="sans-serif" font-size="11">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="10" y="18" font-size="13">The DEM map, v against beta (clockwise): '
           f'`make bench-dem-map`, build {", ".join(builds)}, rows to {last}</text>',
           '<text x="10" y="33">marks and solid lines: the DEM bed (3 seeds, bar ± their standard '
           'deviation); dashed: the paper\'s column model at the same depth</text>']
    # one scale for every panel: the largest |v| drawn, up to the next 0.05 m/s
    vs = [abs(float(r["v_dem"])) + float(r["v_dem_sd"]) for _, _, beds in ps
          for pts in beds.values() for _, r in pts] + [abs(v) for v in col.values()]
    vlim = math.ceil(max(vs + [0.1]) / 0.05 - 1e-9) * 0.05
    for i, (mat, drive, beds) in enumerate(ps):
        out += panel((i % ncol) * PW, top + (i // ncol) * PH, mat, drive, beds, col, vlim)
    x = 10
    for d, c in COLOURS.items():
        out.append(f'<line x1="{x}" y1="{H - 12}" x2="{x + 18}" y2="{H - 12}" stroke="{c}" stroke-width="2"/>'
                   f'<text x="{x + 22}" y="{H - 8}">{d} grain{"s" if d > 1 else ""} deep</text>')
        x += 110
    out.append('</svg>')
    return "\n".join(out) + "\n"


def check():
    """The committed SVG against what the committed CSVs give, and each
    mark against its point's chosen row; prints node:test's summary."""
    rows, mats = dem_map.read_rows(), dem_map.materials()
    want = svg(rows, mats, column_model(MODEL_CHECK))
    have = open(SVG).read() if os.path.exists(SVG) else ""
    fails = []
    if have != want:
        fails.append("%s is not what the CSVs give: run tests/bench/dem_map_plot.py > %s" % (SVG, SVG))
    marks = re.findall(r'data-bed="(\w+) (\w+) (\d+)" data-beta="(\d+)" data-v="([^"]+)"', have)
    npts = 0
    for mat, drive, d, b, v in marks:
        r = chosen(rows, mat, int(d), drive, float(b), "cw", mats)
        if not r or abs(float(r["v_dem"]) - float(v)) > 1e-6 * max(1, abs(float(v))):
            fails.append("mark %s %s %s beta %s: %s, the map says %s" %
                         (mat, drive, d, b, v, r and r["v_dem"]))
    for _, _, beds in panels(rows, mats):
        npts += sum(len(p) for p in beds.values())
    if len(marks) != npts:
        fails.append("%d marks for %d map points" % (len(marks), npts))
    for m in fails:
        print("not ok:", m)
    print("# pass %d" % (0 if fails else 1))
    print("# fail %d" % len(fails))
    return 1 if fails else 0


def main():
    if sys.argv[1:2] == ["--check"]:
        sys.exit(check())
    path = sys.argv[1] if len(sys.argv) > 1 else dem_map.CSV
    mc = sys.argv[2] if len(sys.argv) > 2 else MODEL_CHECK
    sys.stdout.write(svg(dem_map.read_rows(path), dem_map.materials(), column_model(mc)))


if __name__ == "__main__":
    main()
