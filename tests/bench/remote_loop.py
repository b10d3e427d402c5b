#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The loop closed from the user's code (docs/examples/remote_pi.py) at pace 1, with
0, 100 and 200 ms added before each command, and the same beta steps open loop (the
feedforward alone, one step each): settling, overshoot, IAE and steady error per
setpoint segment and the loop's latency, as a Markdown table (part of `make bench`;
docs/control-remote.md quotes it).

    python3 tests/bench/remote_loop.py [build/convsimd] > tests/bench/results/remote_loop.md
"""
import os, re, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DAEMON = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "convsimd")
SCRIPT = os.path.join(ROOT, "docs", "examples", "remote_pi.py")
SETPOINTS = "0.10:8,-0.08:8,0.05:8"
RUNS = [("PI, as measured", ["--delay", "0"]), ("PI, +100 ms", ["--delay", "0.1"]),
        ("PI, +200 ms", ["--delay", "0.2"]),
        ("open loop (feedforward step)", ["--kp", "0", "--ki", "0", "--rate", "1e6"])]
ROW = re.compile(r"^ +(\d) +([+-]\S+) +(\S+)(?: s)? +(\S+) % +(\S+) m +(\S+) %$")


def build():
    """The checkout's commit, and whether it had uncommitted changes."""
    rev = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], stdout=subprocess.PIPE,
                         text=True, cwd=ROOT).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD", "--", ".", ":!tests/bench/results",
                            ":!docs", ":!README.md"], cwd=ROOT).returncode
    return rev + (" with uncommitted changes" if dirty else "")


def main():
    daemon = subprocess.Popen([DAEMON, "--port", "0", "--log-level", "warn", "--web-root", os.path.join(ROOT, "web")],
                              stdout=subprocess.PIPE, text=True)
    try:
        port = re.search(r":(\d+)$", daemon.stdout.readline().strip()).group(1)
        env = {**os.environ, "CONVSIM_URL": f"http://127.0.0.1:{port}"}
        load = open("/proc/loadavg").read().split()[:3]
        print("# The loop closed from your own code: latency and settling\n")
        print(f"Command: `python3 tests/bench/remote_loop.py` (part of `make bench`), "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores, "
              f"load average {' '.join(load)} before; build {build()}.")
        print(f"Each run: `python3 docs/examples/remote_pi.py --pace 1 --setpoints {SETPOINTS}` "
              "with the options named; the preset, clockwise, from beta = 38 deg.\n")
        print("| loop | latency p50 / p99 (wall) | dead time p50 (simulated) | setpoint | settling (2 %) "
              "| overshoot | IAE | steady error |")
        print("|---|---|---|---|---|---|---|---|")
        for name, opts in RUNS:
            out = subprocess.run([sys.executable, SCRIPT, "--pace", "1", "--setpoints", SETPOINTS, *opts],
                                 env=env, check=True, capture_output=True, text=True).stdout
            wall = re.search(r"p50 (\S+) ms, p90 \S+ ms, p99 (\S+) ms", out)
            sim = re.search(r"t_effective\): p50 (\S+) ms", out)
            lat = f"{wall[1]} / {wall[2]} ms" if wall else "no command"
            dead = f"{sim[1]} ms" if sim else "-"
            for line in out.splitlines():
                m = ROW.match(line)
                if m:
                    settle = f"{m[3]} s" if m[3] != "never" else "never"
                    print(f"| {name} | {lat} | {dead} | {m[2]} m/s | {settle} | {m[4]} % | {m[5]} m | {m[6]} % |")
                    name = lat = dead = ""
        print(f"\nLoad average {' '.join(open('/proc/loadavg').read().split()[:3])} after. Settling: from the "
              "segment's start to the first period after which v stays within 2 % of the setpoint; "
              "overshoot: past the setpoint, in % of the step; IAE: the integral of |setpoint - v| "
              "over the segment; steady error: the mean of v - setpoint over its last second, in % of "
              "the setpoint.")
    finally:
        daemon.terminate()
        daemon.wait()


main()
