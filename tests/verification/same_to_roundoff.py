"""Two runs' results and history agree to round-off: the same frames (step
and time), the same fields, each within TOL of the first run's largest
magnitude of that field in that frame, and every history column (the wall
time aside) within TOL of the column's largest magnitude, where values one
unit of their 10th significant digit apart count as equal (history.csv
prints 10 digits: a difference of 1e-16 that straddles a rounding shows
as one unit, up to 1e-9 of the value).  Fields and columns
that are zero to 1e-12 of their scale compare absolutely.  The step size dt
compares on the scale of the time: the last step is cut to end at
time.end, dt = t_end - t, so it carries the round-off of t, an absolute
time error.  Reactions compare on the scale of the run's largest reaction:
one whose exact value is 0 (a roller's along a free direction) carries the
round-off of the load.
Usage: same_to_roundoff.py OUT_A OUT_B TOL [COLUMN=BOUND ...]; prints the
largest relative difference and exits 1 when it exceeds TOL.  A history
column named with its own BOUND is held to that instead (one whose round-off
on one process is larger: dynamic relaxation's damping coefficient is
2 sqrt((s3 - s1) / s2), a difference of two sums that nearly cancel), and
its difference is printed apart.  Frames written in pieces across ranks
are compared in one-process order."""
import csv
import os
import sys

import h5py
import numpy as np

# A frame written in pieces across ranks is read in one-process order.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                '..', '..', 'python'))
import pointmech  # noqa: E402
from frame_fields import compared_fields  # noqa: E402

a, b, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
own = {k: float(v) for k, v in (x.split('=') for x in sys.argv[4:])}
apart = {}
fa, fb = h5py.File(a + '/results.h5', 'r'), h5py.File(b + '/results.h5', 'r')
ka, kb = sorted(fa['frames']), sorted(fb['frames'])
assert ka == kb, (len(ka), len(kb))
worst, where = 0.0, ''
for k in ka:
    ga, gb = fa['frames'][k], fb['frames'][k]
    assert ga.attrs['step'] == gb.attrs['step'], (k, 'step')
    assert abs(ga.attrs['time'] - gb.attrs['time']) <= tol * abs(ga.attrs['time']) + 1e-300, (k, 'time')
    names = compared_fields(ga, gb, k)
    for f in names:
        x, y = pointmech.read_rows(ga, f), pointmech.read_rows(gb, f)
        assert x.shape == y.shape, (k, f, x.shape, y.shape)
        if not np.array_equal(np.isnan(x), np.isnan(y)):
            worst, where = float('inf'), 'frame %s %s: NaN in one run' % (k, f)
            continue
        x, y = np.nan_to_num(x), np.nan_to_num(y)
        scale = np.max(np.abs(x)) if x.size else 0.0
        d = np.max(np.abs(x - y)) if x.size else 0.0
        rel = d / scale if scale > 1e-12 else d
        if rel > worst:
            worst, where = rel, 'frame %s %s' % (k, f)
ra = list(csv.reader(open(a + '/history.csv')))
rb = list(csv.reader(open(b + '/history.csv')))
reaction = max([abs(float(r[c])) for r in ra[1:]
                for c, name in enumerate(ra[0])
                if name.startswith('reaction_') and r[c] != 'nan'] + [0.0])
assert len(ra) == len(rb) and ra[0] == rb[0], (len(ra), len(rb))
for c, name in enumerate(ra[0]):
    if name == 'wall_seconds':
        continue
    x = np.array([float(r[c]) for r in ra[1:]])
    y = np.array([float(r[c]) for r in rb[1:]])
    if not np.array_equal(np.isnan(x), np.isnan(y)):
        worst, where = float('inf'), 'history %s: NaN in one run' % name
        continue
    x, y = x[~np.isnan(x)], y[~np.isnan(y)]
    scale = np.max(np.abs(x)) if x.size else 0.0
    if name == 'dt':
        scale = max(scale, max(abs(float(r[0])) for r in ra[1:]))
    if name.startswith('reaction_'):
        scale = max(scale, reaction)
    # history.csv prints 10 significant digits: values that differ by one
    # unit of the last (a real difference of any size that straddles a
    # rounding) cannot be told apart, and count as equal.
    dd = np.abs(x - y)
    big = np.maximum(np.abs(x), np.abs(y))
    unit = np.where(big > 0, 10.0 ** (np.floor(np.log10(np.where(big > 0, big, 1))) - 9), 0)
    dd = np.where(dd <= unit * (1 + 1e-6), 0.0, dd)
    d = np.max(dd) if x.size else 0.0
    rel = d / scale if scale > 1e-12 else d
    if name in own:
        apart[name] = rel
    elif rel > worst:
        worst, where = rel, 'history %s' % name
print('%d frames, %d rows: largest relative difference %.3g (%s)%s' %
      (len(ka), len(ra) - 1, worst, where or 'none',
       ''.join('; %s %.3g (bound %g)' % (k, apart[k], own[k])
               for k in sorted(apart))))
sys.exit(0 if worst <= tol and all(apart[k] <= own[k] for k in apart)
         else 1)
