// SPDX-License-Identifier: GPL-3.0-or-later
// Measured figures on the task pages come from a result file or are not
// there. On README.md and every page of docs/ (not docs/log/, the
// measurement logs the pages link), a figure of a narrow, reliable kind (a number followed by
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
import { readFileSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = fileURLToPath(new URL('../..', import.meta.url));

// README.md and docs/*.md; docs/log/*.md are measurement logs and are not read
export const PAGES = ['README.md', ...readdirSync(join(ROOT, 'docs')).filter((f) => f.endsWith('.md'))
  .sort().map((f) => `docs/${f}`)];

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
  /* the task pages beyond the newcomer's path */
  ['docs/benchmarks.md', 'cut at 60 CPU s each'],
  ['docs/cli.md', '[The curve\nat 0.1 CPU s]'],
  /* the budgets' clocks: CPU_READ_EVERY, COST_WINDOW_CPU, COST_WINDOW_T (server/session/session_int.h) */
  ['docs/budgets.md', '(at most every 10 ms), so a session pauses at most 10 ms of CPU past its grant'],
  ['docs/budgets.md', 'over windows of 50 ms\nof CPU or 2 simulated seconds'],
  ['docs/budgets.md', 'first\nwindow (50 ms of CPU) replaces it'],
  /* a sample's interval at the stream's rate */
  ['docs/cluster.md', 'the next sample (about 100 ms at `rate=10`'],
  /* the latencies the bench adds, and the sample interval of the example's stream */
  ['docs/control-remote.md', 'with 100 and 200 ms added before each command'],
  ['docs/control-remote.md', 'the dead time is about one sample, 40 ms'],
  ['docs/control-remote.md', 'ms for 100 ms added'],
  ['docs/control-remote.md', 'ms for 200 ms added'],
  ['docs/control-remote.md', 'Up to 200 ms the loop'],
  ['docs/control-remote.md', 'more than 100 ms of delay'],
  ['docs/control-remote.md', 'one sample interval (40 ms here)'],
  ['docs/control-remote.md', 'for every 40 ms beyond'],
  /* PACE_MIN and PUBLISH_EVERY (server/session/worker.c) */
  ['docs/development.md', '`PACE_MIN` (20 ms)'],
  ['docs/development.md', 'session every 10 ms'],
  ['docs/performance.md', 'woke every 20 ms (batches of samples due within the next 20 ms)'],
  ['docs/performance.md', 'and at least 20 ms'],
  ['docs/performance.md', 'not up to 20 ms early'],
  /* contact periods the step rule computes: 2 pi sqrt(m_n / k_c) (the Hertzian one at its tangent stiffness) */
  ['docs/machine-zoo.md', 'm_n = 0.5 kg) | 4.4 ms'],
  ['docs/machine-zoo.md', '| k_c = 1e7 | 1.4 ms'],
  ['docs/machine-zoo.md', '| k_c = 3e7 | 0.81 ms'],
  ['docs/machine-zoo.md', '| k_c = 1e8 | 0.44 ms'],
  ['docs/machine-zoo.md', '(8 layers) | 3.6 ms'],
  ['docs/machine-zoo.md', 'M_ut = 80) | 4.4 ms'],
  ['docs/machine-zoo.md', '| tol = 0.005 | 4.4 ms'],
  /* the references' convergence threshold (tests/bench/zoo_ref.sh) */
  ['docs/machine-zoo.md', 'differ by more\nthan 0.1 % of the peak also'],
  /* tests/tether.mjs's poll */
  ['docs/testing.md', 'ends itself within 250 ms of its runner'],
  /* tests/web/picker.test.mjs's sampling */
  ['docs/testing.md', 'sampled every 100 ms for 3 s'],
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

test('measured figures on the task pages are marked with their result file or are specification values', () => {
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
