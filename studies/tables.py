#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""Markdown tables of the study CSVs (studies/run.sh), in the layout of the docs/ sections they regenerate.

  tables.py CSV_DIR_OR_FILE...

Each PROGRAM-NAME.csv (written by lumx_study_PROGRAM NAME) becomes a heading naming the docs section and
its tables, printed to stdout; files of no known study are reported on stderr and skipped. Every CSV has
its study's key columns, then quantity, d, value (studies/study_support.h). Exits 1 if a file cannot be
read or lacks a column its table needs. Standard library only.
"""
import csv
import os
import sys
from collections import OrderedDict
from decimal import ROUND_HALF_UP, Decimal


class Rows:
    """A study's CSV: rows as dicts, value as float, d as float or None."""

    def __init__(self, path):
        with open(path, newline='', encoding='utf-8') as f:
            self.rows = list(csv.DictReader(f))
        for r in self.rows:
            r['value'] = float(r['value'])
            r['d'] = float(r['d']) if r['d'] != '' else None

    def where(self, **match):
        return [r for r in self.rows if all(r[k] == v for k, v in match.items())]

    def groups(self, keys, **match):
        """Ordered {tuple of key values: [rows]} in first-seen order."""
        out = OrderedDict()
        for r in self.where(**match):
            out.setdefault(tuple(r[k] for k in keys), []).append(r)
        return out

    def distances(self, **match):
        ds = []
        for r in self.where(**match):
            if r['d'] is not None and r['d'] not in ds:
                ds.append(r['d'])
        return ds


def by_d(rows, quantity):
    return {r['d']: r['value'] for r in rows if r['quantity'] == quantity and r['d'] is not None}


def one(rows, quantity):
    for r in rows:
        if r['quantity'] == quantity and r['d'] is None:
            return r['value']
    return None


def d_label(d):
    return f'{d:g}'


def fixed(v, places):
    """v to `places` decimals, halves rounded away from zero (as the docs round), '' for None."""
    if v is None:
        return ''
    return str(Decimal(repr(v)).quantize(Decimal(1).scaleb(-places), rounding=ROUND_HALF_UP))


def f2(v):
    return fixed(v, 2)


def f1(v):
    return fixed(v, 1)


def sig3(v):
    """As docs/render.md: one decimal below 100, none above."""
    return fixed(v, 0) if abs(v) >= 100 else fixed(v, 1)


def table(header, rows):
    out = ['| ' + ' | '.join(header) + ' |', '|' + '---|' * len(header)]
    out += ['| ' + ' | '.join(str(c) for c in row) + ' |' for row in rows]
    return '\n'.join(out)


def d_header(ds, first='d = '):
    return [first + d_label(ds[0])] + [d_label(d) for d in ds[1:]]


def rays_label(n):
    n = int(n)
    return f'{n // 1000000} M' if n % 1000000 == 0 else f'{n // 1000} k'


# ---- lumx_study_pinhole_box ---------------------------------------------------------------------------

def pinhole_box_borders(t):
    ds = t.distances()
    rows = []
    for (emitted, leaving, R, apls), g in t.groups(['emitted_rays', 'leaving_rays', 'R', 'apls']).items():
        e = by_d(g, 'relative_rmse_pct')
        rows.append([f'{rays_label(emitted)} ({rays_label(leaving)} leave)', R, apls] + [f2(e.get(d)) for d in ds])
    return table(['rays', 'R', 'APLs'] + d_header(ds), rows)


def map_bytes(R):
    b = 2 * R * R * 4
    return f'{b // (1 << 20)} MiB' if b >= 1 << 20 else f'{b // 1024} KiB'


def pinhole_box_exact_beams(t):
    ds = t.distances()
    rows, carriers = [], []
    for (R, reading), g in t.groups(['R', 'reading']).items():
        e = by_d(g, 'relative_rmse_pct')
        label = f'{R} ({map_bytes(int(R))})' if reading == 'bilinear' else f'{R}, nearest texel'
        rows.append([label] + [f2(e.get(d)) for d in ds])
        if reading == 'bilinear':
            c, lit, ratio = by_d(g, 'carrier_points'), by_d(g, 'lit_points'), by_d(g, 'lit_mean_over_mean')
            carriers.append([R] + [f'{fixed(c[d], 0)} / {fixed(lit[d], 0)} / {fixed(ratio[d], 1)}×' for d in ds])
    points = one(t.where(reading='bilinear'), 'points')
    out = table(['R (map bytes, one channel)'] + d_header(ds), rows)
    out += ('\n\nPoints carrying 90 % of the squared error / lit points / the lit points\' mean irradiance over the '
            f'sphere\'s mean ({fixed(points, 0)} points per sphere):\n\n')
    out += table(['R'] + d_header(ds), carriers)
    return out


