// SPDX-License-Identifier: GPL-3.0-or-later
// Measured figures on the pages of a newcomer's path come from a result
// file or are not there. On README.md, docs/getting-started.md and the task
// pages below, a figure of a narrow, reliable kind (a number followed by
// ms, µs, CPU s, PATCH/s, "% of the peak" or "× real time") is either
// - marked: a `<!-- from tests/bench/results/FILE.md "KEY" N -->` comment
//   follows it on its line with no other number between (tests/docs_bench.py
//   --check compares it with that file, as it does the bench tables), or
// - inside a bench table block (<!-- bench: ... --> ... <!-- /bench -->), or
// - a specification value (a setting, default, limit or target) listed in
//   SPEC below with the words around it.
// Anything else fails: mark it, link the result page, or move the paragraph
// to docs/log/. Other measured figures (plain percentages, counts) are not
// recognised reliably and are not checked. Conventions: docs/testing.md
// ("Examples in the documentation").
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = fileURLToPath(new URL('../..', import.meta.url));

export const PAGES = ['README.md', 'docs/getting-started.md', 'docs/accuracy.md', 'docs/speed.md',
  'docs/feed-models.md', 'docs/dem.md', 'docs/control.md', 'docs/hardening.md', 'docs/durability.md',
  'docs/load.md'];

const NUM = String.raw`(?<![\w.])\d+(?:,\d{3})*(?:\.\d+)?(?:e[-+]?\d+)?`;
// a number, optionally a range "16 to 49" / "5–7", then the unit
const FIGURE = new RegExp(String.raw`${NUM}(?:\s*(?:to|–|-)\s*${NUM})?\s*(?:ms\b|µs\b|CPU s\b|CPU seconds\b|PATCH/s|% of the peak|[×x] real time)`, 'g');
const MARK = /^(?:\s|[^\d<])*?<!-- from \S+ "[^"]+"(?: \d+)? -->/;

// Specification values: [page, the exact words around the figure].
// A listed phrase the page no longer has fails, so the list stays true.
export const SPEC = [
  ['docs/accuracy.md', '[The curve at 0.1 CPU s]'],
  ['docs/accuracy.md', '[The curve at 0.1 CPU\n  s]'],
  ['docs/accuracy.md', 'v within 0.1 % of the peak of the full model\'s'],
  ['docs/accuracy.md', 'holds it within 0.1 % of the peak'],
  ['docs/speed.md', '## The curve at 0.1 CPU s'],
  ['docs/speed.md', 'at most 0.1 CPU s'],
  ['docs/load.md', 'stream lag p99 stays under 50 ms'],
  ['docs/load.md', 'p99 < 50 ms'],
  ['docs/feed-models.md', '(1000 CPU s a simulated second by default)'],
  /* the admission's cost model: DEM_CPU_PER_GRAIN_STEP in dem/dem.h, and what it gives */
  ['docs/feed-models.md', '3.2e-7 CPU s a\n   grain\'s step; 0.78 CPU s a simulated second'],
  ['docs/dem.md', 'it is within 5 % of the peak at'],
  ['docs/dem.md', 'at 5 ms they are'],
  ['docs/dem.md', '10 ms 78 %'],
  ['docs/hardening.md', 'target, p99 under 100 ms'],
  ['docs/hardening.md', 'runs for up to 30 ms of CPU'],
  ['docs/hardening.md', 'within the first 50 ms of CPU'],
  /* the moments the durability tests and the kill probe kill the daemon at */
  ['docs/durability.md', 'down to 0 ms)'],
  ['docs/durability.md', '0 ms), and neither'],
  ['docs/durability.md', 'SIGKILL at once (0 ms) and about 1 ms after'],
  ['docs/durability.md', 'experiment 404 at 0 ms'],
  ['docs/durability.md', 'or unreadable` at 1 ms'],
  ['docs/durability.md', 'at a random moment 150 to 400 ms into each round'],
  ['docs/durability.md', '(0 ms) and about 1 ms after a 200'],
  ['docs/durability.md', 'missing from the log at 0 ms'],
  ['docs/durability.md', 'at 1 ms).'],
];

// The unmarked measured-looking figures of one page: ["page:line: text"].
export function unmarkedFigures(name, text, spec = SPEC) {
  const bad = [];
  const allowed = [];
  for (const [page, words] of spec) {
    if (page !== name) continue;
    let at = text.indexOf(words);
    if (at < 0) bad.push(`${name}: the specification value "${words}" is not on the page (remove it from SPEC)`);
    while (at >= 0) { allowed.push([at, at + words.length]); at = text.indexOf(words, at + 1); }
  }
  let fence = false, bench = false, offset = 0;
  text.split('\n').forEach((line, i) => {
    const start = offset;
    offset += line.length + 1;
    if (/^\s*```/.test(line)) { fence = !fence; return; }
    if (/^<!-- bench: /.test(line.trim())) bench = true;
    if (line.trim() === '<!-- /bench -->') bench = false;
    if (fence || bench) return;
    for (const m of line.matchAll(FIGURE)) {
      const from = start + m.index, to = from + m[0].length;
      if (allowed.some(([a, b]) => a <= from && to <= b)) continue;
      /* the mark follows the figure's (a range's last) number */
      const nums = [...m[0].matchAll(new RegExp(NUM, 'g'))];
      const last = nums[nums.length - 1];
      if (MARK.test(line.slice(m.index + last.index + last[0].length))) continue;
      bad.push(`${name}:${i + 1}: ${m[0]}`);
    }
  });
  return bad;
}

test('measured figures on the newcomer\'s pages are marked with their result file or are specification values', () => {
  const bad = PAGES.flatMap((p) => unmarkedFigures(p, readFileSync(join(ROOT, p), 'utf8')));
  assert.deepEqual(bad, []);
});

test('the figure rule can fail', () => {
  assert.deepEqual(unmarkedFigures('x.md', 'it took 12.5 ms a call\n'), ['x.md:1: 12.5 ms']);
  assert.deepEqual(unmarkedFigures('x.md', 'it took 12.5<!-- from tests/bench/results/a.md "k" 2 --> ms\n'), []);
  assert.deepEqual(unmarkedFigures('x.md', 'it took 12.5 ms<!-- from tests/bench/results/a.md "k" -->\n'), []);
  /* another number between the figure and the mark: the mark is not its */
  assert.deepEqual(unmarkedFigures('x.md', 'it took 12.5 ms and 3 runs<!-- from r.md "k" -->\n'), ['x.md:1: 12.5 ms']);
  assert.deepEqual(unmarkedFigures('x.md', 'p99 16 to 49 ms, 0.3 CPU s, 252 PATCH/s, 2.5 % of the peak, 1,774× real time\n').length, 5);
  assert.deepEqual(unmarkedFigures('x.md', '```sh\nsleep 5 ms\n```\n<!-- bench: f table 1 -->\n| 3 ms |\n<!-- /bench -->\n'), []);
  const spec = [['x.md', 'at most 0.1 CPU s']];
  assert.deepEqual(unmarkedFigures('x.md', 'the target: at most 0.1 CPU s; it took 0.2 CPU s\n', spec), ['x.md:1: 0.2 CPU s']);
  assert.deepEqual(unmarkedFigures('x.md', 'nothing here\n', spec), ['x.md: the specification value "at most 0.1 CPU s" is not on the page (remove it from SPEC)']);
});
