#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The DEM map as its own fast model: how far a held-out bed is from its
neighbours in depth (`make fast-feed-check` runs it after
fast_feed_check.py; docs/feed-models.md).

    depth_surrogate.py [CSV]    reads tests/bench/results/fast_feed.csv (or
                                CSV), writes tests/bench/results/
                                depth_surrogate.md
    depth_surrogate.py --check  (make test) the committed page's rows are
                                those of the committed CSV, and no
                                prediction reads the bed it predicts

Two predictions of each map point from the other depths of the same
material at the same drive and angle, never from the bed itself (leave one
bed out, as fast_feed_check.py):
  map       v_DEM interpolated linearly in log(depth) between the nearest
            shallower and deeper bed; beyond the shallowest or deepest,
            the nearest bed's v (no extrapolation);
  map+model the paper's column model at the point plus the DEM's
            difference from it (v_DEM - v_column) interpolated the same
            way: a correction that could move to another machine.
Each against the target of docs/feed-models.md: |v - v_DEM| <= 5 % of
the bed's DEM peak |v|. Neither runs anything: they read the CSV's
v_dem, peak and v_paper columns.
"""
import collections
import csv
import datetime
import math
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TOL = 0.05


def read(path):
    beds = collections.defaultdict(dict)
    peak = {}
    for r in csv.DictReader(open(path, newline="")):
        k = (r["material"], r["drive"], int(r["depth"]))
        beds[k][int(r["beta"])] = (float(r["v_dem"]), float(r["v_paper"]))
        peak[k] = float(r["peak"])
    return beds, peak


def predict(beds, k, beta, corrected):
    """v at bed k (material, drive, depth), angle beta, from the other
    depths of the same material and drive; None where there is none."""
    mat, drive, d = k
    others = sorted(x for (m, dv, x) in beds if (m, dv) == (mat, drive) and x != d)
    if not others:
        return None

    def at(x):
        v_dem, v_col = beds[(mat, drive, x)][beta]
        return v_dem - v_col if corrected else v_dem

    lo = [x for x in others if x < d]
    hi = [x for x in others if x > d]
    if lo and hi:
        a, b = lo[-1], hi[0]
        w = (math.log(d) - math.log(a)) / (math.log(b) - math.log(a))
        v = (1 - w) * at(a) + w * at(b)
    else:
        v = at(lo[-1] if lo else hi[0])
    return v + beds[k][beta][1] if corrected else v


def table(beds, peak):
    rows = []
    for name, corrected in (("map", False), ("map+model", True)):
        errs, within = [], collections.Counter()
        for k in sorted(beds):
            for beta in sorted(beds[k]):
                v = predict(beds, k, beta, corrected)
                if v is None:
                    continue
                e = abs(v - beds[k][beta][0]) / peak[k]
                errs.append(e)
                within[k] += e <= TOL
        n, ok = len(errs), sum(e <= TOL for e in errs)
        rows.append((name, ok, n, max(errs), sorted(errs)[n // 2], within))
    return rows


def noise_text(path):
    """The share of the points a model exactly at the DEM's expectation would put within
    TOL: each point's v_DEM is the mean of its seeds (3), its error normal with the standard
    error sd / sqrt(3) (the seeds' sd in the CSV)."""
    rows = list(csv.DictReader(open(path, newline="")))
    share = sum(math.erf(TOL / (se * math.sqrt(2))) if se > 0 else 1.0 for se in
                (float(r["sd"]) / math.sqrt(3) / float(r["peak"]) for r in rows)) / len(rows)
    return ("The map's own scatter: a model exactly at the DEM's expectation would be within 5 %% "
            "at %.1f %% of the points (each point's mean of three seeds, its standard error the "
            "seeds' sd over the root of 3, its error normal), so the target is not set by the "
            "DEM's noise." % (100 * share))


def rows_text(rows):
    return ["| %s | %d of %d (%.0f %%) | %.1f %% | %.1f %% |"
            % (name, ok, n, 100 * ok / n, 100 * worst, 100 * med)
            for name, ok, n, worst, med, _ in rows]


def check():
    """The page's summary rows are what the CSV gives now, and a bed's
    predictions do not move when its own v_DEM does (leave one bed out)."""
    src = os.path.join(HERE, "results", "fast_feed.csv")
    beds, peak = read(src)
    page = open(os.path.join(HERE, "results", "depth_surrogate.md")).read().splitlines()
    bad = [r for r in rows_text(table(beds, peak)) + [noise_text(src)] if r not in page]
    for k in beds:
        before = {b: [predict(beds, k, b, c) for c in (False, True)] for b in beds[k]}
        saved = dict(beds[k])
        beds[k] = {b: (v + 1.0, col) for b, (v, col) in saved.items()}
        after = {b: [predict(beds, k, b, c) for c in (False, True)] for b in beds[k]}
        beds[k] = saved
        if before != after:
            bad.append("%s %s %d: its predictions read its own v_DEM" % k)
    for line in bad:
        print("depth_surrogate: %s" % line)
    print("depth_surrogate: %s" % ("%d problems" % len(bad) if bad else "the page is the CSV's; "
                                    "no bed predicts itself"))
    return 1 if bad else 0


def main():
    if sys.argv[1:] == ["--check"]:
        return check()
    src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "results", "fast_feed.csv")
    beds, peak = read(src)
    rows = table(beds, peak)
    out = os.path.join(HERE, "results", "depth_surrogate.md")
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    names = ["%s %s %d" % k for k in sorted(beds)]
    rev = subprocess.run(["git", "-C", HERE, "rev-parse", "--short=12", "HEAD"],
                         capture_output=True, text=True).stdout.strip() or "unknown"
    made = os.path.join(os.path.dirname(src), "fast_feed.md")
    m = re.search(r"build `([0-9a-f]+)`", open(made).read()) if os.path.exists(made) else None
    with open(out, "w") as f:
        f.write("# The DEM map as its own fast model (leave one bed out)\n\n")
        f.write("`python3 tests/bench/depth_surrogate.py` (part of `make fast-feed-check`) on %s, "
                "build `%s`, %d cores (it runs nothing: it reads the map's points and the column "
                "model's v from fast_feed.csv, made by build `%s`), "
                "from %s: %d points of %d beds. Each point predicted from the same material's "
                "other depths at the same drive and angle (`map`: v_DEM interpolated in "
                "log(depth), the nearest depth beyond the ends; `map+model`: the paper's column "
                "model plus the DEM's difference from it, interpolated the same way). Error = "
                "|v - v_DEM| / the bed's DEM peak; the target is 5 %% at 90 %% of the points.\n\n"
                % (now, rev, os.cpu_count() or 1, m.group(1) if m else "unknown",
                   os.path.relpath(src, os.path.join(HERE, "..", "..")),
                   sum(len(b) for b in beds.values()), len(beds)))
        f.write("| prediction | points within 5 % | worst | median |\n|---|---|---|---|\n")
        f.write("".join(r + "\n" for r in rows_text(rows)))
        f.write("\n%s\n" % noise_text(src))
        f.write("\nPoints within 5 %%, bed by bed:\n\n| bed | %s |\n|---|%s\n"
                % (" | ".join(r[0] for r in rows), "---|" * len(rows)))
        for k, label in zip(sorted(beds), names):
            f.write("| %s | %s |\n" % (label, " | ".join(
                "%d of %d" % (r[5][k], len(beds[k])) for r in rows)))
    print("wrote %s" % os.path.relpath(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
