#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How much the DEM map moves with the inputs it assumes (`make
bench-dem-inputs`, docs/dem.md "What is not done").

    dem_inputs.py run BINARY BUILD [MATERIAL]   the missing rows, resumable
    dem_inputs.py report              tests/bench/results/dem_inputs.md
    dem_inputs.py --check             each row is the plan's, the report what they give

dem/materials.json names the contact values no measurement gives: glass on
the steel deck (e_pw, mu_pw) and the beads' rolling friction (roll_pp,
roll_pw); wheat's restitutions, grain-on-grain and rolling friction. Each
is changed here, one at a time, towards the far end of what is plausible,
at map points whose value is the map's own stiffness (so that the change is
the input's alone); each row is three seeds of the map's run with
that one value changed, by the map's build (its rows and this file's must
name one build). The report sets each beside its map point: the change in %
of the bed's peak and in units of the two rows' standard error.
"""
import contextlib
import io
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dem_map  # noqa: E402
import provenance  # noqa: E402
from dem_map_report import peak_of, seeds_apart  # noqa: E402  (the map report's measures)
from dem_points import chosen  # noqa: E402

RESULTS = os.path.join(dem_map.ROOT, "tests/bench/results")
CSV = os.path.join(RESULTS, "dem_inputs.csv")
RUNS = os.path.join(RESULTS, "dem_inputs_runs.jsonl")
# per material, (what changes, {material value: the changed value}); the
# map's values in dem/materials.json: glass's rolling friction 0.005 and
# deck contact (e 0.9, mu 0.15) are assumed; wheat's restitutions (0.5),
# grain-on-grain friction (0.5) and rolling friction (0.05, "if anything
# low") are
VARIANTS = {
    "glass": [("rolling friction 0.05", {"roll_pp": 0.05, "roll_pw": 0.05}),
              ("rolling friction 0.3", {"roll_pp": 0.3, "roll_pw": 0.3}),
              ("friction on the deck 0.3", {"mu_pw": 0.3}),
              ("restitution on the deck 0.7", {"e_pw": 0.7})],
    "wheat": [("rolling friction 0.2", {"roll_pp": 0.2, "roll_pw": 0.2}),
              ("restitution 0.3", {"e_pp": 0.3, "e_pw": 0.3}),
              ("friction between grains 0.3", {"mu_pp": 0.3})],
}
# at the preset's drive, each at the map's stiffness (so that the change is
# the input's alone): glass one grain deep at the low throw, the forward and
# the reverse peak and the lowest throw past it, and four deep at the low
# throw; wheat two deep (grain on grain) at its two peaks
POINTS = [("glass", 1, "preset", 15), ("glass", 1, "preset", 30), ("glass", 1, "preset", 150),
          ("glass", 4, "preset", 15), ("wheat", 2, "preset", 30), ("wheat", 2, "preset", 135),
          ("glass", 1, "preset", 165)]
COLUMNS = ["input"] + dem_map.COLUMNS


def changed(mats, material, values):
    """mats with the material's values replaced."""
    m = json.loads(json.dumps(mats))
    m["materials"][material].update(values)
    return m


def plan(mats):
    out = []
    for material, layers, drive, beta in POINTS:
        for name, values in VARIANTS[material]:
            p = dem_map.point("inputs", "input", material, layers, drive, beta,
                              youngs=mats["map"]["youngs_map"])
            out.append((name, p, changed(mats, material, values)))
    return out


def row_key(name, p):
    return "%s|%s|%d|%s|%g" % (name, p["material"], p["layers"], p["drive"], p["beta"])


def read_rows():
    return dem_map.read_rows(CSV)


def key_of(r):
    """row_key of a row of the CSV."""
    return row_key(r["input"], {"material": r["material"], "layers": int(r["layers"]),
                                "drive": r["drive"], "beta": float(r["beta_deg"])})


def run(binary, build, only=None):
    """The plan's missing rows (of the material `only`, where given: two
    runners may share the files, one a material)."""
    mats = dem_map.materials()
    builds = {r["build"] for r in dem_map.read_rows()}
    if builds != {build}:
        sys.exit("dem_inputs: the map's rows come from build %s; run that build" % ",".join(sorted(builds)))
    dem_map.repair(CSV)
    dem_map.repair(RUNS)
    if not os.path.exists(CSV) or os.path.getsize(CSV) == 0:
        dem_map.append(CSV, dem_map.csv_line(COLUMNS))
    done = {key_of(r) for r in read_rows()}
    seeds = dem_map.finished_seeds(build, RUNS, "row")
    for name, p, m in plan(mats):
        k = row_key(name, p)
        if k in done or (only and p["material"] != only):
            continue
        have = seeds.setdefault(k, {})
        for s in dem_map.SEEDS:
            if s in have:
                continue
            rec = dem_map.run_seed(binary, build, p, m, s)
            rec["row"] = k
            dem_map.append(RUNS, json.dumps(rec, sort_keys=True) + "\n")
            have[s] = rec
            print("dem-inputs: %s, %s %d grains %s beta %g seed %d: v %.5f m/s, %.0f CPU s" %
                  (name, p["material"], p["layers"], p["drive"], p["beta"], s, rec["out"]["v_dem"],
                   rec["cpu_s"]), flush=True)
        dem_map.append(CSV, dem_map.csv_line([name] + dem_map.row_of(p, m, build, have)))


def report():
    mats = dem_map.materials()
    rows, maprows = read_rows(), dem_map.read_rows()
    w = print
    w("# The DEM map against the inputs it assumes")
    w("")
    w("`make bench-dem-inputs` (tests/bench/dem_inputs.py), report of %s. Build: %s. Rows run "
      "at nice 19 on %s, beside the map's runs. Data: "
      "tests/bench/results/dem_inputs.csv (the command of each row in its `command` column). Each row "
      "is a map point run again, three seeds, with one assumed value of dem/materials.json "
      "changed; the change is v_changed - v_map in %% of the bed's peak (its largest |v| on the "
      "map), and in units of the two rows' combined standard error (each row's seeds' standard "
      "deviation over the root of 3)." %
      (time.strftime("%Y-%m-%d", time.gmtime()), ", ".join(sorted({"`%s`" % r["build"][:12] for r in rows}))
       or "none yet", provenance.cores()))
    w("")
    w("| material | depth (grains) | drive | beta cw | changed | v map (m/s) | v changed (m/s) | "
      "change, % of the peak | seeds apart | CPU s |")
    w("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        layers, beta = int(r["layers"]), float(r["beta_deg"])
        m = chosen(maprows, r["material"], layers, r["drive"], beta, "cw", mats)
        if not m:
            continue
        peak = peak_of(maprows, m, mats)
        a, b = float(r["v_dem"]), float(m["v_dem"])
        w("| %s | %d | %s | %g | %s | %+.4f ± %.4f | %+.4f ± %.4f | %+.1f %% | %.1f | %s |" %
          (r["material"], layers, r["drive"], beta, r["input"], b, float(m["v_dem_sd"]), a,
           float(r["v_dem_sd"]), 100 * (a - b) / peak, seeds_apart(r, m),
           r["cpu_s"]))
    w("")
    if rows:
        w("Rows: %d; CPU: %.2f h." % (len(rows), sum(float(r["cpu_s"]) for r in rows) / 3600))


def check():
    """make test: each row is the plan's (its point, and its command the map's
    run with the row's one value changed), and the committed report's table
    is what the rows give; prints node:test's summary."""
    mats = dem_map.materials()
    want = {row_key(n, p): (p, m) for n, p, m in plan(mats)}
    fails = []
    for r in read_rows():
        k = key_of(r)
        if k not in want:
            fails.append("row %s is not in the plan" % k)
            continue
        cmd = dem_map.command_of(*want[k])
        if r["command"] != cmd:
            fails.append("row %s: command %s, the plan's %s" % (k, r["command"], cmd))
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        report()
    table = [ln for ln in buf.getvalue().splitlines() if ln.startswith("|")]
    have = os.path.join(RESULTS, "dem_inputs.md")
    if [ln for ln in open(have).read().splitlines() if ln.startswith("|")] != table:
        fails.append("%s is not what dem_inputs.csv gives: run dem_inputs.py report" % have)
    for f in fails:
        print("not ok:", f)
    print("# pass %d\n# fail %d" % (0 if fails else 1, len(fails)))
    return 1 if fails else 0


def main():
    if sys.argv[1:2] == ["--check"]:
        sys.exit(check())
    if len(sys.argv) >= 4 and sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3], sys.argv[4] if len(sys.argv) > 4 else None)
        return
    if len(sys.argv) >= 2 and sys.argv[1] == "report":
        report()
        return
    sys.exit(__doc__)


if __name__ == "__main__":
    main()
