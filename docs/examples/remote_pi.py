#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A PI loop on the feed's transport velocity, closed from outside the daemon.

It reads a session's NDJSON stream, turns beta with PATCH, and prints per setpoint
segment the settling time, overshoot, IAE and steady error, and the loop's latency
(a sample line received -> the PATCH's 200). Standard library only; see
docs/control-remote.md ("The loop closed from your own code"). Run it next to `make run`:

    python3 docs/examples/remote_pi.py --setpoints 0.10:8,-0.08:8 [--pace 1] [--delay 0]
"""
import argparse, http.client, json, math, os, queue, sys, threading, time, urllib.parse

p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
p.add_argument("--setpoints", default="0.10:8,-0.08:8", help="V:SECONDS,... (m/s, simulated s)")
p.add_argument("--pace", type=float, default=1.0, help="the session's real-time factor")
p.add_argument("--kp", type=float, default=0.05, help="proportional gain (m/s per m/s)")
p.add_argument("--ki", type=float, default=1.5, help="integral gain (1/s)")
p.add_argument("--rate", type=float, default=60.0, help="beta rate limit, deg per simulated s")
p.add_argument("--deadband", type=float, default=0.05, help="smaller beta changes are not sent, deg")
p.add_argument("--delay", type=float, default=0.0, help="wall seconds added before each PATCH")
args = p.parse_args()
SETPOINTS = [tuple(map(float, s.split(":"))) for s in args.setpoints.split(",")]

URL = urllib.parse.urlsplit(os.environ.get("CONVSIM_URL", "http://127.0.0.1:8080"))
TOKEN = os.environ.get("CONVSIM_TOKEN")
if TOKEN is None and os.path.exists("var/token"):  # what `make run` made
    TOKEN = open("var/token").read().strip()
HEAD = {"Content-Type": "application/json", **({"Authorization": "Bearer " + TOKEN} if TOKEN else {})}


def call(conn, method, path, body=None):
    """One request on a kept-alive connection; the JSON answer (raises on >= 400)."""
    conn.request(method, "/api/v1" + path, json.dumps(body) if body is not None else None, HEAD)
    answer = conn.getresponse()
    text = answer.read()
    if answer.status >= 400:
        raise RuntimeError(f"{method} {path}: {answer.status} {text.decode()}")
    return json.loads(text) if text else None


def monotonic_branch(conn):
    """v(beta) of the preset (clockwise) between its two peaks, as (beta, v) sorted by beta."""
    sweep = call(conn, "POST", "/sweeps", {"beta": {"from": 10, "to": 170, "step": 5}, "rotations": ["cw"]})
    while (s := call(conn, "GET", f"/sweeps/{sweep['id']}"))["state"] != "done":
        time.sleep(0.2)
    curve = sorted((pt["beta"], pt["velocity"]) for pt in s["points"])
    top = max(range(len(curve)), key=lambda i: curve[i][1])  # the forward peak
    bottom = min(range(len(curve)), key=lambda i: curve[i][1])  # the backward peak
    branch = curve[top:bottom + 1]
    assert all(v0 > v1 for (_, v0), (_, v1) in zip(branch, branch[1:])), "v(beta) not monotonic"
    return branch


def beta_for(branch, v):
    """The beta of the branch where v(beta) = v (linear between the sweep's points)."""
    for (b0, v0), (b1, v1) in zip(branch, branch[1:]):
        if v1 <= v <= v0:
            return b0 + (b1 - b0) * (v0 - v) / (v0 - v1)
    return branch[0][0] if v > branch[0][1] else branch[-1][0]


def setpoint(t):
    """The setpoint at simulated time t."""
    end = 0.0
    for v, seconds in SETPOINTS:
        end += seconds
        if t < end:
            return v
    return SETPOINTS[-1][0]


def sender(sid, todo, latency):
    """Sends each command when it is due (--delay after its sample was received), in
    order, and keeps its latency: (wall s from the sample to the 200, t_effective - t)."""
    conn = http.client.HTTPConnection(URL.hostname, URL.port)
    while (command := todo.get()) is not None:
        due, received, t, beta = command
        time.sleep(max(0.0, due - time.monotonic()))
        try:
            answer = call(conn, "PATCH", f"/sessions/{sid}", {"beta": round(beta, 3)})
        except Exception as e:  # the loop is broken: say so, and stop sending
            latency.append(e)
            return
        assert answer["acknowledged"]
        latency.append((time.monotonic() - received, answer["t_effective"] - t))


def control(sid, branch, beta):
    """The loop: every sample of the stream (25 a simulated second, one per period)
    measures v and sets beta. Returns the samples [(t, v)] and the latencies
    [(wall s, simulated s)] of the acknowledged commands."""
    stream = http.client.HTTPConnection(URL.hostname, URL.port)
    stream.request("GET", f"/api/v1/sessions/{sid}/stream?format=ndjson&fields=feed&rate=25", headers=HEAD)
    lines = stream.getresponse()
    samples, latency, todo = [], [], queue.Queue()
    thread = threading.Thread(target=sender, args=(sid, todo, latency))
    thread.start()
    integral, last = 0.0, None
    for line in lines:
        received = time.monotonic()
        rec = json.loads(line)
        if rec["type"] == "end":
            break
        if rec["type"] != "sample":
            continue
        # v over the last period from the feed's mean position (feed_velocity, the
        # daemon's own, is null from a command until one period after its ramp)
        t, x = rec["t"], rec["feed_displacement"]
        prev, last = last, (t, x)
        if prev is None or t - prev[0] < 0.03:
            continue
        dt = t - prev[0]
        v = (x - prev[1]) / dt
        samples.append((t, v))
        r = setpoint(t)
        e = r - v
        # PI in velocity units, through the inverse curve (feedforward: beta for r)
        trial = integral + args.ki * e * dt
        want = beta_for(branch, r + args.kp * e + trial)
        step = max(-args.rate * dt, min(args.rate * dt, want - beta))
        if abs(step - (want - beta)) < 1e-9 and branch[0][0] < want < branch[-1][0]:
            integral = trial  # anti-windup: integrate only while beta is not limited
        if abs(step) < args.deadband:
            continue
        beta += step
        todo.put((received + args.delay, received, t, beta))
    todo.put(None)
    thread.join()
    stream.close()
    for failed in (x for x in latency if isinstance(x, Exception)):
        raise failed
    return samples, latency


def segment_table(samples):
    """Per setpoint segment: setpoint, settling time (2 %), overshoot, IAE, steady error."""
    rows, start, v_before = [], 0.0, samples[0][1]
    for k, (r, seconds) in enumerate(SETPOINTS):
        end = start + seconds
        seg = [(t, v) for t, v in samples if start <= t < end]
        out = [i for i, (t, v) in enumerate(seg) if abs(v - r) > 0.02 * abs(r)]
        if not out:
            settle = 0.0
        elif out[-1] + 1 < len(seg):
            settle = seg[out[-1] + 1][0] - start
        else:
            settle = math.inf  # not settled in the segment
        step = r - v_before
        over = max(0.0, max((v - r) * math.copysign(1, step) for t, v in seg)) / abs(step)
        iae = sum(abs(r - v) * (t1 - t0) for (t0, v), (t1, _) in zip(seg, seg[1:] + [(end, 0)]))
        tail = [v - r for t, v in seg if t >= end - min(1.0, seconds / 4)]
        rows.append((k + 1, r, settle, 100 * over, iae, 100 * sum(tail) / len(tail) / abs(r)))
        start, v_before = end, seg[-1][1]
    return rows


def percentile(xs, q):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(q / 100 * len(xs)))]


