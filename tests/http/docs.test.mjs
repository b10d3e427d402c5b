// SPDX-License-Identifier: GPL-3.0-or-later
// The documents cannot drift from the program: every sh and python block of
// README.md, docs/*.md and docs/log/*.md runs against the real daemon
// (started with a token, as `make run` starts it) through a validating
// proxy (Prism: a request or an answer that breaks the OpenAPI document
// fails the example), every `<!-- output -->` block is compared with what
// its example printed, figures in examples' comments are elided, and every
// relative link between the documents resolves to a file and a heading.
// The conventions are written down in docs/testing.md
// ("Examples in the documentation").
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFile } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, relative, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { startDaemon, tokenFile, req, until, SLOW } from './lib.mjs';
import { startPrism } from './prism.mjs';

const ROOT = fileURLToPath(new URL('../..', import.meta.url));
const BUILD = resolve(ROOT, process.env.BUILD || 'build');
const TOKEN = 'docs-example-token-0123456789abcdef';
const AUTH = { Authorization: `Bearer ${TOKEN}` };
const run = promisify(execFile);

// README.md and every page of docs/, as [path relative to ROOT, text]
// (docs/log/, the measurement logs, included)
export function documents(root = ROOT) {
  const names = ['README.md'];
  for (const dir of ['docs', 'docs/log']) {
    if (!existsSync(join(root, dir))) continue;
    names.push(...readdirSync(join(root, dir)).filter((f) => f.endsWith('.md')).sort().map((f) => `${dir}/${f}`));
  }
  return names.map((n) => [n, readFileSync(join(root, n), 'utf8')]);
}

// The fenced blocks of a Markdown text: {lang, code, line, mark} where mark
// is the HTML comment on the line before the fence (after blank lines), if any.
export function blocks(text) {
  const lines = text.split('\n');
  const out = [];
  for (let i = 0; i < lines.length; i++) {
    const open = lines[i].match(/^```(\w*)\s*$/);
    if (!open) continue;
    let j = i + 1;
    while (j < lines.length && !/^```\s*$/.test(lines[j])) j++;
    let k = i - 1;
    while (k >= 0 && lines[k].trim() === '') k--;
    const mark = k >= 0 && /^<!--.*-->$/.test(lines[k].trim()) ? lines[k].trim() : null;
    out.push({ lang: open[1], code: lines.slice(i + 1, j).join('\n'), line: i + 1, mark });
    i = j;
  }
  return out;
}

// The examples of one document: runnable blocks with the output block that
// follows each, if any. Throws on a skip mark without its reason.
export function examples(name, text) {
  const out = [];
  for (const b of blocks(text)) {
    const where = `${name}:${b.line}`;
    if (b.mark && /example:\s*skip/.test(b.mark)) {
      assert.match(b.mark, /example:\s*skip\s*\(\S[^)]*\)/, `${where}: a skipped example says why: <!-- example: skip (REASON) -->`);
      continue;
    }
    if (b.lang === 'text' && b.mark === '<!-- output -->') {
      assert.ok(out.length, `${where}: an output block follows an example`);
      out[out.length - 1].output = b.code;
      continue;
    }
    if (b.mark && /example:\s*direct/.test(b.mark))
      assert.match(b.mark, /example:\s*direct\s*\(\S[^)]*\)/, `${where}: a direct example says why: <!-- example: direct (REASON) -->`);
    const direct = Boolean(b.mark && /example:\s*direct/.test(b.mark));
    if (['sh', 'bash', 'python'].includes(b.lang)) out.push({ ...b, where, direct });
  }
  return out;
}

