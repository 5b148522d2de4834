"""same-builds.py BEFORE AFTER: every run folder in BEFORE against the one of
the same name in AFTER: frames and history rows bit for bit (the wall time
aside), summary.json's figures (timings, rates, memory and paths aside).
Prints one line a run and the count that differ; exits 1 if any does."""
import sys, os, json, csv, h5py, numpy as np
A, B = sys.argv[1], sys.argv[2]
skip = ('seconds', 'per_second', 'scene', 'per_core', 'memory_bytes', 'rss', 'stage_seconds', 'wall')
def flat(x, p=''):
    if isinstance(x, dict):
        for k, v in x.items():
            if any(s in k for s in skip): continue
            yield from flat(v, p + '.' + k)
    elif isinstance(x, list):
        for i, v in enumerate(x): yield from flat(v, p + '[%d]' % i)
    else: yield p, x
bad = 0
for d in sorted(os.listdir(A)):
    a, b = os.path.join(A, d), os.path.join(B, d)
    if not os.path.isdir(a): continue
    msg = []
    if not os.path.isdir(b): print(d, 'MISSING'); bad += 1; continue
    try:
        if os.path.exists(a + '/results.h5'):
            fa, fb = h5py.File(a + '/results.h5', 'r'), h5py.File(b + '/results.h5', 'r')
            ka, kb = sorted(fa['frames']), sorted(fb['frames'])
            if ka != kb: msg.append('frames %d vs %d' % (len(ka), len(kb)))
            for k in ka:
                if k not in fb['frames']: continue
                for f in fa['frames'][k]:
                    x, y = fa['frames'][k][f][()], fb['frames'][k][f][()]
                    if not np.array_equal(x, y): msg.append('frame %s %s' % (k, f))
        if os.path.exists(a + '/history.csv'):
            ra = list(csv.reader(open(a + '/history.csv'))); rb = list(csv.reader(open(b + '/history.csv')))
            w = ra[0].index('wall_seconds') if 'wall_seconds' in ra[0] else None
            if len(ra) != len(rb): msg.append('history rows %d vs %d' % (len(ra), len(rb)))
            for x, y in zip(ra, rb):
                if w is not None and len(x) > w and len(y) > w: x[w] = y[w] = ''
                if x != y: msg.append('history row differs: %s' % x[:3]); break
        if os.path.exists(a + '/summary.json'):
            sa = dict(flat(json.load(open(a + '/summary.json'))))
            sb = dict(flat(json.load(open(b + '/summary.json'))))
            for k in sorted(set(sa) | set(sb)):
                if sa.get(k, 'ABSENT') != sb.get(k, 'ABSENT'):
                    msg.append('summary %s: %s vs %s' % (k, sa.get(k, 'ABSENT'), sb.get(k, 'ABSENT')))
    except Exception as e:
        msg.append('error %r' % e)
    print(d, 'same' if not msg else 'DIFFERS')
    for m in msg[:8]: print('   ', m)
    bad += bool(msg)
print(bad, "differ")
sys.exit(1 if bad else 0)
