// SPDX-License-Identifier: GPL-3.0-or-later
// Prism (`prism proxy --errors`, @stoplight/prism-cli in tests/node_modules)
// as a validating proxy in front of a daemon: a request or an answer that
// breaks the OpenAPI document is answered as a violation (a 4xx/5xx problem
// of type https://stoplight.io/prism/errors#VIOLATIONS, or an sl-violations
// header) instead of passing. Prism runs under a shell that ends it when its
// standard input closes, so that it ends with the test process however that
// process ends. Used by openapi.test.mjs and docs.test.mjs.
import { spawn } from 'node:child_process';
import { existsSync, mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { freePorts, SLOW } from './lib.mjs';

const PRISM = fileURLToPath(new URL('../node_modules/.bin/prism', import.meta.url));

// Start Prism on a free port with the document docText in front of target
// (http://HOST:PORT). Resolves to {url, log(), stop()} once it listens.
export async function startPrism(docText, target) {
  // without it the shell below waits on its input for ever (make test
  // installs it: `make deps`)
  if (!existsSync(PRISM)) throw new Error(`${PRISM} is missing: run \`make deps\` (make test does)`);
  const file = join(mkdtempSync(join(tmpdir(), 'convsim-prism-')), 'openapi.json');
  writeFileSync(file, docText);
  const [port] = await freePorts(1);
  const child = spawn('sh', ['-c', '"$@" & p=$!; read _; kill $p; wait $p', 'sh',
    PRISM, 'proxy', '--errors', '-h', '127.0.0.1', '-p', String(port), file, target],
  { stdio: ['pipe', 'pipe', 'pipe'] });
  let text = '';
  const listening = new Promise((resolve, reject) => {
    const seen = (b) => { text += b; if (/Prism is listening/.test(text)) resolve(); };
    child.stdout.on('data', seen);
    child.stderr.on('data', seen);
    child.on('exit', (code) => reject(new Error(`prism exited (${code}): ${text.slice(-2000)}`)));
  });
  // the deadline's timer is cleared once Prism listens: left to run, it
  // kept the test process alive 60 s after its last test
  let timer;
  const late = new Promise((_, no) => { timer = setTimeout(() => no(new Error(`prism did not start: ${text}`)), 60000 * SLOW); });
  try {
    await Promise.race([listening, late]);
  } finally {
    clearTimeout(timer);
  }
  return { url: `http://127.0.0.1:${port}`, log: () => text, stop: () => child.stdin.end() };
}
