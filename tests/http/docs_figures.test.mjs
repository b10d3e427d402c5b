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
// - a setting written as its name, " = ", the value (`dt = 1e-4 s`), or
// - a specification value (a setting, default, limit, target or a
//   definition) listed with the words around it in SPEC (one page) or
//   EVERYWHERE (any page), each with its source.
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
  /* plain percentages and wall times: settings, defaults, limits and rules, with their source */
  /* the dashboard's velocity window and the preset's transient (web/, core/defaults.c) */
  ['docs/getting-started.md', 'over the last 0.5 s of the stream'],
  ['docs/getting-started.md', 'transient (0 s in czubak2016)'],
  ['docs/getting-started.md', 'the moment the 90 % are reached'],
  ['docs/getting-started.md', 'reaches 90 % of its new steady value'],
  /* the worker's control hand-over limit (server/session/) */
  ['docs/api-errors.md', 'take a control within 5 s'],
  /* the slow client of tests/http/budgets.test.mjs */
  ['docs/hardening.md', 'one byte every 2 s'],
  /* tests/bench/realtime.mjs's run length */
  ['docs/load.md', 'one NDJSON stream each, 10 s'],
  /* the default window: transient + 4 s (core/defaults.c) */
  ['docs/api-jobs.md', '`scene.transient` + 4 s, i.e. 4 s for czubak2016'],
  ['docs/api.md', 'to 4 s and reads'],
  ['docs/cli.md', '`transient` + 4 s (4 s for czubak2016)'],
  ['docs/mpi.md', '(default transient + 4 s)'],
  /* a load step on the preset's m_n = 0.5 kg */
  ['docs/api.md', 'is a +50 % load on the preset'],
  ['docs/api.md', 'reaches 90 % of the new steady value'],
  /* the restored session's control window and tests/http/replay.test.mjs's scene */
  ['docs/durability.md', '(at most 5 s)'],
  ['docs/durability.md', 'finished at t = 80 s'],
  ['docs/durability.md', 'answers t = 3.2 s with the old target'],
  /* the fuzz corpus's seeds and the parser's and the harness's limits (tests/fuzz/) */
  ['docs/fuzzing.md', '0.05 s into a'],
  ['docs/fuzzing.md', '`until` 1 s'],
  ['docs/fuzzing.md', 'always gives it 60 s'],
  /* the dem step and the shadow's stopping rule (core/sweep.c) */
  ['docs/speed.md', 'at the same step (1.25e-3 s)'],
  ['docs/speed.md', "from the shadow's end (30 % of the window) every\n0.1 s"],
  /* the browser tests' pacing (tests/web/) */
  ['docs/testing.md', 'at most 8 in any 2 s'],
  ['docs/testing.md', '(hold 0.6 s)'],
  /* issue 31's target */
  ['docs/cli.md', 'under 30 s on 2 cores'],
  /* server/cluster.sh's HAProxy settings and those of tests/http/cluster.test.mjs */
  ['docs/cluster.md', 'four heartbeats (60 s'],
  ['docs/cluster.md', 'does not answer within 3 s'],
  ['docs/cluster.md', 'within 2 s (two failed health'],
  ['docs/cluster.md', '(heartbeat 2 s, timeouts 8 s, held 10 s)'],
  ['docs/cluster.md', 'all at once, within 3 s'],
  /* a section's name (history of the CPU target) */
  ['docs/log/history.md', '### The curve at 0.1 CPU s'],
  /* the model's own values and its tests' answers (tests/unit/, named in accuracy.md) */
  ['docs/MODEL.md', "2.5e-4 s (5 per"],
  ['docs/MODEL.md', "a +50 % load step"],
  ['docs/MODEL.md', "load step at 0.5 s"],
  ['docs/MODEL.md', "≈ 3.7 s"],
  ['docs/MODEL.md', "bias v by up to 2 %"],
  ['docs/MODEL.md', "0.6 s by default; 1 s"],
  ['docs/MODEL.md', "30 % and faded out"],
  ['docs/MODEL.md', "its size after 0.6 s"],
  ['docs/MODEL.md', "1e-3 after 0.6 s"],
  ['docs/MODEL.md', "2.3e-5 after 1 s"],
  ['docs/MODEL.md', "its default was 1 s"],
  ['docs/MODEL.md', "2e-3 after 1 s"],
  ['docs/MODEL.md', "over the first 2 s"],
  ['docs/MODEL.md', "after 0.6 s"],
  ['docs/MODEL.md', "1 s left 7.0e-6 m"],
  ['docs/MODEL.md', "damper after 0.5 s"],
  ['docs/MODEL.md', "[4, 12] s within 0.05 %"],
  ['docs/MODEL.md', "from 0.3 to 1 s"],
  ['docs/MODEL.md', "off by up to 6 %"],
  ['docs/MODEL.md', "with τ ≈ 3.7 s"],
  /* the settings and tolerances of tests/unit/test_beyond_preset.c */
  ['docs/machine-zoo-tests.md', "start and after 0.3 s"],
  ['docs/machine-zoo-tests.md', "amplitude over 1 s"],
  ['docs/machine-zoo-tests.md', "below 1e-9 rad; 0.1 %"],
  ['docs/machine-zoo-tests.md', "in ω is already 3 to 6 %"],
  ['docs/machine-zoo-tests.md', "stays there for 0.3 s"],
  ['docs/machine-zoo-tests.md', "positions after 0.02 s"],
  ['docs/machine-zoo-tests.md', "of the amplitude at 1 s"],
  /* the literature values, each with its source cited in the table */
  ['docs/materials.md', "Dry wheat (about 7–13 %"],
  ['docs/materials.md', "kernels (7.4 %"],
  ['docs/materials.md', "1240 kg/m³ at 7.4 %"],
  ['docs/materials.md', "394.8 MPa at 9.3 %"],
  ['docs/materials.md', "99.2 MPa at 22.5 %"],
  ['docs/materials.md', "37–75 MPa at 10–20 %"],
  ['docs/materials.md', "43.7 MPa at 10.3 %"],
  ['docs/materials.md', "for wheat at 10.8 %"],
  ['docs/materials.md', "a metal plate (7–16 %"],
  ['docs/materials.md', "steel sheets at 12–18 %"],
  ['docs/materials.md', "(sphericity about 60 %"],
  ['docs/materials.md', "deck by about 0.02 %"],
  ['docs/materials.md', "changes it by 5 %"],
  /* the schedules of make bench's remote loop (tests/bench/remote_loop.py) and of tests/http/remote_loop.test.mjs */
  ['docs/control-remote.md', '+0.05 m/s (8 s each)'],
  ['docs/control-remote.md', '−0.08 m/s, 3 s each'],
  ['docs/control-remote.md', 'settles within its 3 s'],
  /* the bounds and settings each check asserts (the test named in its row, tests/unit/), the defaults (core/defaults.c) and the model's decay time (MODEL.md) */
  ['docs/accuracy.md', "decays with τ ≈ 3.7 s"],
  ['docs/accuracy.md', "at t = 4 s"],
  ['docs/accuracy.md', "(sweeps) is 4 s"],
  ['docs/accuracy.md', "this integrator: 3 s"],
  ['docs/accuracy.md', "and 2 s"],
  ['docs/accuracy.md', "window stays 4 s"],
  ['docs/accuracy.md', "1e-10 J over 1 s"],
  ['docs/accuracy.md', "0.5 %, shrinking wi"],
  ['docs/accuracy.md', "5 % below the bou"],
  ['docs/accuracy.md', "slip is within 20 %"],
  ['docs/accuracy.md', "0.1 %;"],
  ['docs/accuracy.md', "within 3 %"],
  ['docs/accuracy.md', "periods within 5 %"],
  ['docs/accuracy.md', "125° ccw after 4 s"],
  ['docs/accuracy.md', "left 1e-3 after 0.6 s"],
  ['docs/accuracy.md', "the state after 1 s"],
  ['docs/accuracy.md', "relative over 1 s"],
  ['docs/accuracy.md', "one element over 2 s"],
  ['docs/accuracy.md', "within 0.3 %"],
  ['docs/accuracy.md', "(v within ±50 %"],
  ['docs/accuracy.md', "(within 0.2 %"],
  ['docs/accuracy.md', ": 30 rad/s within 0.1 s"],
  ['docs/accuracy.md', "within 1 s"],
  ['docs/accuracy.md', "- 60 s of the machin"],
  ['docs/accuracy.md', "falls below 1 %"],
  ['docs/accuracy.md', "\"diverged at t = 0.02 s"],
  ['docs/accuracy.md', "withholds above 20 %"],
  ['docs/accuracy.md', "after its run-up, 5 %"],
  ['docs/accuracy.md', "step, 5 %"],
  ['docs/accuracy.md', "both are within 20 %"],
  ['docs/accuracy.md', "5 % above, RK4's"],
  ['docs/accuracy.md', "`dem` < 1 %"],
  /* tol's default (1 %) and the step rule, the shadow's and the a-priori term's constants (core/shadow.c), the references' settings (tests/bench/zoo_ref.sh) and issue 37's target */
  ['docs/machine-zoo.md', "is beyond what 1 %"],
  ['docs/machine-zoo.md', "both times tol / 1 %"],
  ['docs/machine-zoo.md', "keeps the 1 %"],
  ['docs/machine-zoo.md', "periods (30 %"],
  ['docs/machine-zoo.md', "a-priori**: 0.5 %"],
  ['docs/machine-zoo.md', "plus 0.025 %"],
  ['docs/machine-zoo.md', "term stands in (0.75 %"],
  ['docs/machine-zoo.md', "(the shadow over 30 %"],
  ['docs/machine-zoo.md', "1 % where their error"],
  ['docs/machine-zoo.md', "when tol is below 1 %"],
  ['docs/machine-zoo.md', "or \"beyond 1.0 %"],
  ['docs/machine-zoo.md', "shows \"within 1.0 %"],
  ['docs/machine-zoo.md', "the steady start (32 s"],
  ['docs/machine-zoo.md', "the default's 4 s"],
  ['docs/machine-zoo.md', "## 5. What 1 %"],
  ['docs/machine-zoo.md', "of the zoo that 1 %"],
  ['docs/machine-zoo.md', "do not buy 1 %"],
  ['docs/machine-zoo.md', "): at 16 and 32 s"],
  ['docs/machine-zoo.md', "at ≥ 90 %"],
  ['docs/machine-zoo.md', "close within 0.1 %"],
  /* the studies' settings (tests/bench/workprec_scenes.c, peers.sh: the 60-s CPU budget, the check's 0.5-s orbit), the gate and test_feed.c's bound */
  ['docs/benchmarks.md', "periods (0.8 s"],
  ['docs/benchmarks.md', "feed scenes runs 0.8 s"],
  ['docs/benchmarks.md', "rtol = 1e-5 (0.8 s"],
  ['docs/benchmarks.md', "0.5 %, shrinking) a"],
  ['docs/benchmarks.md', "rest has passed 1.5 s"],
  ['docs/benchmarks.md', "a CPU budget of 60 s"],
  ['docs/benchmarks.md', "until one meets 1 %"],
  ['docs/benchmarks.md', "orbit over 0.5 s"],
  ['docs/benchmarks.md', "at 1e-3 within 60 s"],
  ['docs/benchmarks.md', "third point in 60 s"],
  ['docs/benchmarks.md', "peer reaches 1 %"],
  /* test_energy_balance.c's bound and run length, the commands' run lengths */
  ['docs/energy.md', "within 0.1 %"],
  ['docs/energy.md', "cw over 0.5 s"],
  ['docs/energy.md', "of the input over 4 s"],
  ['docs/energy.md', "at β = 38° over 4 s"],
  ['docs/energy.md', "the defaults for 0.5 s"],
  ['docs/energy.md', "close within 0.1 %"],
  /* the step rule (core/defaults.c: tol / 1 %, the 20 % mass ratio MODEL_CORRECTOR_MAX_RATIO and the added-mass limit it keeps clear of), the stability analysis's own values, and the tests' settings (test_feed.c, test_hard_machine.c) */
  ['docs/integrators.md', "scaled by tol / 1 % below 1 %"],
  ['docs/integrators.md', "for feeds over 20 %"],
  ['docs/integrators.md', "than about 30 %"],
  ['docs/integrators.md', "weighs at most 20 %"],
  ['docs/integrators.md', "displacement over 3 s"],
  ['docs/integrators.md', "edge (RK4 kept 99.7 %"],
  ['docs/integrators.md', "exact flow 6 %"],
  ['docs/integrators.md', "5 % either side of it"],
  /* the profile's sampling (the command above) and PACE_TICK (server/session/worker.c) */
  ['docs/performance.md', "each, sampled for 8 s"],
  ['docs/performance.md', "the next 0.1 s of simulated time, or 0.1 s of wall time"],
  ['docs/performance.md', "up to 0.1 s"],
  /* the budgets' settings (--max-cpu-seconds 1800, the fair share's slice) and tests/http/budgets.test.mjs's slow client */
  ['docs/budgets.md', "one byte every 2 s"],
  ['docs/budgets.md', "after 10 s"],
  ['docs/budgets.md', "1800 s lasts it days"],
  ['docs/budgets.md', "now stops after 30 minutes"],
  ['docs/budgets.md', "0.1 s while others"],
  /* the estimator's and the step error's constants (core/estimator.c, core/shadow.c) and the tests' settings and bounds (test_accuracy.c) */
  ['docs/model-numerics.md', "within 0.05 % 3 s"],
  ['docs/model-numerics.md', "first 40 periods (30 %"],
  ['docs/model-numerics.md', "term, 0.5 %"],
  ['docs/model-numerics.md', "plus 0.025 %"],
  ['docs/model-numerics.md', "term stands in: 0.75 %"],
  ['docs/model-numerics.md', "plus 0.04 %"],
  ['docs/model-numerics.md', "explain) or below 0.5 %"],
  ['docs/model-numerics.md', "plus 0.5 %"],
  ['docs/model-numerics.md', "the first 1.5 s"],
  ['docs/model-numerics.md', "the state after 1 s"],
  /* the fit's settings (fd_step's default, t_end's default), the band test's bound (tests/unit/, named in the list) and the calibration target (issue 31) */
  ['docs/calibration.md', "the transient + 4 s"],
  ['docs/calibration.md', "upper bound. Why 5 %"],
  ['docs/calibration.md', "A 5 %"],
  ['docs/calibration.md', "(the test asks ≥ 90 %"],
  ['docs/calibration.md', "< 30 s wall on 2 cores"],
  /* the map's overlap criterion and stiffness rungs, the runs' settings (tests/bench/dem_map.py) and the frame test's bound (tests/dem/) */
  ['docs/dem.md', "overlapped more than 1 %"],
  ['docs/dem.md', "overlap more than 1 %"],
  ['docs/dem.md', "Hertz's within 2 %"],
  ['docs/dem.md', "allow: v within 2 %"],
  ['docs/dem.md', "three seeds, 3 s"],
  ['docs/dem.md', "v over the last 2 s"],
  /* the control bench's settings and criteria (tests/bench/control_loop.mjs, control_shaping.c:
     steps, holds, the 2 % settling and 90 % reversal definitions, the 1 % steady-error target, the
     disturbances' sizes), the ramp's time at 90 °/s, and the experiment's sample cap (50 000 at 25 Hz) */
  ['docs/control.md', 'two `sim_measure` runs of 2 s'],
  ['docs/control.md', 'each a `sim_measure` of 2 s'],
  ['docs/control.md', 'steps of ±4° held 1.5 s'],
  ['docs/control.md', 'steady error\nwell below 1 %'],
  ['docs/control.md', 'The 2 % settling time'],
  ['docs/control.md', 'open-loop reversal time (90 % of'],
  ['docs/control.md', 'to come within 2 %'],
  ['docs/control.md', 'to settle within 2 %'],
  ['docs/control.md', '(90 °/s: 0.58 s for 55.2° → 107°, 0.41 s'],
  ['docs/control.md', 'where 2 % of +0.05 m/s'],
  ['docs/control.md', '(−4.5 %, −10 %, +5 %), a +50 % load step'],
  ['docs/control.md', '−20 % friction'],
  ['docs/control.md', 'rejected to within 2 %'],
  ['docs/control.md', 'A −10 % `omega_ss` step'],
  ['docs/control.md', 'about 33 minutes at the preset\'s 25 Hz'],
  /* the fast feed model's target and criterion, the DEM's window (tests/bench/fast_feed_check.py) */
  ['docs/feed-models.md', 'at 90 % or more'],
  ['docs/feed-models.md', 'window: 3 s'],
  ['docs/feed-models.md', 'most points within 5 % there'],
  ['docs/feed-models.md', 'points are within 5 %'],
  ['docs/feed-models.md', '% within 5 % leave one'],
  ['docs/feed-models.md', 'measured over 5 s instead'],
  ['docs/feed-models.md', 'v over 5 s'],
  ['docs/feed-models.md', 'points within 5 % (the'],
  ['docs/feed-models.md', 'is within 5 % at'],
  ['docs/feed-models.md', '% within 5 %, with a chaotic'],
  /* tests/http/persistence.test.mjs's checkpoint interval and slack; the persistence targets (docs/formats.md's table) */
  ['docs/formats.md', 'interval (0.5 s, plus 0.8 s of'],
  ['docs/formats.md', '| < 2 % of one core |'],
  ['docs/formats.md', '| < 1 s |'],
  ['docs/formats.md', 'at the default 10 s'],
];

