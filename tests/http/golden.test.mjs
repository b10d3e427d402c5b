// SPDX-License-Identifier: GPL-3.0-or-later
// The job routes' answers, byte for byte: sweeps, fits and experiments
// (create, get as JSON and CSV, list as JSON and CSV, delete, the errors),
// the files each leaves in the data directory, the same after a restart on
// that directory, and a replica's list merged with its peer's. Everything
// is compared with tests/http/golden/jobs.json, recorded once from the
// daemon as it was before its jobs shared one path (GOLDEN_RECORD=1
// writes it again). Ids are replaced by their kind and rank of appearance
// and the framed files' checksums by zeros (they cover the ids); what
// depends on the moment a request lands is named below and normalised.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { createHash } from 'node:crypto';
import { mkdtempSync, readFileSync, readdirSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { startDaemon, req, until, CHEAP, SLOW } from './lib.mjs';

const GOLDEN = fileURLToPath(new URL('./golden/jobs.json', import.meta.url));
const RECORD = process.env.GOLDEN_RECORD === '1';
const JSON_CT = { 'Content-Type': 'application/json' };
const HEADERS = ['content-type', 'location', 'allow', 'vary', 'cache-control', 'retry-after'];

const dir = mkdtempSync(join(tmpdir(), 'convsim-golden-'));
const daemons = [];
after(async () => {
  for (const d of daemons) await d.stop();
  rmSync(dir, { recursive: true, force: true });
});

// ids in order of appearance, each named by its kind and rank
const ids = new Map();
const nameId = (id, kind) => {
  if (id && !ids.has(id)) ids.set(id, `<${kind}-${[...ids.values()].filter((v) => v.startsWith(`<${kind}-`)).length + 1}>`);
};
// and a fit's CPU and wall time
const normalise = (text) => {
  let out = text;
  for (const [id, name] of ids) out = out.split(id).join(name);
  return out.replace(/"(cpu|wall)_seconds":[^,]*/g, '"$1_seconds":<s>');
};

const answers = [];
// One request's answer as recorded: status, the headers above, the body.
// opts.kind names an id the answer creates; opts.volatile: [regexp,
// replacement] pairs for what depends on the moment; opts.headers: sent.
async function record(name, base, method, path, body, opts = {}) {
  const r = await req(base, method, path, body, method === 'DELETE' ? JSON_CT : opts.headers || {});
  if (opts.kind && r.body && r.body.id) nameId(r.body.id, opts.kind);
  if (opts.kind && r.body && r.body.session) nameId(r.body.session, 'session');
  const headers = {};
  for (const h of HEADERS) if (r.headers.get(h) !== null) headers[h] = normalise(r.headers.get(h));
  let text = normalise(r.text);
  for (const [re, to] of opts.volatile || []) text = text.replace(re, to);
  answers.push({ name, status: r.status, headers, body: text });
  return r;
}

// The data directory's files: text files whole, framed files (.bin) as the
// SHA-256 of their bytes with the ids replaced and the checksum zeroed;
// sessions' files by name only (their checkpoints hold the worker's timing).
function dataDir() {
  const files = {};
  const walk = (rel) => {
    for (const name of readdirSync(join(dir, rel)).sort()) {
      const path = rel ? `${rel}/${name}` : name;
      if (statSync(join(dir, path)).isDirectory()) { walk(path); continue; }
      const key = normalise(path);
      if (path.startsWith('sessions/')) { files[key] = 'session file'; continue; }
      const bytes = readFileSync(join(dir, path));
      if (!path.endsWith('.bin')) { files[key] = normalise(bytes.toString('utf8')); continue; }
      // a fit's record holds its result's JSON with its CPU and wall time
      // (and their length): its texts, normalised
      if (path.startsWith('fits/')) {
        files[key] = normalise(bytes.subarray(32).toString('latin1')).match(/[\x20-\x7e\n]{8,}/g);
        continue;
      }
      const b = Buffer.from(bytes);
      b.fill(0, 24, 32); // the payload's checksum
      for (const [id, tag] of ids) {
        const from = Buffer.from(id), to = Buffer.alloc(id.length, 0);
        to.write(tag.slice(0, id.length));
        for (let at = b.indexOf(from); at >= 0; at = b.indexOf(from, at + 1)) to.copy(b, at);
      }
      files[key] = `${bytes.length} bytes, sha256 ${createHash('sha256').update(b).digest('hex')}`;
    }
  };
  walk('');
  return files;
}

const scene = { ...CHEAP.scene, transient: 0.3 };
const SWEEP = { scene, beta: [30, 150], rotations: ['cw', 'ccw'], t_end: 0.8 };
const FIT = {
  scene, t_end: 0.8, free: ['e'], curve_step: 90,
  points: [{ beta: 30, rotation: 'cw', v: 0.07 }, { beta: 150, rotation: 'cw', v: -0.07 }],
};
const EXPERIMENT = { session: { scene }, schedule: [{ beta: 38, until: 4 }, { beta: 128, until: 8 }] };
// the experiment's answer at its creation: its session's worker may have
// begun, or even ended, by then
const EXP_STARTING = [
  [/"state":"(waiting|running|pending|done)"/g, '"state":"<state>"'],
  [/"(t_end|steady_velocity|mean_velocity|uncertainty|steady|reversal_time)":[^,}]*/g, '"$1":<result>'],
  [/"t":[^,]*/, '"t":<t>'], [/"progress":[^,]*/, '"progress":<p>'],
  [/"t_command":[^,]*/g, '"t_command":<t>'], [/"start_velocity":[^,]*/g, '"start_velocity":<v>'],
];

