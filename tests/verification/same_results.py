"""Two runs' results and history are the same bit for bit (the wall time
column aside): every frame's step, time and fields, and every history row;
with --frames the frames alone (the caller compares the history otherwise).
Frames written in pieces across ranks compare in one-process order.
Usage: same_results.py [--frames] OUT_A OUT_B"""
import sys, os, h5py, numpy as np, csv
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                '..', '..', 'python'))
import pointmech  # noqa: E402
from frame_fields import compared_fields  # noqa: E402
frames_only = sys.argv[1] == '--frames'
a, b = sys.argv[1 + frames_only], sys.argv[2 + frames_only]
fa, fb = h5py.File(a + '/results.h5', 'r'), h5py.File(b + '/results.h5', 'r')
na, nb = len(fa['frames']), len(fb['frames'])
assert na == nb, (na, nb)
for k in fa['frames']:
    ga, gb = fa['frames'][k], fb['frames'][k]
    assert ga.attrs['step'] == gb.attrs['step'] and ga.attrs['time'] == gb.attrs['time'], k
    names = compared_fields(ga, gb, k)
    for f in names:
        assert np.array_equal(pointmech.read_rows(ga, f),
                              pointmech.read_rows(gb, f)), (k, f)
if frames_only:
    print('identical:', na, 'frames')
    sys.exit(0)
ra = list(csv.reader(open(a + '/history.csv'))); rb = list(csv.reader(open(b + '/history.csv')))
assert len(ra) == len(rb), (len(ra), len(rb))
w = ra[0].index('wall_seconds')
for x, y in zip(ra, rb):
    x[w] = y[w] = ''
    assert x == y, (x, y)
print('identical:', na, 'frames,', len(ra) - 1, 'rows')
