#!/usr/bin/env python3
"""The one-assembly comparison's table and figure (docs/verification.md, "One assembly: the
direct-shear CI box in both codes"; scripts/parity_direct_shear.sh runs the codes).

Usage: python3 tests/parity/direct_shear_compare.py DIR [--figure PNG]

DIR holds one directory per run, each with a lab.csv (fdem's, or tests/parity/yade_direct_shear.py's,
the same columns): fdem_s<seed>_<sigma> (fdem packed seed <seed>; the first stress packs, the others
start from its specimen.h5), fdem_txt_s1_<sigma> (fdem from seed 1's specimen.txt: positions only,
as YADE starts) and yade_s<seed>_<sigma> (YADE from seed <seed>'s specimen.txt).

Per run, from the start of shearing (step 8000): the peak tau and the shear displacement at it,
tau at 3 / 6 / 9 mm, the residual tau (mean of 7-9 mm), the dilation (the plate's rise since the
start of shearing) at 3 / 6 / 9 mm, the mean sigma_n while shearing. Then, per sigma_n and
quantity, |YADE(s1) - fdem(s1)| against the yardstick |fdem(s1) - fdem(s2)| (the issue's
criterion) and against the range of all fdem seeds, and the RMS difference of the tau curves.
"""
import csv
import math
import os
import re
import sys

CONSOL = 8000
KEYS = [('peak', 'peak τ (kPa)', 1e-3, '%.2f'), ('dpeak', 'δ at the peak (mm)', 1e3, '%.2f'),
        ('t3', 'τ at 3 mm (kPa)', 1e-3, '%.2f'), ('t6', 'τ at 6 mm (kPa)', 1e-3, '%.2f'),
        ('t9', 'τ at 9 mm (kPa)', 1e-3, '%.2f'), ('tres', 'τ mean 7–9 mm (kPa)', 1e-3, '%.2f'),
        ('d3', 'dilation at 3 mm (mm)', 1e3, '%.3f'), ('d6', 'dilation at 6 mm (mm)', 1e3, '%.3f'),
        ('d9', 'dilation at 9 mm (mm)', 1e3, '%.3f'), ('sig', 'mean σ_n while shearing (kPa)', 1e-3, '%.2f')]


def load(path):
    with open(path) as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def summary(rows):
    sh = [r for r in rows if r['step'] >= CONSOL]
    z0 = sh[0]['normal_displacement']

    def at(d):
        return min(sh, key=lambda r: abs(r['shear_displacement'] - d))
    pk = max(sh, key=lambda r: r['tau'])
    s = {'peak': pk['tau'], 'dpeak': pk['shear_displacement']}
    for d in (3, 6, 9):
        a = at(d * 1e-3)
        s['t%d' % d] = a['tau']
        s['d%d' % d] = a['normal_displacement'] - z0
    res = [r['tau'] for r in sh if 7e-3 - 1e-9 <= r['shear_displacement'] <= 9e-3 + 1e-9]
    s['tres'] = sum(res) / len(res)
    s['sig'] = sum(r['sigma_n'] for r in sh[1:]) / len(sh[1:])
    s['curve'] = [(r['shear_displacement'], r['tau'], r['normal_displacement'] - z0) for r in sh]
    return s


def rms(a, b, lo=0.0, hi=1.0, col=1):
    n = min(len(a['curve']), len(b['curve']))
    ks = [k for k in range(n) if lo - 1e-9 <= a['curve'][k][0] <= hi + 1e-9]
    return math.sqrt(sum((a['curve'][k][col] - b['curve'][k][col]) ** 2 for k in ks) / len(ks))


