#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The DEM reference map (`make bench-dem-map`, docs/dem.md "The map").

    dem_map.py run BIN BUILD [PART ...]   run the parts' missing rows
    dem_map.py plan [PART ...]            list the planned rows, by part
    dem_map.py --self-test                (make test) the runner with a stand-in
                                          for convsim-dem, three seeds at once

Every row is one map point: a named material (dem/materials.json), a
depth in grains, a drive, beta and the sense of rotation, measured with
convsim-dem on the deck orbit that the one-way machine computes for that
scene, over three packing seeds. A row is appended to the CSV whole, in
one write, when its last seed ends; each seed's JSON line goes to the
runs file as it ends, so that a row cut short resumes from its finished
seeds. Rows already in the CSV are skipped. DEM_MAP_JOBS (default 1)
LIGGGHTS processes at a time, a point's seeds side by side, at nice 19;
each seed's CPU is its own process's.
"""
import concurrent.futures
import csv
import fcntl
import io
import json
import math
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# DEM_MAP_CSV, DEM_MAP_RUNS: other files (the runner's own check)
CSV = os.environ.get("DEM_MAP_CSV") or os.path.join(ROOT, "tests/bench/results/dem_map.csv")
RUNS = os.environ.get("DEM_MAP_RUNS") or os.path.join(ROOT, "tests/bench/results/dem_map_runs.jsonl")
MATERIALS = os.path.join(ROOT, "dem/materials.json")

# the schema model_error reads: these columns first, in this order
COLUMNS = ["material", "layers", "drive", "beta_deg", "rotation", "v_dem", "v_dem_sd", "seeds",
           "window_s", "v_first_half", "v_second_half", "overlap_max_rel", "e_scale",
           "cell_width_d", "grains", "cpu_s", "build", "command",
           # and after them
           "role", "part", "youngs_pa", "overlap_pp_rel", "overlap_pw_rel", "v_seeds",
           "half_drift", "deck_amplitude_m", "dem_dt_s", "date"]

SEEDS = (1, 2, 3)
DURATION, TRANSIENT = 3.0, 1.0  # s: the window is the last 2 s, 50 periods at 25 Hz
CELL_X = 20                      # mean diameters along the deck
WIDTH = 4                        # mean diameters across the deck (the map's cell)
BETAS = list(range(0, 181, 15))
# the drives: `preset` is czubak2016's machine; `a150` its unbalance's
# eccentricity e times 1.5 (the deck's amplitude about 1.5 times)
DRIVES = {"preset": [], "a150": ["--set", "e=0.03225"]}


def materials():
    with open(MATERIALS) as f:
        return json.load(f)


def point(part, role, material, layers, drive, beta, rotation="cw", youngs=None, width=WIDTH):
    return {"part": part, "role": role, "material": material, "layers": layers, "drive": drive,
            "beta": beta, "rotation": rotation, "youngs": youngs, "width": width}


def plan():
    """The parts in the order they run: the most useful rows first."""
    mats = materials()
    e_map = mats["map"]["youngs_map"]
    lo, _, hi = mats["map"]["youngs_ladder"]
    parts = []

    def sweep(name, material, layers, drive):
        return (name, [point(name, "map", material, n, drive, b, youngs=e_map)
                       for n in layers for b in BETAS])

    def checks(name, material, stiff, stiff_lo, cell, mirror):
        rows = []
        for n, b in stiff:
            rows.append(point(name, "stiffness", material, n, "preset", b, youngs=hi))
        for n, b in stiff_lo:
            rows.append(point(name, "stiffness", material, n, "preset", b, youngs=lo))
        for n, b in cell:
            rows.append(point(name, "cell", material, n, "preset", b, youngs=e_map, width=2 * WIDTH))
        for n, b in mirror:
            rows.append(point(name, "mirror", material, n, "preset", b, rotation="ccw", youngs=e_map))
        return (name, rows)

    # glass at the preset's drive first, one grain deep, then the checks
    # that validate the map's stiffness and cell on it, before the deeper
    # rows that cost more; a part may come in pieces (DEM_MAP_PARTS runs
    # all of a part's pieces)
    parts.append(sweep("glass-shallow", "glass", [1], "preset"))
    parts.append(checks("glass-checks", "glass", [(1, 30), (1, 150)], [(1, 30)], [(1, 30)], [(1, 150)]))
    parts.append(sweep("glass-shallow", "glass", [2, 4], "preset"))
    parts.append(checks("glass-checks", "glass", [(2, 30), (2, 150), (4, 30), (4, 150)],
                        [(2, 30)], [(2, 30), (4, 30)], [(2, 150)]))
    parts.append(sweep("glass-deep", "glass", [8, 16], "preset"))
    parts.append(checks("glass-deep-checks", "glass", [(8, 30), (16, 30)], [], [(8, 30), (16, 30)], []))
    parts.append(sweep("wheat-shallow", "wheat", [1, 2, 4], "preset"))
    parts.append(checks("wheat-checks", "wheat", [(2, 30), (2, 150), (4, 30)], [], [(2, 30), (4, 30)],
                        [(2, 150)]))
    parts.append(sweep("wheat-deep", "wheat", [8, 16], "preset"))
    parts.append(sweep("glass-a150", "glass", [1, 2, 4, 8, 16], "a150"))
    parts.append(sweep("wheat-a150", "wheat", [1, 2, 4, 8, 16], "a150"))
    return parts


def key(material, layers, drive, beta, rotation, e_scale, width):
    return "%s|%d|%s|%g|%s|%.6g|%g" % (material, int(layers), drive, float(beta), rotation,
                                       float(e_scale), float(width))


def point_key(p, mats):
    return key(p["material"], p["layers"], p["drive"], p["beta"], p["rotation"],
               p["youngs"] / mats["materials"][p["material"]]["youngs_real"], p["width"])


def args_of(p, mats, seed):
    m = mats["materials"][p["material"]]
    a = ["--no-column", "--duration", "%g" % DURATION, "--transient", "%g" % TRANSIENT,
         "--intervals", "0", "--depth", "%g" % p["layers"], "--set", "beta=%g" % p["beta"],
         "--set", "rotation=%s" % p["rotation"]] + DRIVES[p["drive"]]
    a += ["--d-min", "%g" % m["d_min"], "--d-max", "%g" % m["d_max"], "--density", "%g" % m["density"],
          "--hertz", "%g:%g" % (p["youngs"], m["poisson"]),
          "--pair", "%g:%g:%g" % (m["e_pp"], m["mu_pp"], m["roll_pp"]),
          "--wall", "%g:%g:%g" % (m["e_pw"], m["mu_pw"], m["roll_pw"]),
          "--cell", "%g" % CELL_X, "--width", "%g" % p["width"], "--seed", str(seed)]
    return a


def read_rows(path=CSV):
    """The CSV's whole rows (a line cut short by a kill is not one)."""
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [r for r in rows if r.get("date") not in (None, "")]


