// SPDX-License-Identifier: GPL-3.0-or-later
// The DEM programs read a number as convsim does (core/decimal.h: sign,
// digits, point, exponent; tests/cli/numbers.test.mjs): convsim-dem's
// options and their parts (--hertz E:NU, --pair and --wall E:MU:MUR,
// --frame-check A:DEG), convsim-bed's --nice, and the coupled run's
// CONVSIM_DEM_GRAINS. What strtod, sscanf or atoi would also have read
// (0x8, ' 8', '1e', a trailing word, 1.5 for a count) exits 2 naming the
// option, nothing on stdout. Each refused line ends with an operand, so
// that a refusal missed ends at "no operands are taken" before any bed
// is built. Needs build/convsim-dem and build/convsim-bed.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import '../tether.mjs'; // nothing started here outlives the test

const BUILD = process.env.BUILD || 'build';
const ROOT = new URL('../..', import.meta.url).pathname;
const DEM = process.env.CONVSIM_DEM || `${ROOT}${BUILD}/convsim-dem`;
const BED = `${ROOT}${BUILD}/convsim-bed`;
const CONVSIM = process.env.CONVSIM || `${ROOT}${BUILD}/convsim`;
// (leak detection off under ASan: the MPI stack's own leaks at exit, as in dem.test.mjs)
const ENV = { ...process.env, ASAN_OPTIONS: [process.env.ASAN_OPTIONS, 'detect_leaks=0'].filter(Boolean).join(':') };
const spawn = (bin, args, more = {}) => {
  const r = spawnSync(bin, args, { encoding: 'utf8', timeout: 120000, input: '', env: { ...ENV, ...more } });
  return { code: r.status, out: r.stdout, err: r.stderr };
};

test('convsim-dem: every number of its command line is a plain decimal number, a count a whole one', () => {
  const range = (opt, lo, hi, v) => `convsim-dem: --${opt} must be a number in [${lo}, ${hi}], got '${v}'\n`;
  const whole = (opt, v) => `convsim-dem: --${opt} must be a whole number, got '${v}'\n`;
  const hertz = (v) => "convsim-dem: --hertz must be E:NU with E in [5e6, 1e9] Pa and NU in (0, 0.5), " +
    `got '${v}'\n`;
  const contact = (opt, v) => `convsim-dem: --${opt} must be E:MU:MUR with E in (0.05, 1], MU and MUR ` +
    `in [0, 10], got '${v}'\n`;
  const frame = (v) => 'convsim-dem: --frame-check must be A:DEG with A in (0, 0.01] m and DEG in ' +
    `[0, 180], got '${v}'\n`;
  const cases = [
    [['--depth', '0x8'], range('depth', 0.1, 1000, '0x8')],
    [['--depth', ' 8'], range('depth', 0.1, 1000, ' 8')],
    [['--depth', '8 '], range('depth', 0.1, 1000, '8 ')],
    [['--depth', '1e'], range('depth', 0.1, 1000, '1e')],
    [['--depth', ''], range('depth', 0.1, 1000, '')],
    [['--duration', 'infinity'], range('duration', 0.01, 1000, 'infinity')],
    [['--density', '0x1p11'], range('density', 1, 100000, '0x1p11')],
    [['--seed', '0x10'], range('seed', 0, '1e+09', '0x10')],
    [['--seed', '1.5'], whole('seed', '1.5')],
    [['--grains', '2.5'], whole('grains', '2.5')],
    [['--harmonics', '2.5'], whole('harmonics', '2.5')],
    [['--intervals', '1e'], range('intervals', 0, 100000, '1e')],
    [['--coupling-steps', '1.5'], whole('coupling-steps', '1.5')],
    [['--hertz', '2e8:0.3x'], hertz('2e8:0.3x')],
    [['--hertz', '0x1p28:0.3'], hertz('0x1p28:0.3')],
    [['--hertz', '2e8: 0.3'], hertz('2e8: 0.3')],
    [['--hertz', '2e8:0.3:1'], hertz('2e8:0.3:1')],
    [['--pair', '0.9:0.3:0x0'], contact('pair', '0.9:0.3:0x0')],
    [['--wall', ' 0.9:0.3:0'], contact('wall', ' 0.9:0.3:0')],
    [['--wall', '0.9:0.3:'], contact('wall', '0.9:0.3:')],
    [['--frame-check', '0.002:30junk'], frame('0.002:30junk')],
    [['--frame-check', '0.002:30:5'], frame('0.002:30:5')],
  ];
  for (const [args, message] of cases) {
    const r = spawn(DEM, [...args, 'operand']);
    assert.equal(r.code, 2, `${args.join(' ')}: ${r.err}`);
    assert.equal(r.out, '', args.join(' '));
    assert.equal(r.err, message, args.join(' '));
  }
  // the same options with plain numbers are taken (the operand is what is refused)
  const good = ['--depth', '8', '--seed', '3', '--grains', '2', '--harmonics', '2', '--coupling-steps', '4',
    '--hertz', '2e8:0.3', '--pair', '0.9:0.3:0', '--wall', '.9:+0.3:0e0', '--frame-check', '0.002:30'];
  const r = spawn(DEM, [...good, 'operand']);
  assert.equal(r.code, 2, r.err);
  assert.equal(r.err, 'convsim-dem: no operands are taken\n');
});

test('convsim-bed: --nice takes a whole number in [0, 19] only', () => {
  const nice = (v) => `convsim-bed: --nice must be a number in [0, 19], got '${v}'\n`;
  for (const [v, message] of [['0x5', nice('0x5')], ['5abc', nice('5abc')], [' 5', nice(' 5')],
    ['', nice('')], ['20', nice('20')], ['5.5', "convsim-bed: --nice must be a whole number, got '5.5'\n"]]) {
    const r = spawn(BED, ['--serve', '--nice', v]);
    assert.equal(r.code, 2, `--nice '${v}': ${r.err}`);
    assert.equal(r.out, '', `--nice '${v}'`);
    assert.equal(r.err, message, `--nice '${v}'`);
  }
  // a good one serves (here: the end of stdin at once, exit 0)
  const r = spawn(BED, ['--serve', '--nice', '5']);
  assert.equal(r.code, 0, r.err);
  assert.equal(r.out, '');
});

test('a coupled run: CONVSIM_DEM_GRAINS is a whole number in [1, 1000000], as a plain decimal number', () => {
  const msg = (v) => `convsim run: CONVSIM_DEM_GRAINS must be an integer in [1, 1000000], got '${v}'\n`;
  for (const v of [' 5', '+5x', '0x5', '5.5', '1e']) {
    const r = spawn(CONVSIM, ['run', '--set', 'feed_model=liggghts', '--set', 'layers=1', '-d', '0.01', '-q'],
      { CONVSIM_DEM_GRAINS: v });
    assert.equal(r.code, 2, `CONVSIM_DEM_GRAINS='${v}': ${r.err}`);
    assert.equal(r.out, '', `CONVSIM_DEM_GRAINS='${v}'`);
    assert.equal(r.err, msg(v), `CONVSIM_DEM_GRAINS='${v}'`);
  }
});