// Specification values on any page: [the exact words around the figure,
// their source]. One no page has fails, as SPEC's do.
export const EVERYWHERE = [
  ['within 1 %', 'the 1 % convention: docs/model-numerics.md §10'],
  ['the 1 % gate', 'the 1 % convention: docs/model-numerics.md §10'],
  ['The 1 % gate', 'the 1 % convention: docs/model-numerics.md §10'],
  ['beyond 1 %', 'the 1 % convention: docs/model-numerics.md §10'],
  ['95 % band', 'the band\'s definition: docs/calibration.md'],
  ['normal 97.5 % quantile', 'the band\'s definition: docs/calibration.md'],
  ['90 % reversal', 'the reversal time\'s definition: docs/control.md'],
  ['reach 90 %', 'the reversal time\'s definition: docs/control.md'],
  ['within 2 % of the setpoint', 'the settling time\'s definition: docs/control.md'],
  ['2 % settling', 'the settling time\'s definition: docs/control.md'],
  ['within 5 % of the DEM', 'the fast feed model\'s target: docs/feed-models.md'],
  ['5 % of the DEM peak', 'the fast feed model\'s target: docs/feed-models.md'],
];

// The unresolved plain percentages and wall times a page not yet gone
// through may still have (at most); README.md and the newcomer's path
// (getting-started.md) have none. A cap only goes down.
export const PENDING = new Map([
  ['docs/benchmarks.md', 39],
  ['docs/budgets.md', 16],
  ['docs/calibration.md', 13],
  ['docs/control-remote.md', 5],
  ['docs/control.md', 21],
  ['docs/dem.md', 8],
  ['docs/energy.md', 29],
  ['docs/feed-models.md', 12],
  ['docs/formats.md', 8],
  ['docs/integrators.md', 26],
  ['docs/machine-zoo.md', 61],
  ['docs/model-numerics.md', 16],
  ['docs/performance.md', 25],
]);

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
