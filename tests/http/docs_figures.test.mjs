// SPDX-License-Identifier: GPL-3.0-or-later
// Measured figures on the pages come from a result file or are not there.
// On README.md, every page of docs/ and docs/log/ (the history), a figure is
// a number followed by ms, µs, CPU s, PATCH/s, "% of the peak", "× real
// time" (the narrow kinds), or by a plain % or a wall time (s, min, h and
// their words). Each is either
// - marked: a `<!-- from tests/bench/results/FILE.md "KEY" N -->` comment
//   follows it on its line with no other number between (tests/docs_bench.py
//   --check compares it with that file, as it does the bench tables), or
// - inside a bench table block (<!-- bench: ... --> ... <!-- /bench -->), a
//   fenced block or an inline code span (a command or a setting as typed), or
// - a setting or default by its form (`dt = 1e-4 s`, an option's value in
//   brackets, "default 4 s", a time in powers of ten: a step), or
// - a specification value (a setting, default, limit, target or a
//   definition) listed with the words around it in SPEC (one page) or
//   EVERYWHERE (any page), each with its source (tests/http/docs_spec.mjs).
// Anything else fails: mark it, link the result page and leave the figure
// out, or put it in words. PENDING caps the unresolved plain percentages and
// wall times of the pages not yet gone through (the narrow kinds have no
// cap); a page's cap only goes down. Conventions: docs/testing.md
// ("Examples in the documentation").
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { SPEC, EVERYWHERE, PENDING } from './docs_spec.mjs';

const ROOT = fileURLToPath(new URL('../..', import.meta.url));

// README.md, docs/*.md and docs/log/*.md
export const PAGES = ['README.md', ...['docs', 'docs/log'].flatMap((d) => readdirSync(join(ROOT, d))
  .filter((f) => f.endsWith('.md')).sort().map((f) => `${d}/${f}`))];