def pinhole_box_beam_masks(t):
    ds = t.distances()
    labels = {'two_at_sources': 'two APLs at the sources, maps binned from the rays',
              'builder_512': "the builder's 512 APLs, each masked by the lines through it",
              'builder_512_placed': 'the same level, each ray moved to the APL its line passes nearest'}
    rows = []
    for s in labels:
        first = True
        for R in OrderedDict.fromkeys(r['R'] for r in t.where(set=s) if r['R']):
            cells = []
            for reading in ('plain', 'masked'):
                e = by_d(t.where(set=s, R=R, reading=reading), 'relative_rmse_pct')
                cells.append(' / '.join(f1(e[d]) for d in ds) if e else '')
            rows.append([labels[s] if first else '', R] + cells)
            first = False
    out = table(['set', 'R', 'plain, d = ' + ' / '.join(d_label(d) for d in ds), 'masked'], rows)
    lines = []
    src = t.where(set='two_at_sources', R='')
    lines.append(f"- The sources' masks: {fixed(one(src, 'source_1_caps'), 0)} and {fixed(one(src, 'source_2_caps'), 0)} caps.")
    for R in OrderedDict.fromkeys(r['R'] for r in t.where(set='builder_512', reading='')):
        g = t.where(set='builder_512', R=R, reading='')
        p = t.where(set='builder_512_placed', R=R, reading='')
        least, median, most = one(g, 'off_source_least_mm'), one(g, 'off_source_median_mm'), one(g, 'off_source_most_mm')
        off = (f'; the others {fixed(least, 1)}–{fixed(most, 1)} mm from the nearer source (median {fixed(median, 1)} mm)'
               if least is not None else '')
        lines.append(f"- R {R}: {fixed(one(g, 'masks'), 0)} masks, {fixed(one(g, 'masked_apls'), 0)} APLs masked holding "
                     f"{fixed(one(g, 'masked_flux_pct'), 1)} % of the flux{off}; the sources "
                     f"{fixed(one(g, 'sources_apart_mm'), 1)} mm apart. Placed: {fixed(one(p, 'empty_apls'), 0)} APLs left "
                     f"empty, {fixed(one(p, 'masked_flux_pct'), 1)} % of the flux masked.")
    return out + '\n\n' + '\n'.join(lines)


def pinhole_box_masked_estimate(t):
    per_seed = [r for r in t.rows if r['seed'] != 'all']
    ds = []
    for r in per_seed:
        if r['d'] not in ds:
            ds.append(r['d'])
    rows = []
    for (seed, R, masked), g in t.groups(['seed', 'R', 'masked']).items():
        if seed == 'all':
            continue
        truth, est, res, up, border = (by_d(g, q) for q in
                                       ('truth_pct', 'estimate_pct', 'resolved', 'upper_pct', 'border_share_pct'))
        cells = [f"{fixed(truth[d], 1)} / {fixed(est[d], 1)}{'' if res[d] else '<'} / {fixed(up[d], 1)} ({fixed(border[d], 1)})" for d in ds]
        rows.append([seed, R + ('' if masked == '1' else ', not masked')] + cells)
    out = table(['seed', 'R'] + d_header(ds), rows)
    a = t.where(seed='all')
    out += ('\n\nPer sphere: the truth / the estimate with the noise removed (`<`: unresolved) / its upper bound '
            '(the border allowance), %.\n\n')
    out += (f"{fixed(one(a, 'spheres'), 0)} spheres, {fixed(one(a, 'spikes'), 0)} with the truth above 10 %: the upper bound "
            f"below 3/4 of the truth at {fixed(one(a, 'flatters'), 0)}, resolved and more than 25 % off at "
            f"{fixed(one(a, 'resolved_off'), 0)}.")
    return out


# ---- lumx_study_far_field ------------------------------------------------------------------------------

