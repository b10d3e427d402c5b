# SPDX-License-Identifier: GPL-3.0-or-later
"""Random machines whose feed is thrown harder than the zoo's, against converged references.

Each machine is the preset with its eccentricity e drawn log-uniform in [0.025, 0.1] m (the
preset's 0.0215 gives a throw of about 3.4) and up to two more settings drawn from plausible
ranges (restitution, friction, element mass, contact stiffness, layers, trough mass, motor
speed). Its curve `convsim sweep --beta 0:180:30 --rotation cw,ccw` at the defaults (this
build, and BASELINE's where given) is held against two references: dem at 1.25e-4 s / 40
sub-steps without feed events over [10, 18] s, and at 6.25e-5 s / 80 over [20, 28] s. A point
is claimed by the references where both are steady and they agree within a quarter of the 1 %
gate (docs/model-numerics.md section 10); the finer one is v_ref. A point of a curve misses
where it says steady and tol_met and lies beyond the gate from v_ref.

  python3 tests/bench/throw_probe.py [--seeds 1,2,3] [--count 14] [--baseline BIN] [--out MD]
                                    [--jsonl FILE] [--refs FILE] [--changed]

--refs takes each machine's references from an earlier run's --jsonl: they run at given steps,
which a change to the steps the engine picks leaves as they were.

--changed (with --baseline) runs the references only for the machines whose curve this build
changes (any byte of the two builds' CSV), lists those alone and counts the others as
unchanged: their misses are the baseline's. Default output then
tests/bench/results/throw_probe_changed.md.

Its header gives its wall time (the references take most of it). Writes the table to
tests/bench/results/throw_probe.md (docs/random-machines.md).
"""
import argparse, csv, datetime, io, json, math, os, random, subprocess, sys, tempfile, time

import provenance

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXTRA = [("R", 0.05, 0.6, "lin"), ("mu", 0.2, 0.9, "lin"), ("m_n", 0.2, 2.0, "log"),
         ("k_c", 3e5, 3e7, "log"), ("layers", 1, 12, "int"), ("M_r", 50, 300, "log"),
         ("omega_ss", 100, 220, "lin")]
REF1 = ["--set", "dt=1.25e-4", "--set", "substeps=40", "--set", "feed_events=false",
        "--set", "transient=10"], 18
REF2 = ["--set", "dt=6.25e-5", "--set", "substeps=80", "--set", "feed_events=false",
        "--set", "transient=20"], 28


def draw(rng):
    s = {"e": float("%.4g" % math.exp(rng.uniform(math.log(0.025), math.log(0.1))))}
    for name, lo, hi, kind in rng.sample(EXTRA, rng.choice([0, 1, 2])):
        if kind == "int":
            s[name] = rng.randint(lo, hi)
        elif kind == "log":
            s[name] = float("%.4g" % math.exp(rng.uniform(math.log(lo), math.log(hi))))
        else:
            s[name] = float("%.4g" % rng.uniform(lo, hi))
    return s


def sweep(binary, sets, extra=(), duration=None):
    a = [binary, "sweep", "-q", "--beta", "0:180:30", "--rotation", "cw,ccw", "--format", "csv",
         "--threads", "2"]
    if duration:
        a += ["--duration", str(duration)]
    for k, v in sets.items():
        a += ["--set", "%s=%s" % (k, v)]
    r = subprocess.run(a + list(extra), capture_output=True, text=True)
    if r.returncode:
        return None
    return list(csv.DictReader(io.StringIO(r.stdout)))


