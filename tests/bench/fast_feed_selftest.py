#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The self-test of tests/bench/fast_feed_check.py (`fast_feed_check.py
--self-test`, in `make test`): its leave-one-depth-out bookkeeping on a
fake runner whose v is a known function of the candidate and the point,
no convsim needed."""
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fast_feed_check import R_FLOOR, add_ceiling, ceiling, dissipation, evaluate, fit, resolve, rests, \
    training  # noqa: E402

GLASS = {"e_pw": 0.9, "e_pp": 0.97, "mu_pw": 0.15}  # dem/materials.json's, in part
WHEAT = {"e_pw": 0.5, "e_pp": 0.5, "mu_pw": 0.3}


class FakeRunner:
    """The self-test's runner: v = a known function of the candidate and
    the point; records the depths each get() saw."""

    def __init__(self):
        self.seen = []
        self.beds = set()

    def cost(self, cand, p):
        return float(len(cand.get("Rs", (1,))))

    def long_v(self, cand, p):
        return self.get(cand, p)[0]

    def get(self, cand, p):
        self.seen.append(p["depth"])
        self.beds.add((p["material"], p["depth"]))
        cand = resolve(cand, p)
        if "e" in cand:
            return cand["mu"] * p["beta"] / 100.0, 1.0
        # the depth-d data are made by R = 0.15 d (d = 1, 2: 0.15, 0.3)
        return statistics.fmean(r * p["beta"] / 100.0 for r in rests(cand, p)), 1.0


def self_test():
    """Checks of the harness itself (no convsim): a fit never sees the
    depth it predicts, and the errors are (v - v_DEM) / the peak."""
    pts = [{"material": "m", "drive": "preset", "depth": d, "beta": b, "v_dem": 0.15 * d * b / 100.0,
            "sd": 0.0, "mat": GLASS} for d in (1, 2) for b in (30, 60, 90)]
    peak = {("m", "preset", d): 0.15 * d * 0.9 for d in (1, 2)}
    run = FakeRunner()
    train = [p for p in pts if p["depth"] == 2]
    best = fit(run, "closure", train, peak)
    checks = [("a fit sees only its training depth", set(run.seen) == {2}),
              ("the fit finds the training depth's R", best["Rs"] == (0.3,))]
    recs = evaluate(FakeRunner(), pts, peak)
    r = [x for x in recs if x["depth"] == 1 and x["beta"] == 90][0]
    # depth 1 predicted by depth 2's R 0.3: v 0.27 against 0.135, peak 0.135
    checks.append(("held-out error", abs(r["closure_err"] - 1.0) < 1e-12))
    checks.append(("paper's error", abs(r["err_paper"] - (0.045 - 0.135) / 0.135) < 1e-12))
    lay = {"Rs": (0.5, 0.75), "P": 1}
    checks.append(("layered: R^d at P 1", rests(lay, {"depth": 2}) == (0.25, 0.5625)))
    checks.append(("layered: R^(d^0.5) at P 0.5",
                   rests(dict(lay, P=0.5), {"depth": 4}) == (0.25, 0.5625)))
    checks.append(("layered: R at P 0", rests(dict(lay, P=0), {"depth": 8}) == (0.5, 0.75)))
    checks.append(("layered: R no less than convsim's 0.001",
                   rests({"Rs": (0.05,), "P": 1}, {"depth": 8}) == (R_FLOOR,)))
    run = FakeRunner()
    fit(run, "layered", train, peak)
    checks.append(("a layered fit sees only its training depth", set(run.seen) == {2}))
    # held out, depth 1 runs the depth-2 fit's R at d = 1: R_bed = R, whatever P
    lr = [x for x in recs if x["depth"] == 1]
    best = fit(FakeRunner(), "layered", train, peak)
    checks.append(("layered held out at depth 1", all(
        abs(x["layered_v"] - statistics.fmean(best["Rs"]) * x["beta"] / 100.0) < 1e-12 for x in lr)))
    run = FakeRunner()
    whole = ceiling(run, pts, peak)
    checks.append(("the ceiling's fit sees every bed", set(run.seen) == {1, 2}))
    # no one R makes both depths (R 0.15 d): the tie goes to the first grid point, R 0.15,
    # exact at depth 1 and (0.15 - 0.3) beta / 100 over the peak 0.27 at depth 2
    add_ceiling(FakeRunner(), recs, whole)
    errs = sorted(round(x["closure_err_all"], 12) for x in recs)
    checks.append(("the ceiling: one closure for both depths, right at one of them",
                   whole["closure"]["Rs"] == (0.15,) and errs == [round(-b / 180, 12) for b in
                                                             (90, 60, 30)] + [0.0] * 3))
    checks += collapse_checks()
    checks += summary_checks()
    for name, ok in checks:
        print("%s - %s" % ("ok" if ok else "not ok", name))
    failed = sum(1 for _, ok in checks if not ok)
    print("# pass %d\n# fail %d" % (len(checks) - failed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(self_test())


def summary_checks():
    """A run that failed (NaN) is a miss in the summary: within 5 % at no
    point, the worst "a run failed", the median as if it were the largest."""
    from fast_feed_report import pct_of, summary
    recs = [{"e": math.nan}, {"e": 0.01}, {"e": -0.02}]
    n, tot, worst, med = summary(recs, "e")
    return [("summary: a failed run is a miss", (n, tot) == (2, 3)),
            ("summary: the worst names the failed run", pct_of(worst) == "a run failed"),
            ("summary: the median counts it as the largest", abs(med - 0.02) < 1e-15)]


def collapse_checks():
    """`collapse`: D from the material's restitutions, the regime and mu
    it picks, D_c between the training beds, and leave one bed out across
    materials (a wheat bed held out is fitted on the glass beds and the
    other wheat bed, never on itself)."""
    g8 = {"depth": 8, "mat": GLASS}
    checks = [("collapse: D of glass 8 deep", abs(dissipation(g8) - (0.19 + 7 * 0.0591)) < 1e-12),
              ("collapse: D of wheat 1 deep", abs(dissipation({"depth": 1, "mat": WHEAT}) - 0.75)
               < 1e-12)]
    cand = {"Dc": 0.5, "bouncy": {"Rs": (0.3, 0.75), "c": 2, "k_c": 1e6, "layers": "one"},
            "collapsed": {"Rs": (0.05, 0.4), "c": 4 / 3, "k_c": 1e7, "layers": "one"}}
    checks.append(("collapse: glass 1 deep is bouncy, mu 2 * 0.15",
                   resolve(cand, {"depth": 1, "mat": GLASS}) ==
                   {"Rs": (0.3, 0.75), "c": 2, "k_c": 1e6, "layers": "one", "mu": 0.3}))
    checks.append(("collapse: glass 8 deep has collapsed, mu 4/3 * 0.15",
                   resolve(cand, g8)["Rs"] == (0.05, 0.4) and resolve(cand, g8)["mu"] == 0.2))
    # the fake data: v = mean(R) * beta / 100 with R 0.3 for a bouncy bed, 0.05 a collapsed one
    beds = [("glass", GLASS, 1, 0.3), ("glass", GLASS, 2, 0.3), ("wheat", WHEAT, 1, 0.05),
            ("wheat", WHEAT, 2, 0.05)]
    pts = [{"material": m, "drive": "preset", "depth": d, "beta": b, "v_dem": r * b / 100.0,
            "sd": 0.0, "mat": mat} for m, mat, d, r in beds for b in (30, 60, 90)]
    peak = {(m, "preset", d): r * 0.9 for m, _, d, r in beds}
    best = fit(FakeRunner(), "collapse", pts, peak)
    d_glass2, d_wheat1 = 0.19 + 0.0591, 0.75
    checks.append(("collapse: D_c between glass 2 and wheat 1 deep",
                   abs(best["Dc"] - (d_glass2 * d_wheat1) ** 0.5) < 1e-9))
    checks.append(("collapse: each regime's R", best["bouncy"]["Rs"] == (0.3, 0.3)
                   and best["collapsed"]["Rs"] == (0.05, 0.05)))
    run = FakeRunner()
    train = [p for p in pts if (p["material"], p["depth"]) != ("wheat", 2)]
    fit(run, "collapse", train, peak)
    checks.append(("collapse: a fit sees only its training beds",
                   run.beds == {("glass", 1), ("glass", 2), ("wheat", 1)}))
    recs = evaluate(FakeRunner(), pts, peak)
    w2 = [x for x in recs if (x["material"], x["depth"]) == ("wheat", 2)]
    checks.append(("collapse: wheat 2 deep held out, predicted by the collapsed regime",
                   all(abs(x["collapse_err"]) < 1e-12 for x in w2)))
    # two drives: a bed is held out on both, and the other drive's other beds train
    two = [dict(p, drive=dr) for p in pts for dr in ("preset", "a150")]
    seen = {(p["material"], p["drive"], p["depth"]) for p in training(two, "wheat", 2)}
    checks.append(("training: never the held-out material and depth, on either drive",
                   seen == {(m, dr, d) for m, d in (("glass", 1), ("glass", 2), ("wheat", 1))
                            for dr in ("preset", "a150")}))
    peak2 = {(m, dr, d): v for (m, _, d), v in peak.items() for dr in ("preset", "a150")}
    recs = evaluate(FakeRunner(), two, peak2)
    checks.append(("evaluate: every bed predicted on both drives",
                   len(recs) == len(two) and {r["drive"] for r in recs} == {"preset", "a150"}))
    return checks
