#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Benchmark tables in the documents come from `make bench`'s output files.

A table in README.md, docs/*.md or docs/log/*.md that stands between

    <!-- bench: tests/bench/results/FILE.md table N -->
    ...
    <!-- /bench -->

is the N-th Markdown table (1 = the first) of that results file, line for
line. `python3 tests/docs_bench.py` writes every such block again from its
file (after `make bench`); `--check` only compares and exits 1 naming each
block that differs (tests/http/docs.test.mjs runs it).
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MARK = re.compile(r'^<!-- bench: (\S+) table (\d+) -->$')
END = '<!-- /bench -->'


def tables(text):
    """The Markdown tables of text, each a list of lines."""
    out, cur = [], []
    for line in text.splitlines():
        if line.startswith('|'):
            cur.append(line)
        elif cur:
            out.append(cur)
            cur = []
    if cur:
        out.append(cur)
    return out


def sync(path, check):
    lines = path.read_text().splitlines()
    out, bad, i = [], [], 0
    while i < len(lines):
        m = MARK.match(lines[i].strip())
        out.append(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while j < len(lines) and lines[j].strip() != END:
            j += 1
        if j == len(lines):
            bad.append(f'{path.relative_to(ROOT)}:{i + 1}: no {END} after the mark')
            break
        src = ROOT / m.group(1)
        found = tables(src.read_text()) if src.exists() else []
        n = int(m.group(2))
        if not 1 <= n <= len(found):
            bad.append(f'{path.relative_to(ROOT)}:{i + 1}: {m.group(1)} has no table {n}')
            want = lines[i + 1:j]
        else:
            want = found[n - 1]
        if [l for l in lines[i + 1:j] if l.strip()] != want:
            bad.append(f'{path.relative_to(ROOT)}:{i + 1}: the table differs from table {n} of {m.group(1)}')
        out.extend(want)
        out.append(lines[j])
        i = j + 1
    if not check:
        path.write_text('\n'.join(out) + '\n')
    return bad


def main():
    check = '--check' in sys.argv[1:]
    docs = [ROOT / 'README.md'] + sorted((ROOT / 'docs').glob('*.md')) + sorted((ROOT / 'docs' / 'log').glob('*.md'))
    bad = [b for p in docs for b in sync(p, check)]
    for b in bad:
        print(b)
    blocks = sum(1 for p in docs for l in p.read_text().splitlines() if MARK.match(l.strip()))
    print(f'docs_bench: {blocks} tables from the bench results, {len(bad)} differ' if check
          else f'docs_bench: {blocks} tables written from the bench results')
    return 1 if check and bad else 0


if __name__ == '__main__':
    sys.exit(main())
