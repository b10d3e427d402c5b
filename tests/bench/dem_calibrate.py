#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The column model against the DEM map, as a user would use it: for each
material, depth and drive of tests/bench/results/dem_map.csv, calibrate the
column model on three of the map's points with `convsim fit --data`, predict
the bed's other points with the calibrated model, and tabulate the error and
how far it moves when a calibration point moves by its seeds' spread.

    dem_calibrate.py [CONVSIM]     (`make bench-dem-calibrate`)

Writes tests/bench/results/dem_calibration.md (the page) and
tests/bench/model_presets.csv (one line per calibrated bed, which `make
model-check` turns into the model_error table). Each point's value is taken
by the map report's rule (dem_points.py).

The calibration (DESIGN): mu, the friction of the bed on the deck, is the
material's grain-on-deck friction (mu_pw in dem/materials.json), not fitted;
k_c and R are fitted (from liggghts-bed4's values, FITSTARTS starts) to
three points of the bed's clockwise sweep: the forward peak (largest v), the
reverse peak (smallest v) and the map angle next past the reverse peak, away
from the forward peak, where the reverse flow falls off. Two parameters on
three points: one degree of freedom; among the fit's equally good ends the
one nearest liggghts-bed4's (choose()). k_c's lower bound (SINK) grows with
the depth; DESIGN says why. Every datum's sigma is the root mean
square of the bed's seed spreads. A bed is calibrated once its clockwise
sweep is complete (every angle of dem_map.BETAS); beds with fewer are named
and skipped.

Stability: each calibration point in turn is moved by its seeds' standard
deviation, up and down, and the bed calibrated again; the page gives how far
the worst error and any predicted v move. FORMER is the calibration this
replaced (k_c, R and mu all free on the two peaks and the mid-branch angle),
run through the same perturbations for comparison.

The model is run one-way, as the DEM bed is driven, with model_check.py's
measure (model_check.MEASURE), so the table's errors are the model_error the
engine reports at the points.
"""
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import dem_map  # noqa: E402
import dem_points  # noqa: E402
import model_check  # noqa: E402
import provenance  # noqa: E402

PAGE = os.path.join(HERE, "results", "dem_calibration.md")
START = "liggghts-bed4"       # the fit's starting values
PRESET = "czubak2016"         # the calibrated model: this preset and its settings
FITSTARTS = 8
GOOD = 0.05                   # "within 5 % of the peak"
# k_c from SINK: the bed's weight (layers x m_n g, the preset's m_n 0.5 kg)
# may press the bottom contact at most a grain diameter (4 mm) into the deck,
# k_c >= layers x 1226 N/m; softer, a calibration four grains deep (k_c 1.8e3)
# sank centimetres at an angle it was not fitted at and the run diverged.
# Above 1e8 the steps cost. R up to 0.6 as before.
M_N_G = 0.5 * 9.81
SINK = 0.004
DESIGN = {"name": "mu fixed", "free": "k_c:{kc_min:.6g}:1e8,R:0.01:0.6", "fix_mu": True,
          "third": "past reverse peak", "choose": True}
FORMER = {"name": "former", "free": "k_c:100:1e8,R:0.01:0.6,mu:0.1:1.5", "fix_mu": False,
          "third": "mid-branch", "choose": False}
# The choice among equally good ends (DESIGN's "choose"): of the fit's starts
# that did not fail, those whose chi2 is within the margin of the lowest count
# as equally good: chi2 <= lowest + max(1, lowest / dof), one unit of chi2 (the
# usual one-parameter interval) once the data's sigma is scaled so that the
# lowest chi2 per degree of freedom is 1 (where the model's own misfit, not the
# seeds' scatter, makes chi2 large); of those, the calibration is the end nearest REFERENCE,
# liggghts-bed4's k_c and R, in (log10 k_c, R), each over its search range.
# Three points leave k_c and R a valley or two near-equal minima; without the
# rule the lowest chi2 jumps between them when a point moves by its scatter.
REFERENCE = {"k_c": 25613.34, "R": 0.17732}


machine = provenance.machine


def git_build():
    """The commit of this tree, and whether it differs from it."""
    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                          cwd=HERE).stdout.strip()
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "core", "cli", "fit"],
                           cwd=HERE).returncode != 0
    return head[:12] + (" (with uncommitted changes to core/, cli/ or fit/)" if dirty else "")


def beta(r):
    return float(r["beta_deg"])


def calibration_points(cw, third):
    """The forward peak, the reverse peak and the third point of a bed's
    clockwise points (rows), as (name, row). third "past reverse peak": the
    next map angle beyond the reverse peak, away from the forward peak;
    "mid-branch" (or where there is none past): the angle between the peaks
    nearest their middle (the lower of two)."""
    fwd = max(cw, key=lambda r: float(r["v_dem"]))
    rev = min(cw, key=lambda r: float(r["v_dem"]))
    bf, br = beta(fwd), beta(rev)
    pick = [("forward peak", fwd), ("reverse peak", rev)]
    side = 1 if br > bf else -1
    past = [r for r in cw if (beta(r) - br) * side > 0]
    if third == "past reverse peak" and past:
        return pick + [("past reverse peak", min(past, key=lambda r: abs(beta(r) - br)))]
    mid = 0.5 * (bf + br)
    between = [r for r in cw if min(bf, br) < beta(r) < max(bf, br)]
    if between:
        pick.append(("mid-branch", min(between, key=lambda r: (abs(beta(r) - mid), beta(r)))))
    return pick


def fixed_settings(design, material, mats):
    """The settings a design fixes from the material: mu = mu_pw."""
    if not design["fix_mu"]:
        return []
    return ["mu=%g" % mats["materials"][material]["mu_pw"]]


def fit_command(convsim, data, layers, drive, out, design, fixed):
    free = design["free"].format(kc_min=layers * M_N_G / SINK)
    args = [convsim, "fit", "-p", START, "--data", data, "--free", free,
            "--set", "layers=%d" % layers, "--set", "feed_coupling=false"]
    for s in fixed:
        args += ["--set", s]
    args += dem_map.DRIVES[drive]
    args += model_check.MEASURE + ["--starts", str(FITSTARTS), "--threads", "2",
                                   "--curve-step", "0", "-q", "-o", out]
    return args


def shown(args):
    return " ".join(os.path.relpath(a) if os.path.isabs(a) else a for a in args)


def choose(result):
    """The end taken among the fit's starts (see DESIGN): {"start", "value"
    (by parameter), "chi2", "equal" (how many ends were within the margin)}."""
    pars = result["parameters"]
    runs = [(i, s) for i, s in enumerate(result.get("starts") or [])
            if s["status"] != "failed" and s["chi2"] is not None
            and all(v is not None for v in s["value"])]
    if not runs:
        return {"start": result.get("best_start", 0), "chi2": result["chi2"], "equal": 1,
                "value": {p["name"]: p["value"] for p in pars}}
    low = min(s["chi2"] for _, s in runs)
    margin = max(1.0, low / max(result.get("dof") or 1, 1))
    equal = [(i, s) for i, s in runs if s["chi2"] <= low + margin]

    def distance(run):
        d = 0.0
        for p, v in zip(pars, run[1]["value"]):
            ref = REFERENCE.get(p["name"])
            if ref is None:
                continue
            if p["name"] == "k_c":
                d += (math.log10(v / ref) / math.log10(p["max"] / p["min"])) ** 2
            else:
                d += ((v - ref) / (p["max"] - p["min"])) ** 2
        return (d, run[0])
    i, s = min(equal, key=distance)
    return {"start": i, "chi2": s["chi2"], "equal": len(equal),
            "value": {p["name"]: v for p, v in zip(pars, s["value"])}}


def fit(convsim, data, sigma, layers, drive, design, fixed):
    """`convsim fit` on data, [(beta, rotation, v)]: (its result, the
    command as shown, the calibrated model's settings). With the design's
    "choose", the settings are choose()'s end, in result["chosen"]; else
    the lowest chi2's."""
    with tempfile.TemporaryDirectory() as tmp:
        path, out = os.path.join(tmp, "points.csv"), os.path.join(tmp, "fit.json")
        with open(path, "w") as fh:
            fh.write("beta,rotation,v,sigma\n")
            for b, rot, v in data:
                fh.write("%g,%s,%.6g,%.6g\n" % (b, rot, v, sigma))
        args = fit_command(convsim, path, layers, drive, out, design, fixed)
        subprocess.run(args, check=True)
        with open(out) as fh:
            result = json.load(fh)
    args = [{path: "POINTS.csv", out: "fit.json"}.get(a, a) for a in args]
    drive_sets = [a for a in dem_map.DRIVES[drive] if a != "--set"]
    if design.get("choose"):
        result["chosen"] = choose(result)
        values = result["chosen"]["value"]
    else:
        values = {p["name"]: p["value"] for p in result["parameters"]}
    settings = ";".join(drive_sets + fixed + ["%s=%.6g" % (p["name"], values[p["name"]])
                                              for p in result["parameters"]])
    return result, shown(args), settings


def data_of(rows, moved=None, dv=0.0):
    """[(beta, rotation, v)] of rows, row number moved shifted by dv."""
    return [(beta(r), r["rotation"], float(r["v_dem"]) + (dv if i == moved else 0.0))
            for i, r in enumerate(rows)]


def predict(convsim, pts, settings, layers, peak, calib_rows=()):
    """[(row, v_column, |v_column - v_DEM| / peak, calibration point?)]; a
    run that diverges is v nan, error inf."""
    out = []
    for r in pts:
        p = {"preset": PRESET, "settings": settings, "layers": layers,
             "beta_deg": beta(r), "rotation": r["rotation"]}
        try:
            v = model_check.v_column(convsim, p)
            err = abs(v - float(r["v_dem"])) / peak
        except subprocess.CalledProcessError:
            v, err = float("nan"), float("inf")
        out.append((r, v, err, any(r is c for c in calib_rows)))
    return out


def stats(pred):
    """(worst entry, median error, how many within GOOD) over pred."""
    worst = max(pred, key=lambda x: x[2])
    return worst, statistics.median(x[2] for x in pred), sum(1 for x in pred if x[2] <= GOOD)


def worst_predicted(pred):
    return stats([x for x in pred if not x[3]])[0][2]


def calibrate_design(convsim, bed, design, mats):
    """A bed's calibration by design: the fit on its three points, its
    predictions, and each perturbed fit's settings, worst error and largest
    move of a predicted v (of the peak)."""
    pts, cw, layers, drive = bed["points"], bed["cw"], bed["layers"], bed["drive"]
    calib = calibration_points(cw, design["third"])
    crow = [r for _, r in calib]
    fixed = fixed_settings(design, bed["material"], mats)
    c = {"calib": calib, "fixed": fixed}
    c["fit"], c["command"], c["settings"] = fit(convsim, data_of(crow), bed["sigma"], layers,
                                                drive, design, fixed)
    c["pred"] = predict(convsim, pts, c["settings"], layers, bed["peak"], crow)
    base = worst_predicted(c["pred"])
    c["moves"] = []
    for i, (name, r) in enumerate(calib):
        for sign in (1, -1):
            dv = sign * float(r["v_dem_sd"])
            _, _, settings = fit(convsim, data_of(crow, i, dv), bed["sigma"], layers, drive,
                                 design, fixed)
            pred = predict(convsim, pts, settings, layers, bed["peak"], crow)
            dvmax = max(abs(a[1] - b[1]) for a, b in zip(pred, c["pred"])) / bed["peak"]
            c["moves"].append((name, dv, settings, worst_predicted(pred), dvmax))
    c["d_worst"] = max(abs(m[3] - base) for m in c["moves"])
    c["d_v"] = max(m[4] for m in c["moves"])
    return c


def calibrate(convsim, rows, material, layers, drive, mats):
    """One bed: the calibration (DESIGN) and the former one (FORMER), and the
    fit on all the bed's points (the column model's best over the bed, mu
    fixed as in DESIGN); 'why' where it cannot be calibrated."""
    pts = dem_points.points(rows, material, layers, drive, mats)
    cw = [r for r in pts if r["rotation"] == "cw"]
    bed = {"material": material, "layers": layers, "drive": drive, "points": pts, "cw": cw}
    have = {beta(r) for r in cw}
    if not all(float(b) in have for b in dem_map.BETAS):
        bed["why"] = "%d of the %d clockwise angles measured so far" % (len(have), len(dem_map.BETAS))
        return bed
    bed["sigma"] = statistics.fmean(float(r["v_dem_sd"]) ** 2 for r in cw) ** 0.5
    bed["peak"] = max(abs(float(r["v_dem"])) for r in pts)
    bed["now"] = calibrate_design(convsim, bed, DESIGN, mats)
    bed["former"] = calibrate_design(convsim, bed, FORMER, mats)
    fixed = bed["now"]["fixed"]
    bed["all_fit"], _, bed["all_settings"] = fit(convsim, data_of(pts), bed["sigma"], layers,
                                                 drive, dict(DESIGN, choose=False), fixed)
    bed["all_pred"] = predict(convsim, pts, bed["all_settings"], layers, bed["peak"])
    return bed


def pct(x):
    return "%.1f %%" % (100 * x) if math.isfinite(x) else "diverges"


def moved(x):
    """A stability figure in points of %; a diverging run makes it none."""
    return "%.1f" % (100 * x) if math.isfinite(x) else "diverges"


def summary_line(b):
    if "why" in b:
        return "| %s | %s | %d | not calibrated: %s | | | | | | | |" % (
            b["material"], b["drive"], b["layers"], b["why"])
    c = b["now"]
    calib = ", ".join("%s %g° cw" % (n, beta(r)) for n, r in c["calib"])
    values = c["fit"].get("chosen", {}).get("value", {})
    pars = ", ".join(c["fixed"] + ["%s %.3g" % (p["name"], values.get(p["name"], p["value"]))
                                   for p in c["fit"]["parameters"]])
    rest = [x for x in c["pred"] if not x[3]]
    worst, med, good = stats(rest)
    aw, am, _ = stats(b["all_pred"])
    return ("| %s | %s | %d | %s | %s | %d | %s (%g° %s) | %s | %d of %d | "
            "%s / %s | %s / %s |" % (
                b["material"], b["drive"], b["layers"], calib, pars, len(rest), pct(worst[2]),
                beta(worst[0]), worst[0]["rotation"], pct(med), good, len(rest),
                moved(c["d_worst"]), moved(c["d_v"]), pct(aw[2]), pct(am)))


def former_line(b):
    n, f = b["now"], b["former"]
    calib = ", ".join("%g°" % beta(r) for _, r in f["calib"])
    pars = ", ".join("%s %.3g" % (p["name"], p["value"]) for p in f["fit"]["parameters"])
    ranges = [(min(m[3] for m in c["moves"]), max(m[3] for m in c["moves"])) for c in (f, n)]
    return "| %s | %s | %d | %s | %s | %s | %s–%s | %s / %s | %s | %s–%s | %s / %s |" % (
        b["material"], b["drive"], b["layers"], calib, pars, pct(worst_predicted(f["pred"])),
        pct(ranges[0][0]), pct(ranges[0][1]), moved(f["d_worst"]), moved(f["d_v"]),
        pct(worst_predicted(n["pred"])), pct(ranges[1][0]), pct(ranges[1][1]),
        moved(n["d_worst"]), moved(n["d_v"]))


def detail(b, w):
    c = b["now"]
    w("### %s, %d grains deep, drive `%s`" % (b["material"], b["layers"], b["drive"]))
    w("")
    fit = c["fit"]
    w("Fit on the three points (its lowest χ²): %s after %d iterations, χ² %.3g on %d degree(s) of freedom, "
      "σ %.4f m/s; settings `%s` on the preset %s (the line of tests/bench/model_presets.csv). "
      "On all %d points: `%s`, χ² %.3g on %d degrees of freedom." %
      (fit["status"], fit["iterations"], fit["chi2"], fit["dof"], b["sigma"], c["settings"],
       PRESET, len(b["points"]), b["all_settings"], b["all_fit"]["chi2"], b["all_fit"]["dof"]))
    ch = fit.get("chosen")
    if ch:
        w("Of the %d starts, %d ended within the margin of the lowest χ² (%.3g); the "
          "calibration is start %d's end (χ² %.3g), the one nearest liggghts-bed4's k_c "
          "and R." % (len(fit.get("starts") or []), ch["equal"], fit["chi2"], ch["start"],
                      ch["chi2"]))
    for warning in fit.get("warnings") or []:
        w("Fit warning (three points, the lowest χ²'s run): %s." % warning.rstrip("."))
    w("")
    w("    " + c["command"])
    w("")
    moves = ["%s %+.4f m/s: `%s`, worst %s" % (n, dv, st, pct(wst))
             for n, dv, st, wst, _ in c["moves"]]
    w("A calibration point moved by its seeds' sd, the bed calibrated again: %s." % "; ".join(moves))
    w("")
    w("| β (°) | sense | v_DEM (m/s) | v_column (m/s) | error, % of peak | | v_column, all points fitted | error |")
    w("|---|---|---|---|---|---|---|---|")
    for (r, v, err, is_calib), (_, va, erra, _) in zip(c["pred"], b["all_pred"]):
        name = next((n for n, x in c["calib"] if x is r), "")
        w("| %g | %s | %+.4f ± %.4f | %+.4f | %.1f | %s | %+.4f | %.1f |" %
          (beta(r), r["rotation"], float(r["v_dem"]), float(r["v_dem_sd"]), v,
           100 * err, "calibration: " + name if is_calib else "", va, 100 * erra))
    w("")


def page(beds, convsim, started):
    out = []
    w = out.append
    rows_build = sorted({r["build"][:12] for b in beds for r in b["points"]})
    done = [b for b in beds if "now" in b]
    w("# The column model against the DEM map")
    w("")
    w("`make bench-dem-calibrate` (tests/bench/dem_calibrate.py %s) on %s, column model "
      "build %s; the DEM rows from build %s (tests/bench/results/dem_map.csv, each point's "
      "value by the map report's rule: the map's cell, the softest modulus whose overlap "
      "stays within 1 %% of a diameter; counter-clockwise points are the mirror checks' "
      "rows). %.0f s, %s." % (shown([convsim]), time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                              git_build(), ", ".join(rows_build) or "-", time.time() - started,
                              machine()))
    w("")
    w("Each bed (material, depth, drive) whose clockwise sweep is complete is calibrated on "
      "three of its points, named below: the forward peak (largest v clockwise), the reverse "
      "peak (smallest v) and the next map angle past the reverse peak, where the reverse flow "
      "falls off. μ, the bed's friction on the deck, is the material's grain-on-deck friction "
      "(μ_pw in dem/materials.json); `convsim fit --data` fits k_c and R (from liggghts-bed4's "
      "values, %d starts): two parameters on three points. Three points leave k_c and R a valley or two "
      "near-equal minima, so the calibration is not simply the lowest χ²: of the starts whose "
      "χ² is within max(1, χ²/dof) of the lowest χ² (one unit once σ is scaled to make the lowest "
      "χ²/dof 1: the model's misfit, not the seeds' scatter, makes it large), it is the end nearest liggghts-bed4's "
      "k_c 2.56e4 N/m and R 0.177 in (log k_c, R), each over its search range. k_c is at least the depth × 1226 "
      "N/m: the bed's weight may press the column's contact at most a grain diameter (4 mm) "
      "into the deck; softer calibrations sank at angles they were not fitted at and diverged. "
      "The calibrated model then predicts "
      "every other point of the bed. The error is |v_column − v_DEM| in %% of the bed's peak "
      "|v_DEM|; worst and median are over the predicted points only. The column model runs "
      "one-way like the DEM bed (`%s`), so these errors are the `model_error` the engine "
      "reports at the points (tests/bench/model_presets.csv, `make model-check`)." %
      (FITSTARTS, " ".join(model_check.MEASURE)))
    w("")
    w("Stability: each calibration point in turn moved up and down by its seeds' standard "
      "deviation and the bed calibrated again (six fits); the column gives the largest change "
      "of the worst error (points of %) and the largest change of any predicted v (% of the "
      "peak). The last column fits k_c and R to all the bed's points: what the column model "
      "reaches when it may see every point (the lowest of its starts, not a proven optimum).")
    w("")
    w("| material | drive | depth (grains) | calibrated on | μ (fixed), k_c (N/m^p), R | points "
      "predicted | worst | median | within %.0f %% | stability: worst / v moves by | "
      "all points fitted: worst / median |" % (100 * GOOD))
    w("|---|---|---|---|---|---|---|---|---|---|---|")
    for b in beds:
        w(summary_line(b))
    w("")
    w("The calibration this replaces fitted k_c, R and μ to the two peaks and the angle between "
      "them (three parameters on three points). The same perturbations, both calibrations "
      "(worst error with the points as measured, its range over the six perturbed fits, "
      "and the stability column as above):")
    w("")
    w("| material | drive | depth (grains) | former: calibrated on | former: k_c, R, μ | worst "
      "| worst, perturbed | worst / v moves by | now: worst | worst, perturbed | worst / v moves by |")
    w("|---|---|---|---|---|---|---|---|---|---|---|")
    for b in done:
        w(former_line(b))
    w("")
    for b in done:
        detail(b, w)
    return "\n".join(out) + "\n"


def write_presets(beds):
    path = model_check.PRESETS
    head = [line for line in open(path) if line.startswith("#")] if os.path.exists(path) else []
    with open(path + ".new", "w") as fh:
        fh.writelines(head)
        wr = csv.writer(fh, lineterminator="\n")
        wr.writerow(["material", "layers", "drive", "preset", "settings"])
        for b in beds:
            if "now" in b:
                wr.writerow([b["material"], b["layers"], b["drive"], PRESET, b["now"]["settings"]])
    os.replace(path + ".new", path)


def main():
    convsim = sys.argv[1] if len(sys.argv) > 1 else "build/convsim"
    started = time.time()
    rows = dem_map.read_rows()
    mats = dem_map.materials()
    beds = []
    for material, layers, drive in dem_points.beds(rows):
        print("dem_calibrate: %s, %d grains deep, drive %s" % (material, layers, drive),
              file=sys.stderr)
        beds.append(calibrate(convsim, rows, material, layers, drive, mats))
    text = page(beds, convsim, started)
    with open(PAGE + ".new", "w") as fh:
        fh.write(text)
    os.replace(PAGE + ".new", PAGE)
    write_presets(beds)
    print(text)


if __name__ == "__main__":
    main()
