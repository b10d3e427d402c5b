# SPDX-License-Identifier: GPL-3.0-or-later
"""What a hard-thrown machine's curve costs: this build against a baseline, in turn.

The machines of docs/random-machines.md whose points take the later window (a throw above 5.5)
or the check at twice the sub-steps (above 4.2), the zoo's `ideal` machine (5.0 at most), and
the preset for scale. Each curve is `convsim sweep --beta 0:180:30 --rotation cw,ccw
--threads 1` (14 points); its CPU is the whole process's user + system time, the least of
--repeats runs, the two builds taking turns on the same machine.

  python3 tests/bench/throw_cost.py --baseline BIN [--build BIN] [--repeats 3] [--out MD]
                                    [--callgrind]

Writes tests/bench/results/throw_cost.md (docs/random-machines.md). A minute or two of CPU.
The CPU of this shared machine varies by up to 1.7 times between minutes, which the least of a
few runs does not always remove; --callgrind adds each curve's instruction count under
valgrind's callgrind, the same on every run (about twenty minutes more).
"""
import argparse, datetime, os, re, resource, subprocess

import provenance
from throw_probe import rev

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MACHINES = ["e=0.05195 k_c=3827000", "e=0.05593 R=0.1926 k_c=882600", "e=0.07343", "e=0.09624",
            "e=0.04322 k_c=17170000 mu=0.2682", "e=0.0413 omega_ss=130.1",
            "drive=ideal e=0.03 k_c=5e6 mu=0.5", ""]


def curve(binary, sets):
    a = [binary, "sweep", "-q", "--beta", "0:180:30", "--rotation", "cw,ccw", "--threads", "1",
         "--format", "csv"]
    for kv in sets.split():
        a += ["--set", kv]
    return a


def instructions(binary, sets):
    """Instructions of one curve under callgrind (its 'Collected' count)."""
    r = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null"] +
                       curve(binary, sets), capture_output=True, text=True, check=True)
    return int(re.search(r"Collected : (\d+)", r.stderr).group(1))


def cpu(binary, sets):
    """CPU s of one curve, the whole process."""
    a = curve(binary, sets)
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
    ap.add_argument("--callgrind", action="store_true")
    o = ap.parse_args()
    rows = []
    for sets in MACHINES:
        base, this = [], []
        for _ in range(o.repeats):
            base.append(cpu(o.baseline, sets))
            this.append(cpu(o.build, sets))
        ins = ((instructions(o.baseline, sets), instructions(o.build, sets)) if o.callgrind
               else None)
        rows.append((sets or "the preset", min(base), min(this), ins))
    head = rev(ROOT)
    prev = rev(os.path.dirname(os.path.dirname(os.path.abspath(o.baseline))))
    with open(o.out, "w") as f:
        f.write("# What a hard-thrown machine's curve costs\n\n")
        f.write("Command: `python3 tests/bench/throw_cost.py --baseline BIN%s`, %s UTC, this "
                "build: %s, baseline: %s, %s. Each curve `convsim sweep --beta 0:180:30 "
                "--rotation cw,ccw --threads 1`, the whole process's CPU, the least of %d runs, "
                "the builds in turn%s.\n\n" % (
                    " --callgrind" if o.callgrind else "",
                    datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"), head, prev,
                    provenance.machine(), o.repeats, "; instructions: callgrind's count of one "
                    "run (the same on every run)" if o.callgrind else ""))
        f.write("| machine | baseline, CPU s | this build, CPU s | ratio |%s\n|---|---|---|---|%s\n"
                % ((" baseline, instructions | this build | ratio |", "---|---|---|")
                   if o.callgrind else ("", "")))
        for name, b, t, ins in rows:
            f.write("| %s | %.3f | %.3f | %.2f |" % (name, b, t, t / b if b > 0 else 0.0))
            if ins:
                f.write(" %.4g | %.4g | %.2f |" % (ins[0], ins[1], ins[1] / ins[0]))
            f.write("\n")


if __name__ == "__main__":
    main()
