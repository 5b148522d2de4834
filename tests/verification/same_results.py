"""Two runs' results and history are the same bit for bit (the wall time
column aside): every frame's step, time and fields, and every history row.
Usage: same_results.py OUT_A OUT_B"""
import sys, h5py, numpy as np, csv
a, b = sys.argv[1], sys.argv[2]
fa, fb = h5py.File(a + '/results.h5', 'r'), h5py.File(b + '/results.h5', 'r')
na, nb = len(fa['frames']), len(fb['frames'])
assert na == nb, (na, nb)
for k in fa['frames']:
    ga, gb = fa['frames'][k], fb['frames'][k]
    assert ga.attrs['step'] == gb.attrs['step'] and ga.attrs['time'] == gb.attrs['time'], k
    for f in ga:
        assert np.array_equal(ga[f][()], gb[f][()]), (k, f)
ra = list(csv.reader(open(a + '/history.csv'))); rb = list(csv.reader(open(b + '/history.csv')))
assert len(ra) == len(rb), (len(ra), len(rb))
w = ra[0].index('wall_seconds')
for x, y in zip(ra, rb):
    x[w] = y[w] = ''
    assert x == y, (x, y)
print('identical:', na, 'frames,', len(ra) - 1, 'rows')
