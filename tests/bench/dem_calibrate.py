#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The column model against the DEM map, as a user would use it: for each
material, depth and drive of tests/bench/results/dem_map.csv, calibrate the
column model on three of the map's points with `convsim fit --data`, predict
the bed's other points with the calibrated model, and tabulate the error.

    dem_calibrate.py [CONVSIM]     (`make bench-dem-calibrate`)

Writes tests/bench/results/dem_calibration.md (the page) and
tests/bench/model_presets.csv (one line per calibrated bed, which `make
model-check` turns into the model_error table). Each point's value is taken
by the map report's rule (dem_points.py).

The three calibration points of a bed, from its clockwise points: the
forward peak (largest v), the reverse peak (smallest v), and mid-branch the
map angle between them nearest their middle (the lower of two). A bed is
calibrated once its clockwise sweep is complete (every angle of
dem_map.BETAS). The free parameters are the column model's contact, k_c, R
and mu (as for the preset liggghts-bed4), started at liggghts-bed4's values,
FITSTARTS starts; every datum's sigma is the root mean square of the bed's
seed spreads. The model is run one-way, as the DEM bed is driven, with
model_check.py's measure (model_check.MEASURE), so the table's errors are
the model_error the engine reports at the points.
"""
import csv
import json
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
FREE = "k_c:100:1e8,R:0.01:0.6,mu:0.1:1.5"  # k_c from its least; above 1e8 the steps cost
FITSTARTS = 8
GOOD = 0.05                   # "within 5 % of the peak"



machine = provenance.machine


def git_build():
    """The commit of this tree, and whether it differs from it."""
    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                          cwd=HERE).stdout.strip()
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "core", "cli", "fit"],
                           cwd=HERE).returncode != 0
    return head[:12] + (" (with uncommitted changes to core/, cli/ or fit/)" if dirty else "")


def calibration_points(cw):
    """The forward peak, the reverse peak and the mid-branch point of a
    bed's clockwise points (rows), as (name, row)."""
    fwd = max(cw, key=lambda r: float(r["v_dem"]))
    rev = min(cw, key=lambda r: float(r["v_dem"]))
    bf, br = float(fwd["beta_deg"]), float(rev["beta_deg"])
    mid = 0.5 * (bf + br)
    between = [r for r in cw if min(bf, br) < float(r["beta_deg"]) < max(bf, br)]
    pick = [("forward peak", fwd), ("reverse peak", rev)]
    if between:
        pick.append(("mid-branch", min(between, key=lambda r: (abs(float(r["beta_deg"]) - mid),
                                                                float(r["beta_deg"])))))
    return pick


def fit_command(convsim, data, layers, drive, out):
    args = [convsim, "fit", "-p", START, "--data", data, "--free", FREE,
            "--set", "layers=%d" % layers, "--set", "feed_coupling=false"]
    args += dem_map.DRIVES[drive]
    args += model_check.MEASURE + ["--starts", str(FITSTARTS), "--threads", "2",
                                   "--curve-step", "0", "-q", "-o", out]
    return args


def shown(args):
    return " ".join(os.path.relpath(a) if os.path.isabs(a) else a for a in args)


def fit(convsim, data_rows, sigma, layers, drive):
    """`convsim fit` on data_rows: (its result, the command as shown, the
    calibrated model's settings)."""
    with tempfile.TemporaryDirectory() as tmp:
        data, out = os.path.join(tmp, "points.csv"), os.path.join(tmp, "fit.json")
        with open(data, "w") as fh:
            fh.write("beta,rotation,v,sigma\n")
            for r in data_rows:
                fh.write("%s,%s,%s,%.6g\n" % (r["beta_deg"], r["rotation"], r["v_dem"], sigma))
        args = fit_command(convsim, data, layers, drive, out)
        subprocess.run(args, check=True)
        result = json.load(open(out))
    args = [{data: "POINTS.csv", out: "fit.json"}.get(a, a) for a in args]
    drive_sets = [a for a in dem_map.DRIVES[drive] if a != "--set"]
    settings = ";".join(drive_sets + ["%s=%.6g" % (p["name"], p["value"])
                                      for p in result["parameters"]])
    return result, shown(args), settings


def predict(convsim, pts, settings, layers, peak, calib_rows=()):
    """[(row, v_column, |v_column - v_DEM| / peak, calibration point?)]."""
    out = []
    for r in pts:
        p = {"preset": PRESET, "settings": settings, "layers": layers,
             "beta_deg": float(r["beta_deg"]), "rotation": r["rotation"]}
        v = model_check.v_column(convsim, p)
        out.append((r, v, abs(v - float(r["v_dem"])) / peak, any(r is c for c in calib_rows)))
    return out