const NUM = String.raw`(?<![\w.])\d+(?:,\d{3})*(?:\.\d+)?(?:e[-+]?\d+)?`;
// a number, optionally a range "16 to 49" / "5–7", then the unit: the narrow
// kinds, or a plain % or a wall time after a space (group 1 set)
const NARROW = String.raw`ms\b|µs\b|CPU s\b|CPU seconds\b|PATCH/s|% of the peak|[×x] real time`;
const WIDE = String.raw`\s*%|\s+(?:s|min|minutes?|seconds?|h|hours?)\b`;
const FIGURE = new RegExp(String.raw`${NUM}(?:\s*(?:to|–|-)\s*${NUM})?(?:\s*(?:${NARROW})|(${WIDE}))`, 'g');
// A setting or default by its form, before the figure: its name and " = "
// (`dt = 1e-4 s`, `scene.settle` = 0.6 s; a name of two letters or more, so
// `t = 3 s`, a moment, is not one), an option followed by its value in
// brackets (`--request-timeout` (10 s)), or "default"; or after it: "by
// default". The program's --help and the OpenAPI document are their source.
const SETTING = /(?:(?:^|[^\w.])[A-Za-z_][A-Za-z0-9_.]+|`[^`]+`) = $|`[^`]+` \($|\bdefault:? $|\bdefaults? to $/;
const SETTING_AFTER = /^ by default\b/;
// a time in powers of ten (1.25e-4 s, 1e-7 s) is a step or a tolerance
const STEP = /^\d+(?:\.\d+)?e-\d+\s+s$/;
const MARK = /^[^\d<]*<!-- from \S+ "[^"]+"(?: \d+)? -->/;

export { SPEC, EVERYWHERE, PENDING };

// Spaces for newlines, offsets kept: a listed phrase may break across lines.
function flat(text) {
  return text.replace(/\n/g, ' ');
}
// The text with each inline code span (which may break across one line) in
// spaces, offsets and newlines kept: a command or a setting as typed, or a
// program's output quoted, is not a figure of the prose; nor is a comment
// (a mark's key).
function withoutCode(text) {
  return text.replace(/<!--[\s\S]*?-->|`[^`\n]*(?:\n[^`\n]*)?`/g, (m) => m.replace(/[^\n]/g, ' '));
}

// The unmarked measured-looking figures of one page: ["page:line: text"],
// the plain percentages and wall times among them also in .wide.
export function unmarkedFigures(name, text, spec = SPEC, everywhere = EVERYWHERE) {
  const bad = [];
  Object.defineProperty(bad, 'wide', { value: [], enumerable: false });
  const allowed = [];
  const flatText = flat(text);
  for (const [page, words] of spec) {
    if (page !== name) continue;
    const w = flat(words);
    let at = flatText.indexOf(w);
    if (at < 0) bad.push(`${name}: the specification value "${words}" is not on the page (remove it from SPEC)`);
    while (at >= 0) { allowed.push([at, at + w.length]); at = flatText.indexOf(w, at + 1); }
  }
  for (const [words] of everywhere) {
    let at = flatText.indexOf(words);
    while (at >= 0) { allowed.push([at, at + words.length]); at = flatText.indexOf(words, at + 1); }
  }
  let fence = false, bench = false, offset = 0;
  const rawLines = text.split('\n');
  /* fenced blocks out first, so that their backticks pair with nothing */
  let inFence = false;
  const unfenced = rawLines.map((l) => {
    if (/^\s*```/.test(l)) { inFence = !inFence; return ' '.repeat(l.length); }
    return inFence ? ' '.repeat(l.length) : l;
  }).join('\n');
  const lines = withoutCode(unfenced).split('\n');
  rawLines.forEach((raw, i) => {
    const start = offset;
    offset += raw.length + 1;
    if (/^\s*```/.test(raw)) { fence = !fence; return; }
    if (/^<!-- bench: /.test(raw.trim())) bench = true;
    if (raw.trim() === '<!-- /bench -->') bench = false;
    if (fence || bench) return;
    const line = lines[i];
    for (const m of line.matchAll(FIGURE)) {
      const from = start + m.index, to = from + m[0].length;
      if (allowed.some(([a, b]) => a <= from && to <= b)) continue;
      if (STEP.test(m[0])) continue;
      if (SETTING.test(raw.slice(0, m.index)) || SETTING_AFTER.test(raw.slice(m.index + m[0].length))) continue;
      /* the mark follows the figure's (a range's last) number */
      const nums = [...m[0].matchAll(new RegExp(NUM, 'g'))];
      const last = nums[nums.length - 1];
      if (MARK.test(raw.slice(m.index + last.index + last[0].length))) continue;
      const msg = `${name}:${i + 1}: ${m[0]}`;
      bad.push(msg);
      if (m[1] !== undefined) bad.wide.push(msg);
    }
  });
  return bad;
}

// Everything wrong on one page, the pending cap applied: [messages]
export function pageProblems(name, text, pending = PENDING, spec = SPEC, everywhere = EVERYWHERE) {
  const bad = unmarkedFigures(name, text, spec, everywhere);
  const cap = pending.get(name) ?? 0;
  const narrow = bad.filter((b) => !bad.wide.includes(b));
  if (bad.wide.length <= cap) return narrow;
  return [...narrow, ...bad.wide, ...(cap ? [`${name}: ${bad.wide.length} unresolved plain percentages or wall times, PENDING allows ${cap}`] : [])];
}

test('measured figures on the pages are marked with their result file or are specification values', () => {
  const texts = PAGES.map((p) => [p, readFileSync(join(ROOT, p), 'utf8')]);
  const bad = texts.flatMap(([p, t]) => pageProblems(p, t));
  /* every EVERYWHERE phrase is on some page, every PENDING page exists */
  for (const [words] of EVERYWHERE)
    if (!texts.some(([, t]) => flat(t).includes(words))) bad.push(`EVERYWHERE: "${words}" is on no page (remove it)`);
  for (const p of PENDING.keys()) if (!PAGES.includes(p)) bad.push(`PENDING: no page ${p}`);
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

test('the rule for plain percentages and wall times can fail', () => {
  const none = [];
  /* an unmarked plain percentage and wall time are caught, a range as one */
  assert.deepEqual(unmarkedFigures('x.md', 'it was 12 % faster and took 2.3 s, then 3 min and 1–2 h\n', none, none),
    ['x.md:1: 12 %', 'x.md:1: 2.3 s', 'x.md:1: 3 min', 'x.md:1: 1–2 h']);
  assert.deepEqual(unmarkedFigures('x.md', '12%, about 5 minutes, 4 seconds\n', none, none).length, 3);
  /* a mark, a setting, a default, a code span, a listed phrase pass */
  assert.deepEqual(unmarkedFigures('x.md', 'it took 2.3<!-- from tests/bench/results/a.md "k" --> s\n', none, none), []);
  assert.deepEqual(unmarkedFigures('x.md', 'at dt = 1e-4 s, `scene.settle` = 0.6 s, `--request-timeout` (10 s)\n', none, none), []);
  assert.deepEqual(unmarkedFigures('x.md', '(default 4 s), 0.6 s by default, `--duration 3 s`, `a\n5 %` b\n', none, none), []);
  assert.deepEqual(unmarkedFigures('x.md', 'all within 1 % of the\nreference, but 3 % at 70°\n', none, [['within 1 %', 's']]), ['x.md:2: 3 %']);
  /* a moment is no setting; 404s and 37s are no times */
  assert.deepEqual(unmarkedFigures('x.md', 'at t = 3.2 s; 404s and issue 37s round\n', none, none), ['x.md:1: 3.2 s']);
  /* the pending cap: at most N unresolved, more fails naming them */
  const two = 'took 2 s and 3 %\n';
  assert.deepEqual(pageProblems('x.md', two, new Map([['x.md', 2]]), none, none), []);
  assert.deepEqual(pageProblems('x.md', two, new Map([['x.md', 1]]), none, none),
    ['x.md:1: 2 s', 'x.md:1: 3 %', 'x.md: 2 unresolved plain percentages or wall times, PENDING allows 1']);
  assert.deepEqual(pageProblems('x.md', two, new Map(), none, none), ['x.md:1: 2 s', 'x.md:1: 3 %']);
  /* the narrow kinds have no cap */
  assert.deepEqual(pageProblems('x.md', 'took 5 ms\n', new Map([['x.md', 9]]), none, none), ['x.md:1: 5 ms']);
});