const getDone = (base, path) => until(async () => {
  const g = await req(base, 'GET', path);
  return ['done', 'failed', 'error'].includes(g.body.state) && g.body;
}, 200000, path);

test('every job route answers as recorded, and the data directory holds the same files', { timeout: 600000 * SLOW }, async () => {
  let d = await startDaemon(['--data-dir', dir, '--node-id', 'a1']);
  daemons.push(d);
  const base = () => d.base;
  for (const kind of ['sweeps', 'fits', 'experiments']) {
    await record(`${kind}: empty list`, base(), 'GET', `/api/v1/${kind}`);
    await record(`${kind}: empty list as CSV`, base(), 'GET', `/api/v1/${kind}?format=csv`);
    await record(`${kind}: unknown id`, base(), 'GET', `/api/v1/${kind}/a1-000000000000`);
    await record(`${kind}: unknown id, DELETE`, base(), 'DELETE', `/api/v1/${kind}/a1-000000000000`);
    await record(`${kind}: bad format`, base(), 'GET', `/api/v1/${kind}?format=xml`);
    await record(`${kind}: unknown query parameter`, base(), 'GET', `/api/v1/${kind}?colour=red`);
    await record(`${kind}: not JSON`, base(), 'POST', `/api/v1/${kind}`, '{"t_end": ');
    await record(`${kind}: empty object`, base(), 'POST', `/api/v1/${kind}`, {}, { kind: 'default' });
    await record(`${kind}: PUT`, base(), 'PUT', `/api/v1/${kind}`, {});
  }
  await record('sweeps: bad beta', base(), 'POST', '/api/v1/sweeps', { ...SWEEP, beta: [30, 200] });
  await record('sweeps: bad rotation', base(), 'POST', '/api/v1/sweeps', { ...SWEEP, rotations: ['up'] });
  await record('fits: bad free', base(), 'POST', '/api/v1/fits', { ...FIT, free: ['ee'] });
  await record('experiments: bad schedule', base(), 'POST', '/api/v1/experiments', { ...EXPERIMENT, schedule: [{ beta: 38, until: -1 }] });
  await record('experiments: no such session', base(), 'POST', '/api/v1/experiments', { ...EXPERIMENT, session: 'a1-ffffffffffff' });

  // two sweeps, the second deleted when done
  const sw = [];
  for (const i of [1, 2]) sw.push((await record(`sweeps: create ${i}`, base(), 'POST', '/api/v1/sweeps', SWEEP, { kind: 'sweep' })).body.id);
  const fit = await record('fits: create', base(), 'POST', '/api/v1/fits', FIT, { kind: 'fit' });
  const ex = await record('experiments: create', base(), 'POST', '/api/v1/experiments', EXPERIMENT, { kind: 'experiment', volatile: EXP_STARTING });
  // the sweep of every default, created above
  const [defaults] = [...ids].find(([, tag]) => tag === '<default-1>');
  await getDone(base(), `/api/v1/sweeps/${defaults}`);
  for (const id of sw) await getDone(base(), `/api/v1/sweeps/${id}`);
  await getDone(base(), `/api/v1/fits/${fit.body.id}`);
  await getDone(base(), `/api/v1/experiments/${ex.body.id}`);

  const results = async (when) => {
    for (const [kind, id] of [['sweeps', sw[0]], ['sweeps', sw[1]], ['fits', fit.body.id], ['experiments', ex.body.id]]) {
      await record(`${when}: ${kind} ${normalise(id)}`, base(), 'GET', `/api/v1/${kind}/${id}`);
      await record(`${when}: ${kind} ${normalise(id)} as CSV`, base(), 'GET', `/api/v1/${kind}/${id}?format=csv`);
      await record(`${when}: ${kind} ${normalise(id)} as CSV by Accept`, base(), 'GET', `/api/v1/${kind}/${id}`, undefined, { headers: { Accept: 'text/csv' } });
    }
    for (const kind of ['sweeps', 'fits', 'experiments']) {
      await record(`${when}: ${kind} list`, base(), 'GET', `/api/v1/${kind}`);
      await record(`${when}: ${kind} list as CSV`, base(), 'GET', `/api/v1/${kind}?format=csv`);
      await record(`${when}: ${kind} list, local`, base(), 'GET', `/api/v1/${kind}?scope=local`);
    }
  };
  await results('done');
  // (a restart restores in the directory's order: one sweep is kept)
  await record('sweeps: delete the defaults', base(), 'DELETE', `/api/v1/sweeps/${defaults}`);
  await record('sweeps: delete', base(), 'DELETE', `/api/v1/sweeps/${sw[1]}`);
  await record('sweeps: deleted', base(), 'GET', `/api/v1/sweeps/${sw[1]}`);
  // the experiment's session is removed within a second of its end
  await until(async () => (await req(base(), 'GET', `/api/v1/sessions/${ex.body.session}`)).status === 404, 5000, 'the session to go');
  await record('after delete: sweeps list', base(), 'GET', '/api/v1/sweeps');
  await record('after delete: fits list', base(), 'GET', '/api/v1/fits');

  // a second replica merges the first one's lists with its own (empty) ones
  const peer = await startDaemon(['--node-id', 'b2', '--peers', d.base]);
  daemons.push(peer);
  for (const kind of ['sweeps', 'fits', 'experiments']) {
    await record(`peers: ${kind} list`, peer.base, 'GET', `/api/v1/${kind}`);
    await record(`peers: ${kind} list as CSV`, peer.base, 'GET', `/api/v1/${kind}?format=csv`);
  }
  await peer.stop();

  assert.equal((await d.stop()).code, 0, d.stderr());
  const files = dataDir();

  // a restart on the same directory serves what was kept
  d = await startDaemon(['--data-dir', dir, '--node-id', 'a1']);
  daemons.push(d);
  for (const [kind, id] of [['sweeps', sw[0]], ['sweeps', sw[1]], ['fits', fit.body.id], ['experiments', ex.body.id]]) {
    await record(`restarted: ${kind} ${normalise(id)}`, base(), 'GET', `/api/v1/${kind}/${id}`);
    await record(`restarted: ${kind} ${normalise(id)} as CSV`, base(), 'GET', `/api/v1/${kind}/${id}?format=csv`);
  }
  for (const kind of ['sweeps', 'fits', 'experiments']) {
    await record(`restarted: ${kind} list`, base(), 'GET', `/api/v1/${kind}`);
    await record(`restarted: ${kind} list as CSV`, base(), 'GET', `/api/v1/${kind}?format=csv`);
  }
  await record('restarted: fits: delete', base(), 'DELETE', `/api/v1/fits/${fit.body.id}`);
  await record('restarted: sweeps: delete', base(), 'DELETE', `/api/v1/sweeps/${sw[0]}`);
  await record('restarted: experiments: delete', base(), 'DELETE', `/api/v1/experiments/${ex.body.id}`);
  await record('restarted: experiments: deleted', base(), 'GET', `/api/v1/experiments/${ex.body.id}`);
  assert.equal((await d.stop()).code, 0, d.stderr());
  const filesAfter = dataDir();

  // a finished fit is served after a restart as it was before
  const byName = (name) => answers.find((a) => a.name === name);
  for (const csv of ['', ' as CSV']) {
    assert.deepEqual(byName(`restarted: fits <fit-1>${csv}`), { ...byName(`done: fits <fit-1>${csv}`), name: `restarted: fits <fit-1>${csv}` });
  }

  const got = { answers, files, files_after_deletes: filesAfter };
  if (RECORD) {
    writeFileSync(GOLDEN, JSON.stringify(got, null, 1) + '\n');
    return;
  }
  const want = JSON.parse(readFileSync(GOLDEN, 'utf8'));
  assert.equal(got.answers.length, want.answers.length, 'the number of answers');
  for (let i = 0; i < want.answers.length; i++) assert.deepEqual(got.answers[i], want.answers[i], want.answers[i].name);
  assert.deepEqual(got.files, want.files, 'the data directory');
  assert.deepEqual(got.files_after_deletes, want.files_after_deletes, 'the data directory after the deletes');
});

