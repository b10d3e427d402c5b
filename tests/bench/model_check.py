#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The DEM map's points with the column model's v beside them: the data of
every number's `model_error` (docs/dem.md "Model error").

Writes tests/bench/results/model_check.csv, one row per DEM point that has a
calibrated column model, which the build compiles into the core
(core/model_check.c includes the table the Makefile generates from it):

  preset,settings,material,layers,drive,beta_deg,rotation,v_dem,v_dem_sd,
  seeds,v_column,source,model

model is the column model as the notes name it: "liggghts-bed4",
"czubak2016 against glass", "czubak2016 at e = 0.03225 against glass",
"czubak2016 calibrated to glass", "czubak2016 at e = 0.03225 calibrated to glass".

Sources, in this order:
  1. the 4-diameter bed's curve at the preset's contacts (dem.jsonl, group
     "curve": 11 angles, both senses, three packing seeds each), the data
     the preset liggghts-bed4 was fitted to;
  2. every point of the map against the preset czubak2016 as it is
     (settings empty, or the drive's changes for the map's other drives,
     e.g. e=0.03225; layers = the depth): the default model's distance from
     each material's bed, so that a default session is checked at every
     depth the map has (before 3, so that a scene near no entry is named
     after the preset, not a calibration);
  3. every point of the DEM map (tests/bench/results/dem_map.csv), its
     value taken from its rows by the map report's rule (dem_points.py:
     the map's cell, the softest modulus within the overlap bound; the
     mirror rows counter-clockwise), whose material, depth and drive have
     a calibrated column model in tests/bench/model_presets.csv
     (material,layers,drive,preset,settings; an empty layers is every
     depth; tests/bench/dem_calibrate.py writes the lines).
A map bed without a calibrated line is left out of 3 and named on stderr.