def far_field_wider_kernels(t):
    ds = t.distances()
    rows = []
    for (em, apls, R0, kernel, R, sigma), g in t.groups(['emitter', 'level0_apls', 'level0_R', 'kernel', 'R',
                                                          'sigma_deg']).items():
        e, h = by_d(g, 'relative_rmse_pct'), by_d(g, 'horizon_share_pct')
        what = kernel if kernel in ('exact intensity', 'none') else f'{kernel}, σ {fixed(float(sigma), 1)}°'
        rows.append([f'{em} (level 0: {apls} APLs, R {R0})', what, R] + [f2(e.get(d)) for d in ds] +
                    [f'{fixed(h[ds[-1]], 0)}'])
    return table(['emitter', 'kernel', 'R'] + d_header(ds) + [f'% of the squared error within 15° of the horizon, d = {d_label(ds[-1])}'],
                 rows)


# ---- lumx_study_spot -----------------------------------------------------------------------------------

def spot_name(em):
    return em.split(' spot')[0]


def spot_more_rays(t):
    ds = t.distances()
    rows = []
    for (em, frame, rays, m, apls, R, kernel, sigma), g in t.groups(
            ['emitter', 'frame', 'rays', 'map', 'apls', 'R', 'kernel', 'sigma_deg']).items():
        e = by_d(g, 'relative_rmse_pct')
        if m == 'exact at the centre':
            what = f'exact map, one APL at the centre, R {R}'
        else:
            k = '' if kernel == 'none' else f' σ {fixed(float(sigma), 1)}° {kernel}'
            what = f'{frame} frame, {rays_label(rays)} rays, {m} (R {R}{k})'
        rows.append([spot_name(em), what] + [f2(e.get(d)) for d in ds])
    return table(['spot', 'finest level'] + d_header(ds), rows)


def spot_bias_noise(t):
    ds = t.distances(seed='all')
    rows, choices = [], []
    for (em, turn), g in t.groups(['emitter', 'turned_deg'], seed='all').items():
        rms, bias, noise = by_d(g, 'rms_pct'), by_d(g, 'bias_pct'), by_d(g, 'noise_pct')
        name = spot_name(em) + ('' if float(turn) == 0 else f' turned {float(turn):g}° about y')
        rows.append([name, 'RMS of a set'] + [f2(rms[d]) for d in ds])
        rows.append(['', 'bias / noise'] + [f'{fixed(bias[d], 2)} / {fixed(noise[d], 2)}' for d in ds])
        per_seed = t.groups(['seed', 'kernel'], emitter=em, turned_deg=turn)
        picks = [f"seed {s}: R {fixed(one(g2, 'R'), 0)} σ {fixed(one(g2, 'sigma_deg'), 1)}° {k}"
                 for (s, k), g2 in per_seed.items() if s != 'all']
        choices.append(f'- {name}: ' + '; '.join(picks))
    seeds = len([k for k in t.groups(['seed'], emitter=t.rows[0]['emitter'], turned_deg=t.rows[0]['turned_deg'])
                 if k[0] != 'all'])
    out = table(['spot (finest level)', f'{seeds} seeds'] + d_header(ds), rows)
    return out + '\n\nThe fit\'s choice for the finest level, per seed:\n\n' + '\n'.join(choices)


def spot_wide_two_scale(t):
    ds = t.distances()
    rows = []
    for (em, seed, apls, R, kernel, sigma), g in t.groups(['emitter', 'seed', 'apls', 'R', 'kernel',
                                                           'sigma_deg']).items():
        e = by_d(g, 'relative_rmse_pct')
        rows.append([spot_name(em), seed, f'{apls} APLs, R {R}, σ {fixed(float(sigma), 1)}° {kernel}'] +
                    [f2(e.get(d)) for d in ds])
    return table(['spot', 'seed', 'finest level'] + d_header(ds), rows)


# ---- lumx_study_kernel_density -------------------------------------------------------------------------

def n_label(n):
    n = int(n)
    e = len(str(n)) - 1
    return f'10{str(e).translate(str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹"))}' if n == 10 ** e else str(n)


