// SPDX-License-Identifier: GPL-3.0-or-later
// What a stream client costs the daemon per record it formats and sends
// (`node tests/bench/stream_cost.mjs [N] [SECONDS]`, or tests/bench/stream_cost.sh
// for the result page; about a minute): N
// default sessions at pace 1 on a fresh daemon (--max-paced-cores 2, so
// none is refused), the daemon's CPU time (user + sys) over SECONDS without
// streams, then with one NDJSON stream on each session of three kinds in
// turn: trough fields at ?rate=10, trough fields at every sample, the
// default fields at every sample. A kind's CPU per record is its CPU less
// the one without streams over the records its clients received. The cost
// model of server/admit/budget_cost.c (a record's fixed part and its part
// per formatted double) comes from these figures (docs/budgets.md).
import http from 'node:http';
import { startDaemon } from '../http/lib.mjs';
import { call, procUsage, fmt } from './streamlag.mjs';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Open one stream per id with the query q; stop() closes them all and
// returns the records received since count() was reset.
function openStreams(base, ids, q) {
  const st = { records: 0, reqs: [] };
  for (const id of ids) {
    const r = http.get(`${base}/api/v1/sessions/${id}/stream?format=ndjson${q}`, { agent: false }, (res) => {
      res.setEncoding('utf8');
      res.on('data', (c) => { for (let i = c.indexOf('\n'); i >= 0; i = c.indexOf('\n', i + 1)) st.records++; });
      res.on('error', () => {});
    });
    r.on('error', () => {});
    st.reqs.push(r);
  }
  st.stop = () => st.reqs.forEach((r) => r.destroy());
  return st;
}

async function measure(pid, seconds, st) {
  await sleep(1000);
  if (st) st.records = 0;
  const c0 = procUsage(pid).cpu;
  await sleep(seconds * 1000);
  return { cpu: procUsage(pid).cpu - c0, records: st ? st.records : 0 };
}

const N = Number(process.argv[2]) || 40;
const T = Number(process.argv[3]) || 8;
const d = await startDaemon(['--max-paced-cores', '2', '--max-sessions', String(N + 8)]);
const ids = [];
for (let i = 0; i < N; i++) {
  const r = await call(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
  if (r.status !== 201) throw new Error(`session ${i}: ${r.status} ${JSON.stringify(r.body)}`);
  ids.push(r.body.id);
}
await sleep(2000);
const none = await measure(d.proc.pid, T);
console.log('# What a stream client costs the daemon per record\n');
console.log(`Command: \`node tests/bench/stream_cost.mjs ${N} ${T}\` (\`bash tests/bench/stream_cost.sh\`): ${N} default ` +
  `sessions at pace 1, the daemon's CPU over ${T} s without streams, then with one NDJSON stream on each.`);
console.log('\n| streams | records received | daemon CPU, s | CPU per record, us |\n|---|---|---|---|');
console.log(`| none | 0 | ${fmt(none.cpu, 2)} | |`);
for (const [name, q] of [['trough, rate 10', '&fields=trough&rate=10'], ['trough, rate 50', '&fields=trough&rate=50'],
  ['trough, every sample', '&fields=trough'], ['default fields, every sample', ''],
  ['default fields, rate 10', '&rate=10']]) {
  const st = openStreams(d.base, ids, q);
  const m = await measure(d.proc.pid, T, st);
  st.stop();
  console.log(`| ${name} | ${m.records} | ${fmt(m.cpu, 2)} | ${fmt(1e6 * (m.cpu - none.cpu) / m.records, 1)} |`);
  await sleep(500);
}
await d.stop();
