#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""deps.py - dependency loops between the files of a module, counted by symbols.

For each object file of a folder (build/server/*.o), every undefined symbol is
looked up among the symbols the other objects of that folder define (functions
and globals, `nm`); "a.c uses b.c" when a.o needs a symbol b.o defines. The
strongly connected components of that file graph are the dependency loops.

usage: tests/deps.py [BUILD/DIR ...]   (default: build/server build/api)
Prints, per folder, every loop of two or more files and the largest size; the
exit status is 1 when a loop is larger than --max (default: no limit).
"""
import glob
import os
import subprocess
import sys


def symbols(obj):
    out = subprocess.run(["nm", "-P", obj], capture_output=True, text=True,
                         check=True).stdout
    defined, needed = set(), set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) < 2:
            continue
        name, kind = parts[0], parts[1]
        if kind == "U":
            needed.add(name)
        elif kind.isupper():
            defined.add(name)
    return defined, needed


def graph(folder):
    objs = sorted(glob.glob(os.path.join(folder, "*.o")))
    names = [os.path.basename(o)[:-2] + ".c" for o in objs]
    defs, needs = {}, {}
    for n, o in zip(names, objs):
        defs[n], needs[n] = symbols(o)
    owner = {s: n for n in names for s in defs[n]}
    return {n: sorted({owner[s] for s in needs[n] if s in owner} - {n})
            for n in names}


def scc(g):
    """Tarjan's strongly connected components."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in g[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in g:
        if v not in index:
            visit(v)
    return out


def main(argv):
    limit = None
    if len(argv) > 1 and argv[0] == "--max":
        limit, argv = int(argv[1]), argv[2:]
    folders = argv or ["build/server", "build/api"]
    worst = 0
    for folder in folders:
        g = graph(folder)
        loops = sorted((c for c in scc(g) if len(c) > 1), key=len, reverse=True)
        largest = len(loops[0]) if loops else 1
        worst = max(worst, largest)
        print(f"{folder}: {len(g)} files, largest loop {largest}")
        for c in loops:
            print(f"  loop of {len(c)}: {' '.join(c)}")
    return 1 if limit is not None and worst > limit else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