def kernel_density_figures(t):
    rows, gaps = [], []
    seeds = None
    previous = None
    for (field, n, seeds, region), g in t.groups(['field', 'deposits', 'seeds', 'region']).items():
        cells = []
        for est in ('adaptive', 'fixed', 'histogram'):
            e = [r for r in g if r['estimator'] == est]
            c = f"{sig3(one(e, 'bias_pct'))} / {sig3(one(e, 'sd_pct'))} / **{sig3(one(e, 'rmse_pct'))}** %"
            if est == 'adaptive':
                c += f" ({fixed(one(e, 'seed_sd_pct'), 2)})"
            cells.append(c)
        shown_region = 'shadow' if field == 'shadow edge' and region == 'sparse' else region
        first = (field, n) != previous
        rows.append([field if first else '', n_label(n) if first else '', shown_region] + cells)
        previous = (field, n)
        gap = [r for r in g if r['estimator'] == 'adaptive - fixed']
        gaps.append(f"- {field}, {n_label(n)}, {shown_region}: {'+' if one(gap, 'mean_pct') >= 0 else ''}{f2(one(gap, 'mean_pct'))} % "
                    f"(sd {fixed(one(gap, 'sd_pct'), 2)})")
    out = table(['field', 'N', 'region', 'adaptive bias / sd / RMSE (seed sd)', 'fixed kernel bias / sd / RMSE',
                 'histogram bias / sd / RMSE'], rows)
    return (out + f'\n\nPaired differences adaptive − fixed of one seed\'s RMSE (mean, sd across {seeds} seeds):\n\n' +
            '\n'.join(gaps))


STUDIES = OrderedDict([
    ('pinhole_box-borders', ('docs/apl_sets.md, "Honest error": the box with holes (more rays do not rescue it)',
                             pinhole_box_borders)),
    ('pinhole_box-exact-beams', ('docs/apl_sets.md, "Honest error": what maps can do on the box at all',
                                 pinhole_box_exact_beams)),
    ('pinhole_box-beam-masks', ('docs/apl_sets.md, "Honest error": beam masks, borders as geometry',
                                pinhole_box_beam_masks)),
    ('pinhole_box-masked-estimate', ('docs/apl_sets.md, "Point sources behind apertures": the held-out estimate '
                                     'of the masked level over 20 rayings', pinhole_box_masked_estimate)),
    ('far_field-wider-kernels', ('docs/apl_sets.md, "Honest error": local linear kernels, and the IES far field '
                                 'of the Lambertian emitters', far_field_wider_kernels)),
    ('spot-more-rays', ('docs/apl_sets.md, "Honest error": the spots (what more rays buy) and the map frame',
                        spot_more_rays)),
    ('spot-bias-noise', ('docs/apl_sets.md, "Honest error": bias against noise', spot_bias_noise)),
    ('spot-wide-two-scale', ('docs/apl_sets.md, "Honest error": two-scale at 4.5 texel widths', spot_wide_two_scale)),
    ('kernel_density-figures', ('docs/render.md, "Adaptive-kernel reconstruction": the table of 32 seeds',
                                kernel_density_figures)),
])


def main(argv):
    if len(argv) < 2 or argv[1] in ('-h', '--help'):
        print(__doc__.strip(), file=sys.stdout if len(argv) >= 2 else sys.stderr)
        return 0 if len(argv) >= 2 else 2
    files = []
    for a in argv[1:]:
        if os.path.isdir(a):
            files += [os.path.join(a, f) for f in sorted(os.listdir(a)) if f.endswith('.csv')]
        else:
            files.append(a)
    order = list(STUDIES)
    files.sort(key=lambda f: order.index(os.path.basename(f)[:-4]) if os.path.basename(f)[:-4] in order else len(order))
    status = 0
    for f in files:
        stem = os.path.basename(f)[:-4] if f.endswith('.csv') else os.path.basename(f)
        if stem not in STUDIES:
            print(f'tables.py: {f}: not the CSV of a known study, skipped', file=sys.stderr)
            continue
        section, make = STUDIES[stem]
        try:
            text = make(Rows(f))
        except (OSError, KeyError, ValueError, TypeError, IndexError, csv.Error) as e:
            print(f'tables.py: {f}: {type(e).__name__}: {e}', file=sys.stderr)
            status = 1
            continue
        program, name = stem.split('-', 1)
        print(f'## {section}\n\n`lumx_study_{program} {name}` ({f}):\n\n{text}\n')
    return status


if __name__ == '__main__':
    sys.exit(main(sys.argv))