def calibrate(convsim, rows, material, layers, drive, mats):
    """One bed: the fit on three points and its predictions, and the fit on
    all the bed's points (the column model's best over the bed); 'why'
    where it cannot be calibrated yet."""
    pts = dem_points.points(rows, material, layers, drive, mats)
    cw = [r for r in pts if r["rotation"] == "cw"]
    bed = {"material": material, "layers": layers, "drive": drive, "points": pts}
    have = {float(r["beta_deg"]) for r in cw}
    if not all(float(b) in have for b in dem_map.BETAS):
        bed["why"] = "%d of the %d clockwise angles measured so far" % (len(have), len(dem_map.BETAS))
        return bed
    calib = calibration_points(cw)
    sigma = statistics.fmean(float(r["v_dem_sd"]) ** 2 for r in cw) ** 0.5
    peak = max(abs(float(r["v_dem"])) for r in pts)
    bed.update(calib=calib, sigma=sigma, peak=peak)
    bed["fit"], bed["command"], bed["settings"] = fit(convsim, [r for _, r in calib], sigma,
                                                      layers, drive)
    bed["pred"] = predict(convsim, pts, bed["settings"], layers, peak, [r for _, r in calib])
    bed["all_fit"], _, bed["all_settings"] = fit(convsim, pts, sigma, layers, drive)
    bed["all_pred"] = predict(convsim, pts, bed["all_settings"], layers, peak)
    return bed


def stats(pred):
    """(worst entry, median error, how many within GOOD) over pred."""
    worst = max(pred, key=lambda x: x[2])
    return worst, statistics.median(x[2] for x in pred), sum(1 for x in pred if x[2] <= GOOD)


def summary_line(b):
    if "why" in b:
        return "| %s | %s | %d | not calibrated: %s | | | | | | |" % (
            b["material"], b["drive"], b["layers"], b["why"])
    calib = ", ".join("%s %g° cw" % (n, float(r["beta_deg"])) for n, r in b["calib"])
    pars = ", ".join("%s %.3g" % (p["name"], p["value"]) for p in b["fit"]["parameters"])
    rest = [x for x in b["pred"] if not x[3]]
    worst, med, good = stats(rest)
    aw, am, _ = stats(b["all_pred"])
    return "| %s | %s | %d | %s | %s | %d | %.1f %% (%g° %s) | %.1f %% | %d of %d | %.1f %% / %.1f %% |" % (
        b["material"], b["drive"], b["layers"], calib, pars, len(rest), 100 * worst[2],
        float(worst[0]["beta_deg"]), worst[0]["rotation"], 100 * med, good, len(rest),
        100 * aw[2], 100 * am)


def detail(b, w):
    w("### %s, %d grains deep, drive `%s`" % (b["material"], b["layers"], b["drive"]))
    w("")
    fit = b["fit"]
    w("Fit on the three points: %s after %d iterations, χ² %.3g on %d degrees of freedom, "
      "σ %.4f m/s; settings `%s` on the preset %s (the line of tests/bench/model_presets.csv). "
      "On all %d points: `%s`, χ² %.3g on %d degrees of freedom." %
      (fit["status"], fit["iterations"], fit["chi2"], fit["dof"], b["sigma"], b["settings"],
       PRESET, len(b["points"]), b["all_settings"], b["all_fit"]["chi2"], b["all_fit"]["dof"]))
    for warning in fit.get("warnings") or []:
        w("Fit warning (three points): %s." % warning.rstrip("."))
    w("")
    w("    " + b["command"])
    w("")
    w("| β (°) | sense | v_DEM (m/s) | v_column (m/s) | error, % of peak | | v_column, all points fitted | error |")
    w("|---|---|---|---|---|---|---|---|")
    for (r, v, err, is_calib), (_, va, erra, _) in zip(b["pred"], b["all_pred"]):
        name = next((n for n, c in b["calib"] if c is r), "")
        w("| %g | %s | %+.4f ± %.4f | %+.4f | %.1f | %s | %+.4f | %.1f |" %
          (float(r["beta_deg"]), r["rotation"], float(r["v_dem"]), float(r["v_dem_sd"]), v,
           100 * err, "calibration: " + name if is_calib else "", va, 100 * erra))
    w("")


def page(beds, convsim, started):
    out = []
    w = out.append
    rows_build = sorted({r["build"][:12] for b in beds for r in b["points"]})
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
    w("Each bed (material, depth, drive) is calibrated on three of its points, named below: "
      "the forward peak (largest v clockwise), the reverse peak (smallest v) and the map "
      "angle between them nearest their middle. `convsim fit --data` fits the column "
      "model's contact (k_c, R, μ; from liggghts-bed4's values, %d starts) to them; the "
      "calibrated model then predicts every other point of the bed. The error is "
      "|v_column − v_DEM| in %% of the bed's peak |v_DEM|; worst and median are over the "
      "predicted points only (not the three it was fitted to). The column model runs "
      "one-way like the DEM bed (`%s`), so these errors are the `model_error` the engine "
      "reports at the points (tests/bench/model_presets.csv, `make model-check`)." %
      (FITSTARTS, " ".join(model_check.MEASURE)))
    w("")
    w("The last column fits the same three parameters to all the bed's points (the same "
      "command with every point as data) and gives the error over all of them, the fitted "
      "points included: what the column model reaches on that bed when it may see every "
      "point (the lowest of its starts, not a proven optimum), so what of the three-point "
      "error is the choice of points and what the model's.")
    w("")
    w("| material | drive | depth (grains) | calibrated on | k_c (N/m^p), R, μ | points "
      "predicted | worst | median | within %.0f %% | all points fitted: worst / median |" %
      (100 * GOOD))
    w("|---|---|---|---|---|---|---|---|---|---|")
    for b in beds:
        w(summary_line(b))
    w("")
    for b in beds:
        if "fit" in b:
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
            if "settings" in b:
                wr.writerow([b["material"], b["layers"], b["drive"], PRESET, b["settings"]])
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
