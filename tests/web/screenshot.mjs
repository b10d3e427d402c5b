// SPDX-License-Identifier: GPL-3.0-or-later
// Makes README's picture of the dashboard, docs/img/dashboard.png: the real
// daemon (CONVSIMD, default build/convsimd) on port 0, one default session
// at beta = 38 deg, clockwise, pace 1, and Debian's chromium (CHROMIUM)
// through playwright-core, 1280 x 900, six simulated seconds in. Not a
// test: run it by hand after a visible change of the page,
// `node tests/web/screenshot.mjs`.
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from '../node_modules/playwright-core/index.mjs';
import { startDaemon, req, sleep } from '../http/lib.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const OUT = process.argv[2] || path.join(ROOT, 'docs/img/dashboard.png');
const d = await startDaemon();
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--no-first-run'] });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  const r = await req(d.base, 'POST', '/api/v1/sessions', { params: { beta: 38, rotation: 'cw' }, scene: { layers: 4 }, pace: 1 });
  await page.goto(`${d.base}/#session=${r.body.id}`);
  await page.waitForSelector('body[data-ready="true"]', { timeout: 15000 });
  await sleep(6000);
  await page.screenshot({ path: OUT });
  console.log(`wrote ${OUT}`);
} finally {
  await browser.close();
  await d.stop();
}
