#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""deps.py - dependency loops between the files of a module, counted by symbols.

For each object file of a folder (build/server/base/*.o), every undefined
symbol is looked up among the symbols the other objects of that folder define
(functions and globals, `nm`); "a.c uses b.c" when a.o needs a symbol b.o
defines. The strongly connected components of that file graph are the
dependency loops. A folder written DIR/** is one graph of DIR and all its
sub-folders (build/server/**: the daemon's floors together, so that no loop
runs across floors either). Only objects whose source still exists are
counted (a file moved or removed leaves its old object in the build).

usage: tests/deps.py [--max N] [BUILD/DIR ...]
  (default: the daemon's floors, build/server/** and build/api)
Prints, per folder, every loop of two or more files and the largest size; the
exit status is 1 when a loop is larger than --max (default: no limit).
"""
import glob
import os
import subprocess
import sys


_SYMBOLS = {}


def read_symbols(objs):
    """nm once for all the objects not read yet (one process, not one an
    object): fills _SYMBOLS[obj] = (defined, needed)."""
    todo = sorted({o for o in objs if o not in _SYMBOLS})
    if not todo:
        return
    out = subprocess.run(["nm", "-A", "-P", *todo], capture_output=True,
                         text=True, check=True).stdout
    for o in todo:
        _SYMBOLS[o] = (set(), set())
    for line in out.splitlines():
        obj, _, rest = line.partition(": ")
        parts = rest.split()
        if obj not in _SYMBOLS or len(parts) < 2:
            continue
        name, kind = parts[0], parts[1]
        defined, needed = _SYMBOLS[obj]
        if kind == "U":
            needed.add(name)
        elif kind.isupper():
            defined.add(name)


def symbols(obj):
    read_symbols([obj])
    return _SYMBOLS[obj]


def source_dir(folder):
    """The source folder of an object folder: the shortest tail of its path
    that is a directory here (build/nompi/server/base -> server/base)."""
    parts = os.path.normpath(folder).split(os.sep)
    for i in range(1, len(parts) + 1):
        tail = os.path.join(*parts[i:]) if i < len(parts) else ""
        if tail and os.path.isdir(tail):
            return tail
    return None


def objects(folder):
    """(name, object) of the folder's objects whose source exists; DIR/**:
    of DIR and its sub-folders, named by their path below DIR."""
    deep = folder.endswith("/**")
    top = folder[:-3] if deep else folder
    dirs = [top]
    if deep:
        dirs = sorted(d for d, _, _ in os.walk(top))
    out = []
    for d in dirs:
        src = source_dir(d)
        if src is None:
            continue
        for o in sorted(glob.glob(os.path.join(d, "*.o"))):
            c = os.path.basename(o)[:-2] + ".c"
            if os.path.exists(os.path.join(src, c)):
                out.append((os.path.relpath(os.path.join(d, c), top), o))
    return out


def graph(folder):
    pairs = objects(folder)
    read_symbols([o for _, o in pairs])
    names = [n for n, _ in pairs]
    defs, needs = {}, {}
    for n, o in pairs:
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
    folders = argv or ["build/server/**", "build/api"]
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