def repair(path):
    """Drop a last line cut short (no newline at the end), so that the
    next append starts a line."""
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return
    with open(path, "rb+") as f:
        data = f.read()
        if data.endswith(b"\n"):
            return
        f.truncate(data.rfind(b"\n") + 1)


def append(path, text):
    """One write of whole lines, O_APPEND: a row is in the file whole or not at all."""
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        os.write(fd, text.encode())
    finally:
        os.close(fd)


def csv_line(values):
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(values)
    return buf.getvalue()


def finished_seeds(build, path=None, field="key"):
    """The runs file's seeds of this build: {point key (the record's
    `field`): {seed: record}}; path: the map's runs file unless another."""
    out = {}
    path = path or RUNS
    if not os.path.exists(path):
        return out
    with open(path) as f:
        for line in f:
            try:
                r = json.loads(line)
            except ValueError:
                continue
            if r.get("build") == build:
                out.setdefault(r[field], {})[r["seed"]] = r
    return out


def run_seed(binary, build, p, mats, seed):
    """One seed's run; its CPU is that process's own (wait4), whatever runs beside it."""
    a = args_of(p, mats, seed)
    t0 = time.time()
    with tempfile.TemporaryFile("w+") as fo, tempfile.TemporaryFile("w+") as fe:
        proc = subprocess.Popen(["nice", "-n", "19", binary] + a, stdout=fo, stderr=fe, text=True)
        _, status, ru = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        fo.seek(0)
        fe.seek(0)
        stdout, stderr = fo.read(), fe.read()
    cpu = ru.ru_utime + ru.ru_stime
    if proc.returncode != 0:
        raise RuntimeError("convsim-dem %s: exit %d: %s" % (" ".join(a), proc.returncode,
                                                             stderr.strip()[-400:]))
    out = json.loads(stdout)
    return {"key": point_key(p, mats), "seed": seed, "build": build, "cpu_s": cpu,
            "wall_s": time.time() - t0, "args": " ".join(a), "out": out}


def mean(xs):
    return sum(xs) / len(xs)


