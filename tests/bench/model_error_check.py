#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How well `model_error` holds between the DEM map's angles (docs/dem.md
"Model error"): every interior point of every checked bed left out in turn.

Between two of an entry's angles the core (core/model_check.c,
`interpolate`) says the column model is within model_error +
model_error_uncertainty of the DEM: |v_column - v_DEM| interpolated
linearly plus the seed spread, and the uncertainty the seed spread plus up
to half the change of |v_column - v_DEM| across the interval (its full
share midway). The map measures every 15 degrees, so nothing tells how the
error runs between two of its angles, except the angles themselves: here
each point that has a neighbour on both sides is predicted from those two
alone, as if it had not been measured (midway across 30 degrees, twice the
map's spacing: a harder test than a user's angle between two points, which
lies at most 7.5 degrees from one), and its measured |v_column - v_DEM| is
compared with the bound. The same for two wider rules, to show what a bound
that held more often would cost in width.

    model_error_check.py            writes tests/bench/results/model_error_check.md
                                    from tests/bench/results/model_check.csv
    model_error_check.py --check    (make test) the committed page's tables are
                                    what the CSV gives, the rule here gives a
                                    hand-computed case, and (with CONVSIM, a
                                    convsim binary) the engine's model_error
                                    between two angles is the rule's

It runs nothing: it reads the table the build compiles in (`make
model-check` writes it).
"""
import csv
import json
import datetime
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CSV = os.path.join(HERE, "results", "model_check.csv")
PAGE = os.path.join(HERE, "results", "model_error_check.md")


def gap(r):
    """|v_column - v_DEM| at a map point, m/s."""
    return abs(float(r["v_column"]) - float(r["v_dem"]))


def spread(r):
    """The seeds' standard deviation (0 where the row has none)."""
    try:
        sd = float(r["v_dem_sd"])
    except ValueError:
        return 0.0
    return sd if sd == sd else 0.0


def error_at(lo, hi, w, share):
    """(model_error, model_error_uncertainty) at weight w between lo and hi
    (core/model_check.c `interpolate` with share 0.5)."""
    d_lo, d_hi, s_lo, s_hi = gap(lo), gap(hi), spread(lo), spread(hi)
    err = (1 - w) * d_lo + w * d_hi + (1 - w) * s_lo + w * s_hi
    unc = (1 - w) * s_lo + w * s_hi + 2.0 * min(w, 1.0 - w) * share * abs(d_hi - d_lo)
    return err, unc


def bound(lo, hi, w, share):
    """model_error + model_error_uncertainty."""
    return sum(error_at(lo, hi, w, share))


RULES = (("the engine's: half the change across the interval", 0.5),
         ("the full change", 1.0),
         ("twice the change", 2.0))


def entries(rows):
    """The map's entries (preset, settings, material, depth, drive, sense),
    each its rows by beta; senses with fewer than 3 angles dropped."""
    out = {}
    for r in rows:
        key = (r["preset"], r["settings"], r["material"], int(r["layers"]), r["drive"],
               r["rotation"])
        out.setdefault(key, []).append(r)
    return {k: sorted(v, key=lambda r: float(r["beta_deg"])) for k, v in out.items()
            if len(v) >= 3}


def held_out(ents, share):
    """Each interior point predicted from its two neighbours: (entry, beta,
    measured gap, bound, the entry's DEM peak) per point."""
    out = []
    for k, v in sorted(ents.items()):
        peak = max(abs(float(r["v_dem"])) for r in v)
        for i in range(1, len(v) - 1):
            lo, mid, hi = v[i - 1], v[i], v[i + 1]
            b0, b, b1 = (float(r["beta_deg"]) for r in (lo, mid, hi))
            out.append((k, b, gap(mid), bound(lo, hi, (b - b0) / (b1 - b0), share), peak))
    return out


def summary(points):
    n = len(points)
    held = sum(1 for p in points if p[2] <= p[3])
    over = [p[2] - p[3] for p in points if p[2] > p[3]]
    rel = [(p[2] - p[3]) / p[4] for p in points if p[2] > p[3]]
    width = statistics.median(p[3] for p in points)
    return n, held, width, max(over) if over else 0.0, max(rel) if rel else 0.0


def label(k):
    preset, settings, material, layers, drive, sense = k
    model = "default" if preset == "czubak2016" and settings in ("", "e=0.03225") else (
        "calibrated" if preset == "czubak2016" else preset)
    return "%s %d %s %s, %s" % (material, layers, drive, sense, model)