// `…` stands for any text within a line; a line that is only `…` for any
// number of lines.
export function matchesOutput(actual, expected) {
  const a = actual.replace(/\n+$/, '').split('\n');
  const e = expected.replace(/\n+$/, '').split('\n');
  const line = (p) => new RegExp('^' + p.split('…').map((s) => s.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')).join('.*') + '$');
  const m = (i, j) => {
    if (j === e.length) return i === a.length;
    if (e[j].trim() === '…') { for (let k = i; k <= a.length; k++) if (m(k, j + 1)) return true; return false; }
    return i < a.length && line(e[j]).test(a[i]) && m(i + 1, j + 1);
  };
  return m(0, 0);
}

// Numbers with three or more decimals in the comments of a shell example
// that are not elided with `…`.
export function unelidedFigures(code) {
  const bad = [];
  for (const l of code.split('\n')) {
    const c = l.match(/(^|\s)#\s(.*)$/);
    if (!c) continue;
    for (const n of c[2].matchAll(/\d+\.\d{3,}(…)?/g)) if (!n[1]) bad.push(n[0]);
  }
  return bad;
}

// GitHub's anchors of a Markdown text's headings (outside code blocks).
export function anchors(text) {
  const seen = new Map();
  const out = new Set();
  let fence = false;
  for (const l of text.split('\n')) {
    if (/^```/.test(l)) fence = !fence;
    const h = !fence && l.match(/^#{1,6}\s+(.*?)\s*#*\s*$/);
    if (!h) continue;
    let slug = h[1].toLowerCase().replace(/[^\p{L}\p{N}\s_-]/gu, '').replace(/ /g, '-');
    const n = seen.get(slug) || 0;
    seen.set(slug, n + 1);
    out.add(n ? `${slug}-${n}` : slug);
  }
  return out;
}

// Every relative link of one document that does not resolve: [text] messages.
export function brokenLinks(name, text, root = ROOT) {
  const bad = [];
  const body = text.replace(/^```[\s\S]*?^```/gm, '').replace(/`[^`\n]*`/g, '');
  for (const m of body.matchAll(/\]\(([^)\s]+)\)/g)) {
    const target = m[1];
    if (/^[a-z]+:/i.test(target)) continue;
    const [file, anchor] = target.split('#');
    const path = file ? resolve(root, dirname(name), file) : resolve(root, name);
    if (!existsSync(path)) { bad.push(`${name}: ${target}: no such file`); continue; }
    if (anchor !== undefined && path.endsWith('.md') && !anchors(readFileSync(path, 'utf8')).has(anchor))
      bad.push(`${name}: ${target}: no heading #${anchor} in ${relative(root, path)}`);
  }
  return bad;
}

// The examples reach the daemon through Prism, a validating proxy
// (prism.mjs): a request or an answer of an example that breaks the
// OpenAPI document is a violation, which fails the example. An example
// that must reach the daemon itself (a request the document refuses on
// purpose, a stream Prism would hold until it ends) says why, right
// before it: <!-- example: direct (REASON) -->.
let d, base, prism, viaProxy, direct;
before(async () => {
  d = await startDaemon(['--token-file', tokenFile(TOKEN)]);
  base = d.base;
  direct = base.replace(/^http:\/\//, '');
  const doc = await req(base, 'GET', '/api/v1/openapi.json', undefined, AUTH);
  assert.equal(doc.status, 200);
  prism = await startPrism(doc.text, base);
  viaProxy = prism.url.replace(/^http:\/\//, '');
});
after(async () => { prism?.stop(); await d?.stop(); });

async function finished(path, done, ms) {
  let last;
  await until(async () => { last = (await req(base, 'GET', path, undefined, AUTH)).body; return done.includes(last.state); },
    ms, `${path} to end`);
  return last;
}

// A fresh resource for each placeholder an example names, ended, so that its
// answers are what the document shows.
const MAKE = {
  ID: async () => {
    const r = await req(base, 'POST', '/api/v1/sessions', { params: { beta: 30, rotation: 'cw' }, pace: 'max', until: 4 }, AUTH);
    assert.equal(r.status, 201);
    await finished(`/api/v1/sessions/${r.body.id}`, ['finished'], 60000);
    return r.body.id;
  },
  EID: async () => {
    const r = await req(base, 'POST', '/api/v1/experiments', { session: { scene: { drive: 'ideal', columns: 1, layers: 2 } },
      schedule: [{ beta: 38, until: 1 }, { beta: 128, until: 2 }], keep_session: true }, AUTH);
    assert.equal(r.status, 201, JSON.stringify(r.body));
    await finished(`/api/v1/experiments/${r.body.id}`, ['done'], 60000);
    return r.body.id;
  },
  SID: async () => {
    const r = await req(base, 'POST', '/api/v1/sweeps', { beta: [30, 150], t_end: 2 }, AUTH);
    assert.equal(r.status, 202);
    await finished(`/api/v1/sweeps/${r.body.id}`, ['done'], 60000);
    return r.body.id;
  },
  FID: async () => {
    const r = await req(base, 'POST', '/api/v1/fits', { scene: { drive: 'ideal', columns: 1, layers: 2 }, free: ['e'],
      points: [{ beta: 30, rotation: 'cw', v: 0.1 }, { beta: 60, rotation: 'cw', v: 0.07 }], t_end: 2, curve_step: 0, max_iter: 3 }, AUTH);
    assert.equal(r.status, 202, JSON.stringify(r.body));
    await finished(`/api/v1/fits/${r.body.id}`, ['done', 'failed'], 120000);
    return r.body.id;
  },
};

async function prepare(code, hostport) {
  let text = code.replace(/\b(localhost|127\.0\.0\.1):8080\b/g, hostport);
  const kinds = { sessions: 'ID', experiments: 'EID', sweeps: 'SID', fits: 'FID' };
  for (const [route, word] of Object.entries(kinds)) {
    const re = new RegExp(`/${route}/${word}\\b`, 'g');
    if (re.test(text)) {
      const id = await MAKE[word]();
      text = text.replace(re, `/${route}/${id}`);
    }
  }
  return text;
}

function workdir() {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-docs-'));
  symlinkSync(BUILD, join(dir, 'build'));
  symlinkSync(join(ROOT, 'docs'), join(dir, 'docs')); // the examples' scripts (docs/examples/)
  mkdirSync(join(dir, 'var'));
  writeFileSync(join(dir, 'var', 'token'), TOKEN + '\n', { mode: 0o600 });
  return dir;
}

async function runExample(ex) {
  const hostport = ex.direct ? direct : viaProxy;
  const code = await prepare(ex.code, hostport);
  const cwd = workdir();
  const env = { ...process.env, CONVSIM_URL: `http://${hostport}`, CONVSIM_TOKEN: TOKEN, AUTH: `Authorization: Bearer ${TOKEN}` };
  const opts = { cwd, env, timeout: 240000 * SLOW, maxBuffer: 64 << 20 };
  if (ex.lang === 'python') {
    writeFileSync(join(cwd, 'example.py'), code);
    return (await run('python3', ['example.py'], opts)).stdout;
  }
  const prelude = 'set -eo pipefail\ncurl() { command curl --fail-with-body --max-time 60 "$@"; }\n';
  return (await run('bash', ['-c', prelude + code], opts)).stdout;
}

const DOCS = documents();

test('every relative link between the documents resolves (file and #anchor)', () => {
  const bad = DOCS.flatMap(([n, t]) => brokenLinks(n, t));
  assert.deepEqual(bad, []);
});

// Operations of the OpenAPI document that the API pages (API_PAGES) do not
// name (the method on a line with the path, a path parameter as any word),
// and operations they name that the document lacks.
export function apiDrift(doc, text) {
  const ops = Object.entries(doc.paths).flatMap(([p, item]) => Object.keys(item).map((m) => [m.toUpperCase(), p]));
  const re = (p) => new RegExp(p.replace(/[.*+?^$()|[\]\\]/g, '\\$&').replace(/\{[^}]+\}/g, '[A-Za-z0-9_-]+') + '(?![A-Za-z0-9_/-])');
  const lines = text.split('\n');
  const missing = ops.filter(([m, p]) => !lines.some((l) => re(p).test(l) && (m === 'GET' || new RegExp(`\\b${m}\\b`).test(l))))
    .map(([m, p]) => `${m} ${p}`);
  const named = [...text.matchAll(/\b(GET|POST|PATCH|PUT|DELETE) (\/(?:api\/v1\/)?[A-Za-z0-9_./{}-]+)/g)]
    .filter(([, m, p]) => !ops.some(([om, op]) => om === m && re(op).test(p)))
    .map(([, m, p]) => `${m} ${p}`);
  return { missing, named };
}

// The API reference: docs/api.md and the pages it is split into.
export const API_PAGES = ['docs/api.md', 'docs/api-errors.md', 'docs/api-streams.md', 'docs/api-jobs.md'];

test('the API pages and the served OpenAPI document name the same operations', async () => {
  const doc = (await req(base, 'GET', '/api/v1/openapi.json', undefined, AUTH)).body;
  const text = API_PAGES.map((p) => readFileSync(join(ROOT, p), 'utf8')).join('\n');
  assert.deepEqual(apiDrift(doc, text), { missing: [], named: [] });
  /* and it can fail both ways */
  const less = apiDrift(doc, text.replace(/PATCH/g, 'PUT'));
  assert.ok(less.missing.includes('PATCH /api/v1/sessions/{id}'), JSON.stringify(less));
  assert.deepEqual(apiDrift(doc, text + '\nPOST /api/v1/sessions/ID/rewind\n').named, ['POST /api/v1/sessions/ID/rewind']);
});

// Benchmark tables between <!-- bench: FILE table N --> and <!-- /bench -->
// are the N-th table of `make bench`'s output file, line for line, and a
// figure marked <!-- from FILE "KEY" N --> is the N-th number of FILE's line
// with KEY (tests/docs_bench.py writes them, --check compares, and checks
// that each result page says its command, date, build and machine;
// --self-test shows that a wrong figure, key or number fails, and a page
// without its build).
test('benchmark tables and marked figures in the documents are those of the bench results', async () => {
  const r = await run('python3', [join(ROOT, 'tests/docs_bench.py'), '--check']).catch((e) => e);
  assert.equal(r.code ?? 0, 0, `${r.stdout}${r.stderr ?? ''}`);
  assert.match(r.stdout, /docs_bench: [1-9]\d* tables and [1-9]\d* figures from the bench results, 0 differ/);
  const t = await run('python3', [join(ROOT, 'tests/docs_bench.py'), '--self-test']).catch((e) => e);
  assert.equal(t.code ?? 0, 0, `${t.stdout}${t.stderr ?? ''}`);
  assert.match(t.stdout, /docs_bench self-test: 6 of 6/);
  assert.match(t.stdout, /docs_bench provenance self-test: 3 of 3/);
});

test('the link checker sees a missing file and a missing anchor', () => {
  const bad = brokenLinks('README.md', '[a](docs/nothing-here.md) [b](docs/api.md#no-such-heading) [c](docs/api.md#sessions)');
  assert.equal(bad.length, 2, bad.join('\n'));
  assert.ok(anchors('## The 1 % gate\n## Load: `make load`\n## A\n## A').has('the-1--gate'));
  assert.ok(anchors('## Load: `make load`').has('load-make-load'));
  assert.ok(anchors('## A\n## A').has('a-1'));
});

test('an example goes through the validating proxy unless marked direct, with a reason', () => {
  const fence = (mark) => `${mark}\n\`\`\`sh\ncurl -s localhost:8080/api/v1/health\n\`\`\`\n`;
  assert.equal(examples('x.md', fence(''))[0].direct, false);
  assert.equal(examples('x.md', fence('<!-- example: direct (a request the document refuses) -->'))[0].direct, true);
  assert.throws(() => examples('x.md', fence('<!-- example: direct -->')), /a direct example says why/);
});

test('output blocks and elided figures: the rules can fail', () => {
  assert.ok(matchesOutput('v = 0.1527 +- 0.0012 m/s\nx\ny\n', 'v = 0.15… +- 0.001… m/s\n…'));
  assert.ok(!matchesOutput('v = 0.1527 +- 0.0012 m/s\n', 'v = 0.1526 +- 0.0019 m/s'));
  assert.ok(!matchesOutput('a\nb\n', 'a'));
  assert.deepEqual(unelidedFigures('curl x  # {"v":0.15258…, "u":0.0019}'), ['0.0019']);
  assert.deepEqual(unelidedFigures('curl x  # 204'), []);
});

for (const [name, text] of DOCS) {
  for (const ex of examples(name, text)) {
    test(`${ex.where}: the ${ex.lang} example runs${ex.output ? ' and prints what the document shows' : ''}`,
      { timeout: 300000 * SLOW }, async () => {
        if (ex.lang !== 'python') assert.deepEqual(unelidedFigures(ex.code), [], 'figures in comments are elided with …');
        let stdout;
        try {
          stdout = await runExample(ex);
        } catch (e) {
          assert.fail(`${ex.where}: ${e.message}\nstdout: ${String(e.stdout).slice(0, 2000)}\nstderr: ${String(e.stderr).slice(0, 2000)}`);
        }
        if (ex.output) assert.ok(matchesOutput(stdout, ex.output), `${ex.where}: printed\n${stdout}\nthe document shows\n${ex.output}`);
      });
  }
}
