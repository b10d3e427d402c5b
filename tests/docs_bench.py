#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Benchmark tables in the documents come from `make bench`'s output files.

A table in README.md, docs/*.md or docs/log/*.md that stands between

    <!-- bench: tests/bench/results/FILE.md table N -->
    ...
    <!-- /bench -->

is the N-th Markdown table (1 = the first) of that results file, line for
line. A figure in prose is marked the same way by a comment after it on its
line:

    ... 0.085<!-- from tests/bench/results/FILE.md "KEY" N --> CPU s ...

is the N-th number (1 = the first) of the first line of FILE that contains
KEY; the figure is the last number before the comment (after any earlier
comment on the line). `python3 tests/docs_bench.py` writes every such block
and figure again from its file (after `make bench`); `--check` only compares
and exits 1 naming each block or figure that differs (tests/http/docs.test.mjs
runs it, and `--self-test`, which shows that a wrong figure fails).

`--check` also reads every result page (tests/bench/results/*.md): its
first lines say how it was made, the command, the date, the build and the
machine (tests/bench/provenance.sh writes that line for the scripts).
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MARK = re.compile(r'^<!-- bench: (\S+) table (\d+) -->$')
END = '<!-- /bench -->'
FIGURE = re.compile(r'<!-- from (\S+) "([^"]+)"(?: (\d+))? -->')
NUMBER = re.compile(r'(?<![\w.])\d+(?:,\d{3})*(?:\.\d+)?(?:e[-+]?\d+)?')


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


def source_figure(src, key, n):
    """The n-th number of the first line of src containing key, or an error."""
    path = ROOT / src
    if not path.exists():
        return None, f'no file {src}'
    for line in path.read_text().splitlines():
        if key in line:
            nums = NUMBER.findall(line)
            if not 1 <= n <= len(nums):
                return None, f'the line of {src} with "{key}" has no number {n}'
            return nums[n - 1], None
    return None, f'{src} has no line with "{key}"'


def figures(line, where):
    """line with each marked figure written from its source, the number of
    marks, and [problems]: (new line, count, bad)."""
    out, bad, last, count = [], [], 0, 0
    for m in FIGURE.finditer(line):
        count += 1
        seg = line[last:m.start()]
        nums = list(NUMBER.finditer(seg))
        want, err = source_figure(m.group(1), m.group(2), int(m.group(3) or 1))
        if not nums:
            bad.append(f'{where}: no figure before the mark {m.group(0)}')
        elif err:
            bad.append(f'{where}: {err}')
        elif nums[-1].group(0) != want:
            bad.append(f'{where}: {nums[-1].group(0)} but {m.group(1)} says {want} ("{m.group(2)}")')
        if nums and want is not None:
            seg = seg[:nums[-1].start()] + want + seg[nums[-1].end():]
        out.append(seg + m.group(0))
        last = m.end()
    out.append(line[last:])
    return ''.join(out), count, bad


def sync(path, check, counts=None):
    lines = path.read_text().splitlines()
    out, bad, i = [], [], 0
    while i < len(lines):
        m = MARK.match(lines[i].strip())
        if not m:
            line, n, fbad = figures(lines[i], f'{path.relative_to(ROOT)}:{i + 1}')
            out.append(line)
            bad.extend(fbad)
            if counts is not None:
                counts['figures'] += n
            i += 1
            continue
        out.append(lines[i])
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


# How a result page says what made it, in its first lines.
PROVENANCE = {
    'command': re.compile(r'Command:|Made by|`make [a-z-]+`|`(?:bash|python3|node) tests/bench/'),
    'date': re.compile(r'\b20\d\d-\d\d-\d\d\b'),
    'build': re.compile(r'\b[Bb]uild:? `?[0-9a-f]{7,}|this build: [0-9a-f]{7,}'),
    'machine': re.compile(r'\b\d+ cores?\b'),
}
# Pages written before their generator said all four; the next run of
# their generator writes them whole. A listed page that says all four
# fails: the list only shrinks.
NOT_YET = {'control_loop.md', 'control_shaping.md', 'dem.md',
           'dem_cost.md', 'fit.md', 'peers.md', 'remote_loop.md',
           'scaling.md', 'study.md', 'workprec.md'}


def provenance_missing(text):
    """What of command, date, build and machine the page's first lines lack."""
    head = '\n'.join(text.splitlines()[:12])
    return [k for k, r in PROVENANCE.items() if not r.search(head)]


def provenance(results=ROOT / 'tests' / 'bench' / 'results'):
    bad = []
    for p in sorted(results.glob('*.md')):
        miss = provenance_missing(p.read_text())
        rel = p.relative_to(ROOT)
        if p.name in NOT_YET and not miss:
            bad.append(f'{rel}: says its command, date, build and machine: take it off NOT_YET')
        elif p.name not in NOT_YET and miss:
            bad.append(f'{rel}: its first lines give no {", ".join(miss)}')
    return bad


def self_test():
    """The figure check can fail: a right figure passes and is kept, a wrong
    one, a missing key or number, and a mark with no figure are named."""
    src = 'tests/bench/results/scaling.md'
    key = 'Machine alone at the same step'
    want, err = source_figure(src, key, 1)
    mark = f'<!-- from {src} "{key}" -->'
    cases = [
        (f'alone {want}{mark} CPU s', f'alone {want}{mark} CPU s', 0),
        (f'alone 0.5 CPU s{mark}', f'alone {want} CPU s{mark}', 1),
        (f'alone 7 {mark.replace(key, "no such line")}', None, 1),
        (f'alone 7 {mark.replace(" -->", " 99 -->")}', None, 1),
        (f'alone {mark}', None, 1),
        (f'1 2 {want}{mark} and 3', f'1 2 {want}{mark} and 3', 0),
    ]
    ok = 0
    for line, out, nbad in cases:
        got, count, bad = figures(line, 'x.md:1')
        if err is None and count == 1 and len(bad) == nbad and (out is None or got == out):
            ok += 1
        else:
            print(f'self-test: {line!r} gave {got!r}, {bad}')
    print(f'docs_bench self-test: {ok} of {len(cases)}')
    whole = ('# T\n\nRun 2026-11-28 21:37 UTC, build 9037bb9c2e9c, 2 cores (x), load average 1 1 1 before.\n'
             'Command: `bash tests/bench/x.sh`\n')
    pcases = [(whole, []), (whole.replace('build 9037bb9c2e9c', 'build ?'), ['build']),
              ('# T\n\n| a |\n', ['command', 'date', 'build', 'machine'])]
    pok = sum(1 for text, want in pcases if provenance_missing(text) == want)
    print(f'docs_bench provenance self-test: {pok} of {len(pcases)}')
    return 0 if ok == len(cases) and pok == len(pcases) else 1


def main():
    if '--self-test' in sys.argv[1:]:
        return self_test()
    check = '--check' in sys.argv[1:]
    docs = [ROOT / 'README.md'] + sorted((ROOT / 'docs').glob('*.md')) + sorted((ROOT / 'docs' / 'log').glob('*.md'))
    counts = {'figures': 0}
    bad = [b for p in docs for b in sync(p, check, counts)]
    if check:
        bad += provenance()
    for b in bad:
        print(b)
    blocks = sum(1 for p in docs for l in p.read_text().splitlines() if MARK.match(l.strip()))
    what = f'{blocks} tables and {counts["figures"]} figures'
    print(f'docs_bench: {what} from the bench results, {len(bad)} differ' if check
          else f'docs_bench: {what} written from the bench results')
    return 1 if check and bad else 0


if __name__ == '__main__':
    sys.exit(main())