// docs/jobs.md's table of the descriptor names every field of
// srv_job_kind (server/jobs/job.h), and nothing else.
test('docs/jobs.md lists the job descriptor\'s fields as server/jobs/job.h has them', () => {
  const header = readFileSync(fileURLToPath(new URL('../../server/jobs/job.h', import.meta.url)), 'utf8');
  const body = header.match(/typedef struct srv_job_kind \{([\s\S]*?)\} srv_job_kind;/)[1]
    .replace(/\/\*[\s\S]*?\*\//g, '');
  const fields = [];
  for (const decl of body.split(';')) {
    const fn = decl.match(/\(\*(\w+)\)/);
    if (fn) { fields.push(fn[1]); continue; }
    const names = decl.replace(/^[^*\w]*(const\s+)?[\w ]+?\s+(?=[*\w]+\s*(,|$))/, '').split(',');
    for (const n of names) if (n.trim()) fields.push(n.trim().replace(/^\*+/, ''));
  }
  const doc = readFileSync(fileURLToPath(new URL('../../docs/jobs.md', import.meta.url)), 'utf8');
  const table = doc.split('## The descriptor')[1].split('\n## ')[0];
  const documented = [...table.matchAll(/^\| `(\w+)`/gm)].map((m) => m[1]);
  assert.deepEqual(documented, fields);
});
