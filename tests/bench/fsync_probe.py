#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""What a control log's durable append costs on this disk (docs/hardening.md):
one line appended and fdatasync'd to each of FILES files, ROUNDS rounds, three
ways: the files one after another from one thread (what one shared flush thread
syncing each session's file would do), each file from a thread of its own (what
convsimd does: each session's handler syncs its own log), and all lines to one
file with one fdatasync (a shared journal). Temporary files only.

    [FILES=8] [ROUNDS=50] python3 tests/bench/fsync_probe.py
"""
import os
import tempfile
import threading
import time

FILES = int(os.environ.get("FILES", 8))
ROUNDS = int(os.environ.get("ROUNDS", 50))
LINE = b'{"beta":12.5,"t_effective":1.0}\n'


def main():
    with tempfile.TemporaryDirectory(prefix="convsim-fsync-") as d:
        fds = [os.open(f"{d}/log{i}", os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
               for i in range(FILES)]
        t = time.time()
        for _ in range(ROUNDS):
            for fd in fds:
                os.write(fd, LINE)
                os.fdatasync(fd)
        serial = (time.time() - t) / ROUNDS

        def own(fd):
            for _ in range(ROUNDS):
                os.write(fd, LINE)
                os.fdatasync(fd)
        threads = [threading.Thread(target=own, args=(fd,)) for fd in fds]
        t = time.time()
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        parallel = (time.time() - t) / ROUNDS

        t = time.time()
        for _ in range(ROUNDS):
            os.write(fds[0], LINE * FILES)
            os.fdatasync(fds[0])
        journal = (time.time() - t) / ROUNDS
        for fd in fds:
            os.close(fd)
    print(f"    FILES={FILES} ROUNDS={ROUNDS} python3 tests/bench/fsync_probe.py\n")
    print(f"| {FILES} lines made durable a round | ms a round | durable lines / s |")
    print("|---|---|---|")
    for name, sec in (("one thread, one file after another", serial),
                      ("a thread per file (convsimd)", parallel),
                      ("one file, one fdatasync", journal)):
        print(f"| {name} | {sec * 1000:.2f} | {FILES / sec:.0f} |")


if __name__ == "__main__":
    main()