def sd(xs):
    if len(xs) < 2:
        return float("nan")
    m = mean(xs)
    return math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1))


def command_of(p, mats):
    """The row's `command`: the point's run with its seeds as S."""
    return "convsim-dem " + " ".join(args_of(p, mats, "S")) + " (S = %s)" % " ".join(map(str, SEEDS))


def row_of(p, mats, build, seeds):
    m = mats["materials"][p["material"]]
    outs = [seeds[s]["out"] for s in SEEDS]
    d = outs[0]["d_mean"]
    v = [o["v_dem"] for o in outs]
    h1 = [o["v_first_half"] for o in outs]
    h2 = [o["v_second_half"] for o in outs]
    ovpp = max(o["overlap_pp_max"] for o in outs) / d
    ovpw = max(o["overlap_pw_max"] for o in outs) / d
    values = {
        "material": p["material"], "layers": p["layers"], "drive": p["drive"],
        "beta_deg": p["beta"], "rotation": p["rotation"],
        "v_dem": "%.6g" % mean(v), "v_dem_sd": "%.3g" % sd(v), "seeds": len(v),
        "window_s": "%g" % (DURATION - TRANSIENT),
        "v_first_half": "%.6g" % mean(h1), "v_second_half": "%.6g" % mean(h2),
        "overlap_max_rel": "%.4g" % max(ovpp, ovpw),
        "e_scale": "%.6g" % (p["youngs"] / m["youngs_real"]), "cell_width_d": "%g" % p["width"],
        "grains": outs[0]["grains"], "cpu_s": "%.1f" % sum(seeds[s]["cpu_s"] for s in SEEDS),
        "build": build, "command": command_of(p, mats),
        "role": p["role"], "part": p["part"], "youngs_pa": "%g" % p["youngs"],
        "overlap_pp_rel": "%.4g" % ovpp, "overlap_pw_rel": "%.4g" % ovpw,
        "v_seeds": ";".join("%.6g" % x for x in v),
        # the halves' difference of the seeds' means against their spread
        "half_drift": "%.3g" % (mean(h2) - mean(h1)),
        "deck_amplitude_m": "%.6g" % outs[0]["deck_amplitude"], "dem_dt_s": "%.4g" % outs[0]["dem_dt"],
        "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    return [values[c] for c in COLUMNS]


OVERLAP_MAX = 0.01  # of a mean diameter


def rungs_above(mats):
    """The rungs a map point whose overlap passed the bound runs, in
    order: the ladder's top and, between it and the map's modulus, their
    geometric mean (4e8 Pa: LIGGGHTS refuses a modulus above 1e9 Pa without
    hard_particles, so the top has no stiffer rung, and the point's value is
    shown converged by the change between these two, docs/dem.md "The map")."""
    top = mats["map"]["youngs_ladder"][2]
    return [top, math.sqrt(mats["map"]["youngs_map"] * top)]


def by_key(k):
    for r in read_rows():
        if key(r["material"], r["layers"], r["drive"], r["beta_deg"], r["rotation"], r["e_scale"],
               r["cell_width_d"]) == k:
            return r
    return None


def run_point(binary, build, name, p, mats, have, jobs):
    """The point's missing seeds, jobs of them at once, each kept as it ends; then its row,
    appended whole."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        runs = {pool.submit(run_seed, binary, build, p, mats, s): s for s in SEEDS if s not in have}
        for done in concurrent.futures.as_completed(runs):
            s = runs[done]
            rec = done.result()
            append(RUNS, json.dumps(rec, sort_keys=True) + "\n")
            have[s] = rec
            o = rec["out"]
            print("dem-map: %s %s %s %d layers %s beta %g %s E %g seed %d: v %.5f m/s, overlap "
                  "%.3g d, %.0f CPU s" % (name, p["role"], p["material"], p["layers"], p["drive"],
                                          p["beta"], p["rotation"], p["youngs"], s, o["v_dem"],
                                          max(o["overlap_pp_max"], o["overlap_pw_max"]) / o["d_mean"],
                                          rec["cpu_s"]), flush=True)
    append(CSV, csv_line(row_of(p, mats, build, have)))


def run(binary, build, wanted):
    mats = materials()
    jobs = max(1, int(os.environ.get("DEM_MAP_JOBS", "1")))
    os.makedirs(os.path.dirname(CSV), exist_ok=True)
    lock = open(CSV + ".lock", "w")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        sys.exit("dem_map: another runner holds %s.lock" % CSV)
    repair(CSV)
    repair(RUNS)
    if not os.path.exists(CSV) or os.path.getsize(CSV) == 0:
        append(CSV, csv_line(COLUMNS))
    rows = read_rows()
    builds = {r["build"] for r in rows}
    if builds and builds != {build}:
        sys.exit("dem_map: the map's rows come from build %s, this binary from %s: run the map's "
                 "build (DEM_MAP_BUILD) or start a new map file" % (",".join(sorted(builds)), build))
    done = {key(r["material"], r["layers"], r["drive"], r["beta_deg"], r["rotation"],
                r["e_scale"], r["cell_width_d"]) for r in rows}
    seeds = finished_seeds(build)
    for name, points in plan():
        if wanted and name not in wanted:
            continue
        for p in points:
            todo = [p]
            while todo:
                q = todo.pop(0)
                k = point_key(q, mats)
                if k not in done:
                    run_point(binary, build, name, q, mats, seeds.setdefault(k, {}), jobs)
                    done.add(k)
                # a map point whose overlap passed the bound gets the stiffer
                # rungs at once: the map's value there is the softest rung
                # within the bound (docs/dem.md "The map")
                r = by_key(k)
                if q["role"] == "map" and r and float(r["overlap_max_rel"]) > OVERLAP_MAX:
                    todo += [dict(q, role="stiffness", youngs=e) for e in rungs_above(mats)]


FAKE_DEM = """import json, sys, time
t = time.process_time()
while time.process_time() - t < 0.2:
    pass
seed = int(sys.argv[sys.argv.index("--seed") + 1])
print(json.dumps({"v_dem": 0.1 * seed, "d_mean": 0.004, "v_first_half": 0.1 * seed,
                  "v_second_half": 0.1 * seed, "overlap_pp_max": 4e-6, "overlap_pw_max": 2e-6,
                  "grains": 92, "deck_amplitude": 0.002, "dem_dt": 1e-6}))
"""


def self_test():
    """run_point with a stand-in for convsim-dem (0.2 CPU s a seed) and its three seeds at once:
    one runs line a seed, one CSV row from them, each seed's CPU its own process's (not the
    three's sum) and the row's their sum. Runs no LIGGGHTS."""
    global RUNS, CSV
    with tempfile.TemporaryDirectory() as d:
        fake = os.path.join(d, "fake-dem")
        with open(fake, "w") as f:
            f.write("#!%s\n%s" % (sys.executable, FAKE_DEM))
        os.chmod(fake, 0o755)
        RUNS, CSV = os.path.join(d, "runs.jsonl"), os.path.join(d, "map.csv")
        mats, p, have = materials(), plan()[0][1][0], {}
        run_point(fake, "b", "part", p, mats, have, 3)
        runs = [json.loads(x) for x in open(RUNS)]
        rows = list(csv.reader(open(CSV)))
        bad = []
        if sorted(r["seed"] for r in runs) != list(SEEDS):
            bad.append("seeds %s" % [r["seed"] for r in runs])
        if not all(0.15 <= r["cpu_s"] <= 0.45 for r in runs):
            bad.append("a seed's CPU not its own: %s" % [r["cpu_s"] for r in runs])
        if len(rows) != 1:
            bad.append("%d rows" % len(rows))
        else:
            row = dict(zip(COLUMNS, rows[0]))
            if abs(float(row["cpu_s"]) - sum(r["cpu_s"] for r in runs)) > 0.06:
                bad.append("the row's CPU %s, the seeds' %s" % (row["cpu_s"], [r["cpu_s"] for r in runs]))
            if abs(float(row["v_dem"]) - 0.2) > 1e-9:
                bad.append("the row's v %s, the seeds' mean 0.2" % row["v_dem"])
    for b in bad:
        print("dem_map self-test: %s" % b)
    print("# pass %d\n# fail %d" % (0 if bad else 1, 1 if bad else 0))
    return 1 if bad else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    if len(sys.argv) >= 2 and sys.argv[1] == "plan":
        wanted = set(sys.argv[2:])
        for name, points in plan():
            if not wanted or name in wanted:
                print("%s: %d rows: %s" % (name, len(points), ", ".join(
                    "%s %d %s %g%s" % (p["role"], p["layers"], p["drive"], p["beta"],
                                       "" if p["rotation"] == "cw" else " ccw") for p in points[:6])
                    + (" ..." if len(points) > 6 else "")))
        return
    if len(sys.argv) >= 4 and sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3], set(sys.argv[4:]))
        return
    sys.exit(__doc__)


if __name__ == "__main__":
    main()
