# SPDX-License-Identifier: GPL-3.0-or-later
"""The DEM map's points: which row of tests/bench/results/dem_map.csv gives a
point its value. One rule, read by the map's report (dem_map_report.py), the
column model's check (model_check.py) and its calibration (dem_calibrate.py).

A clockwise point is taken from its rows in the map's cell (dem_map.WIDTH
diameters across the deck) with role map or stiffness: the softest Young's
modulus, not softer than the map's, whose largest overlap is within OVERLAP
of a mean diameter; where none is, the stiffest run. A point exists once its
map row does. A counter-clockwise point is a mirror row (the map runs
clockwise; the mirror checks run counter-clockwise), taken by the same
stiffness rule among that point's mirror rows in the map's cell.
"""
import dem_map

OVERLAP = 0.01  # the largest overlap allowed, of a mean diameter
ROLES = {"cw": ("map", "stiffness"), "ccw": ("mirror",)}


def f(x):
    return float(x)


def e_map_of(mats=None):
    """The map's Young's modulus (Pa)."""
    return (mats or dem_map.materials())["map"]["youngs_map"]


def rungs(rows, material, layers, drive, beta, rotation="cw"):
    """The point's rows in the map's cell that may give it its value: every
    Young's modulus run there (roles map and stiffness; mirror for ccw)."""
    roles = ROLES[rotation]
    return [r for r in rows if r["material"] == material and int(r["layers"]) == layers and
            r["drive"] == drive and f(r["beta_deg"]) == beta and r["rotation"] == rotation and
            f(r["cell_width_d"]) == dem_map.WIDTH and r["role"] in roles]


def chosen(rows, material, layers, drive, beta, rotation="cw", mats=None):
    """The row that gives the point its value, or None where it has none."""
    roles = ROLES[rotation]
    rs = rungs(rows, material, layers, drive, beta, rotation)
    if not any(r["role"] == roles[0] for r in rs):
        return None
    rs.sort(key=lambda r: f(r["e_scale"]))
    e_map = e_map_of(mats)
    ok = [r for r in rs if f(r["overlap_max_rel"]) <= OVERLAP and f(r["youngs_pa"]) >= e_map]
    return ok[0] if ok else rs[-1]


def beds(rows):
    """The (material, layers, drive) that have map rows, in the CSV's order."""
    seen = []
    for r in rows:
        k = (r["material"], int(r["layers"]), r["drive"])
        if r["role"] == "map" and k not in seen:
            seen.append(k)
    return seen


def points(rows, material, layers, drive, mats=None):
    """A bed's points, each its chosen row: clockwise by beta, then
    counter-clockwise by beta."""
    out = []
    for rotation in ("cw", "ccw"):
        betas = sorted({f(r["beta_deg"]) for r in rows if r["material"] == material and
                        int(r["layers"]) == layers and r["drive"] == drive and
                        r["rotation"] == rotation})
        for b in betas:
            r = chosen(rows, material, layers, drive, b, rotation, mats)
            if r:
                out.append(r)
    return out
