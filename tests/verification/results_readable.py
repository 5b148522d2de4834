"""A run's results read back: results.h5 opens with h5py and every frame it
lists exists (as many as its attribute says); results.xdmf parses and
points only at existing frame files.  Prints the frame count.
Usage: results_readable.py OUT"""
import os, sys, h5py, xml.etree.ElementTree as ET
out = sys.argv[1]
with h5py.File(os.path.join(out, "results.h5"), "r") as f:
    n = len(f["frames"])
    assert f.attrs["frames"] == n
    for k in f["frames"]:
        assert "displacement" in f["frames"][k] or "position" in f["frames"][k]
# One grid per frame under the temporal collection (a spatial collection
# of the points and the membrane's triangles when there is a membrane).
# The index is committed before the XDMF: a kill between the two leaves the
# XDMF one frame behind, never ahead.
grids = ET.parse(os.path.join(out, "results.xdmf")).getroot().findall(
    ".//Grid[@CollectionType='Temporal']/Grid")
assert len(grids) in (n, n - 1), (len(grids), n)
for item in ET.parse(os.path.join(out, "results.xdmf")).getroot().iter("DataItem"):
    assert os.path.exists(os.path.join(out, item.text.split(":")[0])), item.text
print(n)
