#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The result page of tests/bench/calibration.sh: reads the fits' JSON in
WORK (e.json, two_NAME.json, mu_one.json, preset.json) and prints
tests/bench/results/calibration.md. Arguments: WORK PROVENANCE SECONDS
(the second parameters as NAME:LO:HI, space-separated)."""
import json
import sys

PAPER = (38, 128)
LABEL = {'m_n': 'feed element mass', 'mu': 'friction', 'omega_ss': 'synchronous speed',
         'k_c': 'contact stiffness', 'R': 'restitution'}


def num(v, sig=4):
    """v with sig significant digits, as a person writes it (7.7e6, not 7.7e+06)."""
    s = f'{v:.{sig}g}'
    if 'e' in s:
        m, x = s.split('e')
        s = f'{m}e{int(x)}'
    return s


def signed(v, d=1):
    return f'{"−" if v < 0 else "+"}{abs(v):.{d}f}'


def peaks(r, key='model', d=2):
    return ', '.join(f'{p[key]:.{d}f}' for p in r['peaks'])


def resid(r, key='model', d=2):
    return ', '.join(signed(p[key] - p['measured'], d) for p in r['peaks'])


def cond(c):
    return f'{c:.1f}' if c < 10 else f'{c:.0f}'


def load(work, name):
    with open(f'{work}/{name}.json') as f:
        return json.load(f)


def table_one(work):
    e, pre = load(work, 'e'), load(work, 'preset')
    p = e['parameters'][0]
    print('| model | e / m | clockwise peaks / ° | residuals / ° | peaks\' uncertainty / ° '
          '| iterations | evaluations | CPU / s |')
    print('|---|---|---|---|---|---|---|---|')
    print(f'| czubak2016 as printed | {num(p["start"])} | {peaks(e, "model_start", 1)} '
          f'| {resid(e, "model_start", 1)} | – | – | – | – |')
    unc = ', '.join(f'{q["model_uncertainty"]:.2f}' for q in e['peaks'])
    print(f'| e alone fitted | {num(p["value"], 3)} ± {num(p["standard_error"], 2)} '
          f'| {peaks(e, d=1)} | {resid(e, d=1)} | {unc} | {e["iterations"]} '
          f'| {e["evaluations"]} | {e["cpu_seconds"]:.1f} |')
    pe, pm = pre['parameters']
    print(f'| preset czubak2016-fit | {num(pe["start"])} (m_n = {num(pm["start"])} kg) '
          f'| {peaks(pre, "model_start")} '
          f'| {resid(pre, "model_start")} | – | – | – | – |')


def spread(runs, i):
    vals = [s['value'][i] for s in runs]
    return num(max(vals) - min(vals), 2)


def table_two(work, seconds):
    print('| second parameter (bounds) | e / m | second | clockwise peaks / ° | residuals / ° '
          '| condition number | the 4 runs\' χ² / deg² | their ends apart: e / m, second '
          '| runs on a bound |')
    print('|---|---|---|---|---|---|---|---|---|')
    notes = []
    for spec in seconds:
        name, lo, hi = spec.split(':')
        r = load(work, f'two_{name}')
        e, s = r['parameters']
        unit = f' {s["unit"]}' if s['unit'] and s['unit'] != '1' else ''
        ok = [x for x in r['starts'] if x['status'] != 'failed']
        chi = ', '.join(f'{x["chi2"]:.2f}' for x in r['starts'])
        bound = sum(1 for x in ok if any(
            abs(v - q[k]) <= 1e-6 * (q['max'] - q['min'])
            for v, q in zip(x['value'], r['parameters']) for k in ('min', 'max')))
        print(f'| `{name}` {LABEL.get(name, name)} ({lo}…{hi}{unit}) | {num(e["value"])} '
              f'| {num(s["value"])}{unit} | {peaks(r)} | {resid(r)} '
              f'| {cond(r["condition_number"])} | {chi} | {spread(ok, 0)}, {spread(ok, 1)} '
              f'| {bound} |')
        for w in r['warnings']:
            if not w.startswith('as many data as free parameters'):
                notes.append(f'- `{name}`: {w}')
    return notes


def table_three(work):
    r = load(work, 'mu_one')
    e, mu = r['parameters']
    print('| from the default start | status | iterations | evaluations | e / m | mu '
          '| clockwise peaks / ° |')
    print('|---|---|---|---|---|---|---|')
    print(f'| e and mu, 1 start | {r["status"]} | {r["iterations"]} | {r["evaluations"]} '
          f'| {num(e["value"])} | {num(mu["value"])} | {peaks(r)} |')
    m = load(work, 'two_mu')
    print(f'| e and mu, 4 starts | {m["status"]} | {m["iterations"]} | {m["evaluations"]} '
          f'| {num(m["parameters"][0]["value"])} | {num(m["parameters"][1]["value"])} '
          f'| {peaks(m)} |')


def near(beta, grid):
    return min(range(len(grid)), key=lambda k: abs(grid[k] - beta))


def table_four(work):
    r = load(work, 'two_m_n')
    e, m = r['parameters']
    c, cw = r['curve'], r['curve']['cw']
    grid = c['beta']
    mark_s = {near(p['model_start'], grid): p['model_start'] for p in r['peaks']}
    mark_f = {near(p['model'], grid): (p['model'], p['measured']) for p in r['peaks']}
    print(f'| β / ° | v, czubak2016 (e = {num(e["start"])} m, m_n = {num(m["start"])} kg) '
          f'| v, fitted (e = {num(e["value"])} m, m_n = {num(m["value"])} kg) |')
    print('|---|---|---|')
    for k, b in enumerate(grid):
        s = f'{cw["start"][k]:.4f}'.replace('-', '−')
        if k in mark_s:
            s += f' (peak {mark_s[k]:.1f}°)'
        f = f'{cw["fit"][k]:.4f} ± {cw["fit_uncertainty"][k]:.4f}'.replace('-', '−')
        if k in mark_f:
            f += f' (peak {mark_f[k][0]:.1f}°; the paper: {mark_f[k][1]:g}°)'
        print(f'| {b:g} | {s} | {f} |')
    return r


def main():
    work, prov, seconds = sys.argv[1], sys.argv[2], sys.argv[3].split()
    print('# Calibration: the czubak2016 model fitted to the paper\'s peaks')
    print()
    print(prov)
    print('Made by `bash tests/bench/calibration.sh` (`make bench-calibration`), every fit')
    print(f'`convsim fit --peaks cw:{PAPER[0]},cw:{PAPER[1]} ... --threads 2` (docs/calibration.md).')
    print()
    print('The model at the printed e, e alone fitted (`--free e:0.005:0.04 --curve-step 0`) and the')
    print('preset czubak2016-fit (`--preset czubak2016-fit --free e,m_n --max-iter 1`, its start):')
    print()
    table_one(work)
    print()
    print('e with a second parameter, each from 4 starts (`--free e:0.005:0.04,NAME:LO:HI')
    print('--starts 4 --curve-step 0`; m_n with `--curve-step 10`, table 4). Two peaks, two')
    print('parameters: no residual variance, no standard errors (each fit warns so).')
    print()
    notes = table_two(work, seconds)
    print()
    print('Their warnings:')
    print()
    print('\n'.join(notes) if notes else '- none')
    print()
    print('e and mu (`--free e:0.005:0.04,mu:0.1:1.5 --curve-step 0`), one start and four:')
    print()
    table_three(work)
    print()
    r = load(work, 'two_m_n')
    unc = ', '.join(f'{p["model_uncertainty"]:.2f}' for p in r['peaks'])
    print(f'The m_n fit: {r["status"]} after {r["iterations"]} iterations, '
          f'{r["evaluations"]} evaluations, {r["cpu_seconds"]:.1f} CPU s, the best of its runs '
          f'number {r["best_start"] + 1}; its peaks\' uncertainty {unc}°.')
    print('Its curve, clockwise, every 10° (`start` and `fit` with its error bar, v in m/s):')
    print()
    table_four(work)


if __name__ == '__main__':
    main()
