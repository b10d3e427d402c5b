# SPDX-License-Identifier: GPL-3.0-or-later
"""How long the `steady` start's settling holds a machine on a motion it does not keep.

The two machines of docs/random-machines.md that leave the start's motion (the preset with e
0.02838 m and omega_ss 120.3 rad/s at 0 deg cw, a throw of 2.7; with e 0.05195 m and k_c
3.827e6 at 120 deg cw, a throw of 9), each run for 30 simulated s after settlings of S s
(scene.settle) at the default steps, its feed displacement sampled at 50 Hz: v over the first
second, when the 1-s v first moves 1 % from it, and v over [25, 30] s.

  python3 tests/bench/settle_probe.py [--build BIN] [--out MD]

Writes tests/bench/results/settle_probe.md (a few seconds of CPU).
"""
import argparse, csv, datetime, os, subprocess, sys, tempfile

import provenance

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MACHINES = [["--set", "e=0.02838", "--set", "omega_ss=120.3", "--set", "beta=0", "--rotation", "cw"],
            ["--set", "e=0.05195", "--set", "k_c=3.827e6", "--set", "beta=120", "--rotation", "cw"]]
SETTLES = [0, 0.6, 2, 5]
DURATION, RATE = 30, 50


def run(binary, machine, settle):
    with tempfile.NamedTemporaryFile(suffix=".csv") as f:
        subprocess.run([binary, "run", "-q", "--duration", str(DURATION), "--sample-rate", str(RATE),
                        "--out", f.name, "--set", "settle=%g" % settle] + machine,
                       check=True, capture_output=True)
        rows = list(csv.DictReader(open(f.name)))
    t = [float(r["t"]) for r in rows]
    x = [float(r["feed_displacement"]) for r in rows]
    return t, x


def v_over(t, x, a, b):
    i = min(range(len(t)), key=lambda k: abs(t[k] - a))
    j = min(range(len(t)), key=lambda k: abs(t[k] - b))
    return (x[j] - x[i]) / (t[j] - t[i])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "convsim"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "settle_probe.md"))
    o = ap.parse_args()
    rows = []
    for machine in MACHINES:
        for s in SETTLES:
            t, x = run(o.build, machine, s)
            first = v_over(t, x, 0, 1)
            leaves = next((b for b in [k / 10 for k in range(10, 10 * DURATION + 1)]
                           if abs(v_over(t, x, b - 1, b) - first) > 0.01 * abs(first)), None)
            rows.append((" ".join(machine[1:6:2]), s, first, leaves, v_over(t, x, 25, 30)))
    rev = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                         text=True).stdout.strip()
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    with open(o.out, "w") as f:
        f.write("# The start's settling and a motion the machine does not keep\n\n")
        f.write("Command: `python3 tests/bench/settle_probe.py`, %s, build: %s, %s. `convsim run "
                "MACHINE --duration %d --sample-rate %d --set settle=S` at the default steps; v in m/s "
                "from the feed displacement.\n\n" % (now, rev, provenance.machine(), DURATION, RATE))
        f.write("| machine | settle S, s | v over [0, 1] s | the 1-s v 1 % off that by, s "
                "| v over [25, 30] s |\n|---|---|---|---|---|\n")
        for m, s, first, leaves, late in rows:
            f.write("| %s | %g | %.4f | %s | %.4f |\n" % (m, s, first, "%.1f" % leaves if leaves
                                                            else "never", late))
    print("wrote %s" % os.path.relpath(o.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