def tables(rows):
    ents = entries(rows)
    text = ["| bound | points | bound holds | median bound, m/s | worst miss, m/s | "
            "worst miss, % of the bed's DEM peak |", "|---|---|---|---|---|---|"]
    by_rule = [held_out(ents, share) for _, share in RULES]
    for (name, _), points in zip(RULES, by_rule):
        n, held, width, over, rel = summary(points)
        text.append("| %s | %d | %d (%.0f %%) | %.4f | %.4f | %.1f |"
                    % (name, n, held, 100.0 * held / n, width, over, 100.0 * rel))
    pts = by_rule[0]  # the engine's
    text += ["", "By angle (the engine's bound):", "",
             "| beta | points | bound holds |", "|---|---|---|"]
    for b in sorted({p[1] for p in pts}):
        at = [p for p in pts if p[1] == b]
        text.append("| %g | %d | %d |" % (b, len(at), sum(1 for p in at if p[2] <= p[3])))
    text += ["", "Every miss of the engine's bound, largest first (m/s):", "",
             "| entry | beta | \\|v_column - v_DEM\\| | bound | miss, % of peak |",
             "|---|---|---|---|---|"]
    for p in sorted((p for p in pts if p[2] > p[3]), key=lambda p: (p[3] - p[2]) / p[4]):
        text.append("| %s | %g | %.4f | %.4f | %.1f |"
                    % (label(p[0]), p[1], p[2], p[3], 100.0 * (p[2] - p[3]) / p[4]))
    return len(ents), text


def against_core(rows, convsim):
    """The rule here against the engine's own model_error: liggghts-bed4 (one
    entry) at 22.5 degrees clockwise, midway between its 15 and 30. None, or
    what differs."""
    at = {float(r["beta_deg"]): r for r in rows
          if r["preset"] == "liggghts-bed4" and r["rotation"] == "cw"}
    want = error_at(at[15.0], at[30.0], 0.5, 0.5)
    out = subprocess.run([convsim, "run", "-q", "-d", "0.01", "-p", "liggghts-bed4", "--set",
                          "beta=22.5", "--set", "rotation=cw"], capture_output=True, text=True)
    s = json.loads(out.stdout)
    got = (s["model_error"], s["model_error_uncertainty"])
    # the core rounds both to 1e-8 m/s
    if any(abs(g - w) > 1e-8 for g, w in zip(got, want)):
        return "the engine says %r, the rule here %r" % (got, want)
    return None


def check():
    # the rule on a hand-computed case: gaps 0.01 and 0.03, spreads 0.002
    # and 0.004, a quarter of the way: model_error 0.015 + 0.0025, its
    # uncertainty 0.0025 + 2 * 0.25 * 0.5 * 0.02 = 0.0075
    lo = {"v_column": "0.11", "v_dem": "0.10", "v_dem_sd": "0.002"}
    hi = {"v_column": "0.17", "v_dem": "0.20", "v_dem_sd": "0.004"}
    e, u = error_at(lo, hi, 0.25, 0.5)
    if abs(e - 0.0175) > 1e-12 or abs(u - 0.0075) > 1e-12:
        print("model_error_check: the rule gives %.6g and %.6g, not 0.0175 and 0.0075" % (e, u))
        return 1
    rows = list(csv.DictReader(open(CSV)))
    convsim = os.environ.get("CONVSIM")
    differs = against_core(rows, convsim) if convsim else None
    if differs:
        print("model_error_check: " + differs)
        return 1
    page = open(PAGE).read()
    _, text = tables(rows)
    if "\n".join(text) not in page:
        print("model_error_check: %s is not what %s gives; run python3 "
              "tests/bench/model_error_check.py" % (os.path.relpath(PAGE), os.path.relpath(CSV)))
        return 1
    print("# pass 1")
    return 0


def main():
    if sys.argv[1:] == ["--check"]:
        return check()
    rows = list(csv.DictReader(open(CSV)))
    n, text = tables(rows)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    rev = subprocess.run(["git", "-C", HERE, "rev-parse", "--short=12", "HEAD"],
                         capture_output=True, text=True).stdout.strip() or "unknown"
    with open(PAGE, "w") as f:
        f.write("# model_error between the map's angles, each point left out\n\n")
        f.write("`python3 tests/bench/model_error_check.py` on %s, build `%s`, %d cores (it "
                "runs nothing: it reads tests/bench/results/model_check.csv, %d rows, %d "
                "entries with 3 angles or more in a sense). Each point with a neighbour on "
                "both sides is predicted from those two alone, midway across 30 degrees, by the "
                "engine's "
                "rule (core/model_check.c: model_error + model_error_uncertainty) and by two "
                "wider ones; \"bound holds\": its measured |v_column - v_DEM| is within the "
                "bound.\n\n" % (now, rev, os.cpu_count() or 1, len(rows), n))
        f.write("\n".join(text) + "\n")
    print("wrote %s" % os.path.relpath(PAGE))
    return 0


if __name__ == "__main__":
    sys.exit(main())