def throw(binary, sets):
    """The largest throw over beta 0, 90, 150 cw: the trough's largest speed times omega_ss / g."""
    om = float(sets.get("omega_ss", 157.08))
    best = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "run.csv")
        for beta in (0, 90, 150):
            a = [binary, "run", "-q", "-d", "1", "-o", path, "-r", "4000", "--set", "beta=%d" % beta]
            for k, v in sets.items():
                a += ["--set", "%s=%s" % (k, v)]
            subprocess.run(a, capture_output=True)
            with open(path) as f:
                rows = list(csv.DictReader(f))
            half = rows[len(rows) // 2:]
            for p, q in zip(half, half[1:]):
                h = float(q["t"]) - float(p["t"])
                v = math.hypot(float(q["x"]) - float(p["x"]), float(q["y"]) - float(p["y"])) / h
                best = max(best, v * om / 9.81)
    return best


def flags(curve, ref):
    """The points claimed by the references that a curve flags: not steady or not tol_met."""
    return sum(1 for r, (c, _, _) in zip(curve, ref) if c and
               not (r["steady"] == "true" and r["tol_met"] == "true"))


def misses(curve, ref):
    """The points a curve claims (steady, tol_met) beyond the gate from v_ref."""
    return [(r["beta"], r["rotation"], float(r["velocity"]), v) for r, (claimed, v, gate) in
            zip(curve, ref) if claimed and r["steady"] == "true" and r["tol_met"] == "true" and
            abs(float(r["velocity"]) - v) > gate]


def rev(tree):
    """The commit a tree was built from: a prev-REV directory's (tests/bench/prev_build.sh
    exports one with git archive, no repository of its own), else the repository's HEAD."""
    for part in reversed(os.path.abspath(tree).split(os.sep)):
        if part.startswith("prev-"):
            return part[len("prev-"):]
    return subprocess.run(["git", "-C", tree, "rev-parse", "--short", "HEAD"],
                          capture_output=True, text=True).stdout.strip() or tree


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--count", type=int, default=14)
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "convsim"))
    ap.add_argument("--baseline")
    ap.add_argument("--out")
    ap.add_argument("--changed", action="store_true", help="only the machines whose curve this "
                    "build changes against --baseline")
    ap.add_argument("--jsonl", help="also keep every machine's points here")
    ap.add_argument("--refs", help="take the references from an earlier run's --jsonl (their "
                    "steps are given, so a change to the steps the engine picks leaves them)")
    o = ap.parse_args()
    if o.changed and not o.baseline:
        ap.error("--changed needs --baseline")
    o.out = o.out or os.path.join(HERE, "results", "throw_probe_changed.md" if o.changed
                                  else "throw_probe.md")
    unchanged = 0
    kept = {}
    if o.refs:
        for line in open(o.refs):
            d = json.loads(line)
            kept[json.dumps(d["sets"], sort_keys=True)] = (d["ref1"], d["ref2"])
    rows, tot = [], {"claimed": 0, "base": 0, "this": 0, "flag": 0, "mach_base": 0,
                     "mach_this": 0, "bflag": 0}
    keep = open(o.jsonl, "a") if o.jsonl else None
    began = time.time()
    for seed in [int(x) for x in o.seeds.split(",")]:
        rng = random.Random(seed)
        for i in range(o.count):
            sets = draw(rng)
            key = json.dumps(sets, sort_keys=True)
            this = sweep(o.build, sets)
            base = sweep(o.baseline, sets) if o.baseline else None
            if o.changed and this and this == base:
                unchanged += 1
                print(seed, sets, "unchanged", file=sys.stderr, flush=True)
                continue
            r1, r2 = kept[key] if key in kept else (sweep(o.build, sets, *REF1),
                                                    sweep(o.build, sets, *REF2))
            if not (r1 and r2 and this):
                rows.append((seed, sets, None))
                continue
            peak = max(abs(float(r["velocity"])) for r in r2) or 1e-9
            ref = []
            for a, b in zip(r1, r2):
                v = float(b["velocity"])
                gate = 0.01 * (abs(v) if abs(v) >= 0.3 * peak else peak)
                claimed = (a["steady"] == "true" and b["steady"] == "true" and
                           abs(float(a["velocity"]) - v) <= 0.25 * gate)
                ref.append((claimed, v, gate))
            m_this = misses(this, ref)
            m_base = misses(base, ref) if base else []
            flagged = flags(this, ref)
            tot["bflag"] += flags(base, ref) if base else 0
            claimed = sum(1 for c, _, _ in ref if c)
            g = throw(o.build, sets)
            rows.append((seed, sets, (g, claimed, m_base, m_this, flagged)))
            tot["claimed"] += claimed
            tot["base"] += len(m_base)
            tot["this"] += len(m_this)
            tot["flag"] += flagged
            tot["mach_base"] += bool(m_base)
            tot["mach_this"] += bool(m_this)
            if keep:
                keep.write(json.dumps({"seed": seed, "sets": sets, "throw": g, "ref1": r1,
                                       "ref2": r2, "this": this, "base": base}) + "\n")
                keep.flush()
            print(seed, sets, "throw %.1f" % g, "claimed", claimed, "baseline misses",
                  len(m_base), "misses", len(m_this), file=sys.stderr, flush=True)
    cmd = "python3 tests/bench/throw_probe.py --seeds %s --count %d%s%s%s" % (
        o.seeds, o.count, " --baseline BIN" if o.baseline else "", " --changed" if o.changed
        else "",
        " --refs JSONL (the references of %d machines from an earlier run)" % len(kept)
        if o.refs else "")
    fmt = lambda ms: "; ".join("%s %s %.4f (v_ref %.4f)" % m for m in ms) or "none"
    with open(o.out, "w") as f:
        f.write("# A feed thrown hard: random machines against converged references\n\n")
        f.write("Command: `%s`, %s UTC, this build: %s%s, %s. Wall time: %.0f min.\n\n" % (
            cmd, datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M"), rev(ROOT),
            ", baseline: %s" % rev(os.path.dirname(os.path.dirname(os.path.abspath(o.baseline))))
            if o.baseline else "", provenance.machine(), (time.time() - began) / 60))
        f.write("| machine | seed | throw | points claimed by the references | baseline's misses"
                " | this build's misses | this build's flagged (not steady or not tol_met) |\n")
        f.write("|---|---|---|---|---|---|---|\n")
        for seed, sets, res in rows:
            name = " ".join("%s=%s" % kv for kv in sets.items())
            if res is None:
                f.write("| %s | %d | - | a run failed | | | |\n" % (name, seed))
                continue
            g, claimed, mb, mt, fl = res
            f.write("| %s | %d | %.1f | %d of 14 | %s | %s | %d |\n" % (
                name, seed, g, claimed, fmt(mb) if o.baseline else "-", fmt(mt), fl))
        f.write("\n| total | points claimed | baseline's misses (machines) | this build's misses"
                " (machines) | this build's flagged | baseline's flagged |\n"
                "|---|---|---|---|---|---|\n")
        f.write("| %d machines%s | %d | %s | %d (%d) | %d | %s |\n" % (
            len(rows), ", %d more unchanged" % unchanged if o.changed else "", tot["claimed"],
            "%d (%d)" % (tot["base"], tot["mach_base"]) if o.baseline else "-",
            tot["this"], tot["mach_this"], tot["flag"],
            tot["bflag"] if o.baseline else "-"))


if __name__ == "__main__":
    main()