def main(argv):
    if not argv or argv[0].startswith('-'):
        print(__doc__)
        return 2
    root = argv[0]
    fig = argv[argv.index('--figure') + 1] if '--figure' in argv else None
    runs = {}
    for d in sorted(os.listdir(root)):
        m = re.fullmatch(r'(fdem|fdem_txt|yade)_s(\d+)_(\d+)', d)
        if m and os.path.isfile(os.path.join(root, d, 'lab.csv')):
            runs[(m.group(1), int(m.group(2)), int(m.group(3)))] = summary(load(os.path.join(root, d, 'lab.csv')))
    sigmas = sorted({k[2] for k in runs})
    for sg in sigmas:
        cols = sorted([k for k in runs if k[2] == sg], key=lambda k: ({'yade': 0, 'fdem_txt': 1, 'fdem': 2}[k[0]], k[1]))
        print('\n#### σ_n = %.1f kPa\n' % (sg / 1e3))
        names = {'yade': 'YADE', 'fdem': 'fdem', 'fdem_txt': 'fdem (txt)'}
        y, f1, f2 = runs.get(('yade', 1, sg)), runs.get(('fdem', 1, sg)), runs.get(('fdem', 2, sg))
        y2 = runs.get(('yade', 2, sg))
        print('| quantity | ' + ' | '.join('%s s%d' % (names[k[0]], k[1]) for k in cols) +
              ' | \\|YADE − fdem\\| s1 | ' + ('\\|YADE − fdem\\| s2 | ' if y2 else '') +
              '\\|fdem s1 − s2\\| | fdem range | s1 within |')
        print('|---' * (len(cols) + 5 + (1 if y2 else 0)) + '|')
        fs = [runs[k] for k in cols if k[0] == 'fdem']
        for key, label, sc, fmt in KEYS:
            line = '| %s | ' % label + ' | '.join(fmt % (runs[k][key] * sc) for k in cols)
            if y and f1 and f2 and key != 'sig':
                dy, ds = abs(y[key] - f1[key]) * sc, abs(f1[key] - f2[key]) * sc
                rg = (max(f[key] for f in fs) - min(f[key] for f in fs)) * sc
                line += (' | ' + fmt) % dy
                if y2:
                    line += (' | ' + fmt) % (abs(y2[key] - f2[key]) * sc)
                line += (' | ' + fmt + ' | ' + fmt + ' | %s') % (ds, rg, 'yes' if dy <= ds else ('range' if dy <= rg else 'no'))
            else:
                line += ' | | | |' + (' |' if y2 else '')
            print(line + ' |')
        if y and f1 and f2:
            pairs = [('YADE s1 / fdem s1', y, f1), ('fdem (txt) s1 / fdem s1', runs.get(('fdem_txt', 1, sg)), f1),
                     ('YADE s1 / fdem (txt) s1', y, runs.get(('fdem_txt', 1, sg))), ('fdem s1 / fdem s2', f1, f2)]
            if runs.get(('yade', 2, sg)):
                pairs.append(('YADE s2 / fdem s2', runs[('yade', 2, sg)], f2))
            print('\n| RMS difference of the curves | τ 0–2 mm (kPa) | τ 2–9 mm (kPa) | dilation 0–9 mm (mm) |\n|---|---|---|---|')
            for n, a, b in pairs:
                if a and b:
                    print('| %s | %.2f | %.2f | %.3f |' % (n, rms(a, b, 0, 2e-3) / 1e3, rms(a, b, 2e-3, 9e-3) / 1e3,
                                                       rms(a, b, 0, 9e-3, 2) * 1e3))
    if fig:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        fg, ax = plt.subplots(2, len(sigmas), figsize=(5.5 * len(sigmas), 7), squeeze=False, sharex=True)
        style = {'yade': dict(color='C3', lw=2.0), 'fdem_txt': dict(color='C0', lw=1.2, ls='--'), 'fdem': dict(color='C0', lw=1.6)}
        for j, sg in enumerate(sigmas):
            for k in sorted(k for k in runs if k[2] == sg):
                s = runs[k]
                st = dict(style[k[0]])
                if k[0] == 'fdem' and k[1] != 1:
                    st = dict(color='C2', lw=1.6) if k[1] == 2 else dict(color='0.65', lw=1.0)
                if k[0] == 'yade' and k[1] != 1:
                    st = dict(color='C1', lw=2.0) if k[1] == 2 else dict(color='C1', lw=1.0)
                lab = {'yade': 'YADE', 'fdem': 'fdem', 'fdem_txt': 'fdem from txt'}[k[0]] + ' s%d' % k[1]
                d = [c[0] * 1e3 for c in s['curve']]
                ax[0][j].plot(d, [c[1] / 1e3 for c in s['curve']], label=lab, **st)
                ax[1][j].plot(d, [c[2] * 1e3 for c in s['curve']], **st)
            ax[0][j].set_title('σ_n = %.1f kPa' % (sg / 1e3))
            ax[0][j].set_ylabel('τ (kPa)')
            ax[1][j].set_ylabel('dilation (mm)')
            ax[1][j].set_xlabel('shear displacement δ (mm)')
            ax[0][j].grid(alpha=0.3)
            ax[1][j].grid(alpha=0.3)
        ax[0][0].legend(fontsize=8)
        fg.tight_layout()
        fg.savefig(fig, dpi=110)
        print('\nfigure: %s' % fig)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
