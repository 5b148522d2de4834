"""The fields two runs' frames are compared on (same_results.py and
same_to_roundoff.py): every dataset but a frame's index in pieces, the same
names in both.  A frame written in pieces has its geometry, "position",
where FPM's gathered frame (drawn over the mesh's cells) has none: it is
compared where both have it."""


def compared_fields(ga, gb, frame):
    na, nb = ({f for f in g if f != 'index'} for g in (ga, gb))
    if ('position' in na) != ('position' in nb):
        na.discard('position')
        nb.discard('position')
    names = sorted(na)
    assert names == sorted(nb), (frame, names)
    return names
