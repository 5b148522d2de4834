"""Two runs' meshes bit for bit and their summary.json figures to
round-off: the keys SAME (comma-separated) equal, or each number within
1e-10 of its own size (counts, places); the keys CLOSE each within 1e-10
of its magnitude; with REACTIONS (1), every reaction component within 1e-10
of the largest (a roller's along a free direction is round-off of the
load).
Usage: same_figures.py OUT_A OUT_B SAME CLOSE [REACTIONS]; exits 1 naming
the first key that differs."""
import json
import sys

import h5py
import numpy as np

a, b, same, close = sys.argv[1:5]
reactions = len(sys.argv) > 5 and sys.argv[5] == '1'
ma = h5py.File(a + '/results/mesh.h5', 'r')
mb = h5py.File(b + '/results/mesh.h5', 'r')
assert all(np.array_equal(ma[k][()], mb[k][()]) for k in ma), 'mesh'
sa = json.load(open(a + '/summary.json'))
sb = json.load(open(b + '/summary.json'))
for k in filter(None, same.split(',')):
    assert sa[k] == sb[k] or np.allclose(sa[k], sb[k], rtol=1e-10), k
for k in filter(None, close.split(',')):
    assert abs(sa[k] - sb[k]) <= 1e-10 * abs(sa[k]), (k, sa[k], sb[k])
if reactions:
    ra, rb = ([v for c in sorted(s['reactions']) for v in s['reactions'][c]]
              for s in (sa, sb))
    assert np.abs(np.subtract(ra, rb)).max() <= 1e-10 * np.abs(ra).max(), \
        (ra, rb)