def main():
    conn = http.client.HTTPConnection(URL.hostname, URL.port)
    branch = monotonic_branch(conn)
    print(f"monotonic branch of v(beta): beta {branch[0][0]:g}..{branch[-1][0]:g} deg, "
          f"v {branch[0][1]:+.3f}..{branch[-1][1]:+.3f} m/s")
    for r, _ in SETPOINTS:
        if not branch[-1][1] < r < branch[0][1]:
            sys.exit(f"setpoint {r:+g} m/s: the branch reaches {branch[-1][1]:+.3f}..{branch[0][1]:+.3f} m/s")
    total = sum(seconds for _, seconds in SETPOINTS)
    session = call(conn, "POST", "/sessions", {"params": {"beta": 38, "rotation": "cw"},
                                               "pace": args.pace, "until": total})
    try:
        samples, latency = control(session["id"], branch, 38.0)
    finally:
        call(conn, "DELETE", f"/sessions/{session['id']}")
    print(f"session {session['id']}: pace {args.pace:g}, {len(latency)} commands, "
          f"{1000 * args.delay:g} ms added before each")
    print("segment  setpoint  settling  overshoot     IAE    steady error")
    for k, r, settle, over, iae, steady in segment_table(samples):
        s = f"{settle:6.2f} s" if math.isfinite(settle) else "   never"
        print(f"{k:7d}  {r:+.3f}  {s}  {over:7.1f} %  {iae:.4f} m  {steady:+7.2f} %")
    wall = [1000 * w for w, _ in latency]
    sim = [1000 * s for _, s in latency]
    print("latency, sample received -> PATCH acknowledged: " + ", ".join(
        f"p{q} {percentile(wall, q):.1f} ms" for q in (50, 90, 99)) + f", max {max(wall):.1f} ms")
    print(f"the same in simulated time (sample t -> t_effective): p50 {percentile(sim, 50):.1f} ms, "
          f"max {max(sim):.1f} ms")


main()
