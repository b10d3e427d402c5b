# SPDX-License-Identifier: GPL-3.0-or-later
"""What a hard-thrown machine's curve costs: this build against a baseline, in turn.

The machines of docs/random-machines.md whose points take the later window (a throw above 5.5)
or the check at twice the sub-steps (above 4.2), the zoo's `ideal` machine (5.0 at most), and
the preset for scale. Each curve is `convsim sweep --beta 0:180:30 --rotation cw,ccw
--threads 1` (14 points); its CPU is the whole process's user + system time, the least of
--repeats runs, the two builds taking turns on the same machine.

  python3 tests/bench/throw_cost.py --baseline BIN [--build BIN] [--repeats 3] [--out MD]

Writes tests/bench/results/throw_cost.md (docs/random-machines.md). A minute or two of CPU.
"""
import argparse, datetime, os, resource, subprocess

import provenance
from throw_probe import rev

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MACHINES = ["e=0.05195 k_c=3827000", "e=0.05593 R=0.1926 k_c=882600", "e=0.07343", "e=0.09624",
            "e=0.04322 k_c=17170000 mu=0.2682", "e=0.0413 omega_ss=130.1",
            "drive=ideal e=0.03 k_c=5e6 mu=0.5", ""]


def cpu(binary, sets):
    """CPU s of one curve, the whole process."""
    a = [binary, "sweep", "-q", "--beta", "0:180:30", "--rotation", "cw,ccw", "--threads", "1",
         "--format", "csv"]
    for kv in sets.split():
        a += ["--set", kv]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(a, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "convsim"))
    ap.add_argument("--baseline", required=True)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(HERE, "results", "throw_cost.md"))
    o = ap.parse_args()
    rows = []
    for sets in MACHINES:
        base, this = [], []
        for _ in range(o.repeats):
            base.append(cpu(o.baseline, sets))
            this.append(cpu(o.build, sets))
        rows.append((sets or "the preset", min(base), min(this)))
    head = rev(ROOT)
    prev = rev(os.path.dirname(os.path.dirname(os.path.abspath(o.baseline))))
    with open(o.out, "w") as f:
        f.write("# What a hard-thrown machine's curve costs\n\n")
        f.write("Command: `python3 tests/bench/throw_cost.py --baseline BIN`, %s UTC, this build: "
                "%s, baseline: %s, %s. Each curve `convsim sweep --beta 0:180:30 --rotation "
                "cw,ccw --threads 1`, the whole process's CPU, the least of %d runs, the builds "
                "in turn.\n\n" % (datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"), head,
                                  prev, provenance.machine(), o.repeats))
        f.write("| machine | baseline, CPU s | this build, CPU s | ratio |\n|---|---|---|---|\n")
        for name, b, t in rows:
            f.write("| %s | %.2f | %.2f | %.2f |\n" % (name, b, t, t / b if b > 0 else 0.0))


if __name__ == "__main__":
    main()
