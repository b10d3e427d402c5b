// SPDX-License-Identifier: GPL-3.0-or-later
// Pages a user reads in one sitting: README.md and every page of docs/
// (docs/log/ included) has at most 300 lines, README.md at most 200, and
// no paragraph of more than 150 words. A paragraph is a run of non-blank
// lines outside code blocks; a heading, an HTML comment line and a table
// row end one; each list item is one of its own, and so is each table row.
// An inline HTML comment (a figure's `<!-- from ... -->` mark) is no words.
// Generated result pages (tests/bench/results/*.md, written by `make bench`)
// are not documents of docs/ and are not checked. The conventions are in
// docs/testing.md ("Examples in the documentation").
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync, readdirSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = fileURLToPath(new URL('../..', import.meta.url));
const MAX_LINES = 300;
const MAX_README_LINES = 200;
const MAX_WORDS = 150;

// Pages that do not meet the rule yet, each with the reason; a page listed
// here that meets it fails the test, so the list only shrinks.
export const EXEMPT = new Map([]);

// README.md, docs/*.md and docs/log/*.md, as [path relative to ROOT, text]
export function pages(root = ROOT) {
  const names = ['README.md'];
  for (const dir of ['docs', 'docs/log']) {
    if (!existsSync(join(root, dir))) continue;
    names.push(...readdirSync(join(root, dir)).filter((f) => f.endsWith('.md')).sort().map((f) => `${dir}/${f}`));
  }
  return names.map((n) => [n, readFileSync(join(root, n), 'utf8')]);
}

// The paragraphs of a Markdown text: {line, words}.
export function paragraphs(text) {
  const out = [];
  let cur = null, fence = false;
  const flush = () => { if (cur) out.push(cur); cur = null; };
  text.split('\n').forEach((l, i) => {
    if (/^\s*```/.test(l)) { flush(); fence = !fence; return; }
    if (fence) return;
    if (!l.trim() || /^#{1,6}\s/.test(l) || /^\s*<!--.*-->\s*$/.test(l)) { flush(); return; }
    /* an inline comment (a figure's source mark) is not read */
    const n = l.replace(/<!--.*?-->/g, ' ').split(/\s+/).filter(Boolean).length;
    if (/^\s*\|/.test(l)) { flush(); out.push({ line: i + 1, words: n }); return; }
    if (/^\s*([-*+]|\d+[.)])\s/.test(l)) flush();
    if (!cur) cur = { line: i + 1, words: 0 };
    cur.words += n;
  });
  flush();
  return out;
}

// What breaks the rule in one page: [messages].
export function shapeProblems(name, text) {
  const bad = [];
  const lines = text.replace(/\n$/, '').split('\n').length;
  const max = name === 'README.md' ? MAX_README_LINES : MAX_LINES;
  if (lines > max) bad.push(`${name}: ${lines} lines (at most ${max}: split the page by task)`);
  for (const p of paragraphs(text)) {
    if (p.words > MAX_WORDS) bad.push(`${name}:${p.line}: a paragraph of ${p.words} words (at most ${MAX_WORDS})`);
  }
  return bad;
}

test('every page is at most 300 lines (README.md 200) with no paragraph over 150 words', () => {
  const bad = [];
  const found = new Set();
  for (const [name, text] of pages()) {
    found.add(name);
    const p = shapeProblems(name, text);
    if (EXEMPT.has(name)) {
      if (!p.length) bad.push(`${name} meets the rule now: remove its exemption (${EXEMPT.get(name)})`);
      continue;
    }
    bad.push(...p);
  }
  for (const name of EXEMPT.keys()) if (!found.has(name)) bad.push(`${name}: exempt but no such page`);
  assert.deepEqual(bad, []);
});

test('the shape rules can fail', () => {
  const long = Array.from({ length: 301 }, (_, i) => `line ${i}`).join('\n\n').split('\n').slice(0, 301).join('\n');
  assert.equal(shapeProblems('docs/x.md', long).length, 1);
  assert.deepEqual(shapeProblems('docs/x.md', long.split('\n').slice(0, 300).join('\n')), []);
  assert.equal(shapeProblems('README.md', long.split('\n').slice(0, 201).join('\n')).length, 1);
  const words = (n) => Array.from({ length: n }, (_, i) => `w${i}`).join(' ');
  assert.deepEqual(shapeProblems('docs/x.md', `# T\n\n${words(150)}\n`), []);
  assert.deepEqual(shapeProblems('docs/x.md', `# T\n\n${words(100)}\n${words(51)}\n`), ['docs/x.md:3: a paragraph of 151 words (at most 150)']);
  /* list items, table rows and code blocks are apart */
  assert.deepEqual(shapeProblems('docs/x.md', `- ${words(100)}\n- ${words(100)}\n| ${words(100)} |\n| ${words(100)} |\n`), []);
  assert.deepEqual(shapeProblems('docs/x.md', `${words(100)}\n\`\`\`sh\n${words(100)}\n\`\`\`\n${words(50)}\n`), []);
  assert.equal(shapeProblems('docs/x.md', `| ${words(160)} |\n`).length, 1);
  assert.deepEqual(shapeProblems('docs/x.md', `${words(148)} 2.5<!-- from tests/bench/results/a.md "k" 3 --> ms\n`), []);
});