v_column is the column model's v at the point: `convsim run -p PRESET
[--set SETTING]... --set layers=L --set beta=B --set rotation=R --set
feed_coupling=false -d 2 --set transient=0.5` (one-way, as the DEM bed is
driven: 2 s from the steady start, v over the whole periods after 0.5 s).
settings is PRESET's changes, `name=value;...` in user units; empty for the
preset itself.

Usage: tests/bench/model_check.py [CONVSIM] > tests/bench/results/model_check.csv
(CONVSIM defaults to build/convsim; `make model-check` runs it)."""
import csv
import json
import math
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dem_map  # noqa: E402  (the map's materials)
import dem_points  # noqa: E402  (which row is a point's value)

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
PRESETS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "model_presets.csv")
# the column model's measure at a point: one-way, as the DEM bed is driven
MEASURE = ["-d", "2", "--set", "transient=0.5"]
COLUMNS = ["preset", "settings", "material", "layers", "drive", "beta_deg", "rotation",
           "v_dem", "v_dem_sd", "seeds", "v_column", "source", "model"]


def bed4_points():
    """The 4-diameter bed's curve, seeds pooled: mean and sample sd."""
    curve = {}
    for line in open(os.path.join(RESULTS, "dem.jsonl")):
        if line.strip():
            r = json.loads(line)
            if r["group"] == "curve" and r["layers"] == 4 and r["k_over_m"] == 2e6:
                curve.setdefault((round(r["beta"]), r["rotation"]), []).append(r["v_dem"])
    for (beta, rot), v in sorted(curve.items(), key=lambda kv: (kv[0][1] != "cw", kv[0][0])):
        yield {"preset": "liggghts-bed4", "settings": "", "material": "preset-contacts",
               "model": "liggghts-bed4",
               "layers": 4, "drive": "preset", "beta_deg": beta, "rotation": rot,
               "v_dem": statistics.fmean(v),
               "v_dem_sd": statistics.stdev(v) if len(v) > 1 else float("nan"),
               "seeds": len(v), "source": "dem.jsonl curve"}


def read_presets(path=PRESETS):
    """tests/bench/model_presets.csv: (material, layers, drive) -> (preset,
    settings); an empty layers is every depth of that material and drive."""
    presets = {}
    if os.path.exists(path):
        for r in csv.DictReader(line for line in open(path) if not line.startswith("#")):
            layers = int(r["layers"]) if r.get("layers") else None
            presets[(r["material"], layers, r["drive"])] = (r["preset"], r["settings"])
    return presets


def map_rows():
    """The DEM map's rows and its materials (none without a map)."""
    path = os.path.join(RESULTS, "dem_map.csv")
    if not os.path.exists(path):
        return [], {}
    return dem_map.read_rows(path), dem_map.materials()


def bed_points(rows, mats, bed, preset, settings, model):
    """The points of one map bed (material, layers, drive), each value
    taken by the map's rule (dem_points.py), against the column model
    PRESET with SETTINGS that the notes call MODEL."""
    material, layers, drive = bed
    for r in dem_points.points(rows, material, layers, drive, mats):
        sd = float(r["v_dem_sd"]) if r["v_dem_sd"] not in ("", "nan") else float("nan")
        yield {"preset": preset, "settings": settings, "material": material,
               "model": model, "layers": layers, "drive": drive,
               "beta_deg": float(r["beta_deg"]), "rotation": r["rotation"],
               "v_dem": float(r["v_dem"]), "v_dem_sd": sd, "seeds": int(r["seeds"]),
               "source": "dem_map.csv " + r.get("build", "")}


def map_points(rows, mats):
    """The DEM map's points that have a calibrated column model."""
    presets = read_presets()
    for bed in dem_points.beds(rows):
        material, layers, drive = bed
        found = presets.get(bed) or presets.get((material, None, drive))
        if not found:
            print(f"model_check.py: no calibrated column model for material {material}, "
                  f"{layers} grains deep, drive {drive} (tests/bench/model_presets.csv): "
                  "its points left out", file=sys.stderr)
            continue
        preset, settings = found
        at = drive_settings(drive)[1]
        yield from bed_points(rows, mats, bed, preset, settings,
                              f"{preset}{at} calibrated to {material}")


# the default preset, whose machine is the map's drive "preset"
DEFAULT = "czubak2016"


def drive_settings(drive):
    """A map drive's changes to the preset, "name=value;...", and how a
    user knows the model there ("" and "" for the preset's own drive)."""
    args = dem_map.DRIVES[drive]
    sets = [args[i + 1] for i in range(0, len(args), 2) if args[i] == "--set"]
    where = ", ".join(s.replace("=", " = ") for s in sets)
    return ";".join(sets), (f" at {where}" if where else "")


def default_points(rows, mats):
    """Every map point against the default preset as it is (with the drive's
    changes for a drive other than its own): one entry per material, depth
    and drive."""
    for bed in dem_points.beds(rows):
        settings, at = drive_settings(bed[2])
        yield from bed_points(rows, mats, bed, DEFAULT, settings, f"{DEFAULT}{at} against {bed[0]}")


def v_column(convsim, p):
    args = [convsim, "run", "-p", p["preset"]]
    for s in filter(None, p["settings"].split(";")):
        args += ["--set", s]
    args += ["--set", f"layers={p['layers']}", "--set", f"beta={p['beta_deg']:g}",
             "--set", f"rotation={p['rotation']}", "--set", "feed_coupling=false",
             "-q"] + MEASURE
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return json.loads(out)["transport_velocity"]


def num(x, digits):
    return "nan" if isinstance(x, float) and math.isnan(x) else f"{x:.{digits}g}"


def main():
    convsim = sys.argv[1] if len(sys.argv) > 1 else "build/convsim"
    w = csv.writer(sys.stdout, lineterminator="\n")
    w.writerow(COLUMNS)
    rows, mats = map_rows()
    for p in list(bed4_points()) + list(default_points(rows, mats)) + list(map_points(rows, mats)):
        p["v_column"] = v_column(convsim, p)
        w.writerow([p["preset"], p["settings"], p["material"], p["layers"], p["drive"],
                    num(float(p["beta_deg"]), 6), p["rotation"], num(p["v_dem"], 6),
                    num(p["v_dem_sd"], 3), p["seeds"], num(p["v_column"], 6), p["source"],
                    p["model"]])


if __name__ == "__main__":
    main()
