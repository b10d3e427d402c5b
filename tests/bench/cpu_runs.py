#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""CPU time of whole processes, for the bench tables (tests/bench/startup.sh).

    python3 tests/bench/cpu_runs.py N CMD1 ... [-- CMD2 ... [-- ...]]

runs each command N times, the commands taking turns (so that a busy
machine weighs on each alike), stdout and stderr to /dev/null, and prints
one line per command: the least and the median CPU time (user + sys of the
process and its children, from wait4's rusage, in seconds) and the median
wall time. The process is started with posix_spawn, so no copy of this
interpreter is charged to it.
"""
import os
import statistics
import sys
import time


def main():
    n = int(sys.argv[1])
    cmds, cur = [], []
    for a in sys.argv[2:]:
        if a == '--':
            cmds.append(cur)
            cur = []
        else:
            cur.append(a)
    cmds.append(cur)
    null = os.open(os.devnull, os.O_WRONLY)
    acts = [(os.POSIX_SPAWN_DUP2, null, 1), (os.POSIX_SPAWN_DUP2, null, 2)]
    cpu = [[] for _ in cmds]
    wall = [[] for _ in cmds]
    for _ in range(n):
        for i, c in enumerate(cmds):
            t0 = time.monotonic()
            pid = os.posix_spawnp(c[0], c, os.environ, file_actions=acts)
            _, status, ru = os.wait4(pid, 0)
            wall[i].append(time.monotonic() - t0)
            if os.waitstatus_to_exitcode(status) != 0:
                sys.exit(f'cpu_runs: {" ".join(c)}: exit status {os.waitstatus_to_exitcode(status)}')
            cpu[i].append(ru.ru_utime + ru.ru_stime)
    for i in range(len(cmds)):
        print(f'{min(cpu[i]):.6f} {statistics.median(cpu[i]):.6f} {statistics.median(wall[i]):.6f}')


if __name__ == '__main__':
    main()
