"""Read a pointmech run folder from Python, with Debian's h5py and numpy.

    import pointmech
    r = pointmech.open("out/f2-unconstrained-compression")
    u = r.frames[-1]["displacement"]        # numpy array, one row a point
    x = r.mesh["coordinates"]               # reference coordinates
    r.history["time"], r.history["reaction_zmax_z"]
    r.summary["status"]
    for frame in r.follow():                # every frame, as it is written
        print(frame.step, frame.time, frame["von_mises"].max())

A run folder holds one HDF5 file per frame (results/frame_NNNNNN.h5),
each written under a temporary name and renamed once it is complete, and
the mesh (results/mesh.h5).  A run across ranks writes a frame in pieces,
one a rank, joined by the frame's file; its fields read here in one
process's order all the same.  This module reads those files directly and
holds none of them open between calls, so it reads a run while it goes
on and never blocks the writer.

Each HDF5 file is vetted by the program before h5py opens it (`pointmech
vet FILE`: HDF5 reads it whole in a child process): libhdf5 stops or
loops the process that reads some damaged files, and such a file raises
`Refused` with the program's reason instead.  The program is $POINTMECH,
else `pointmech` on the PATH, else build/pointmech beside this module's
folder; `open(folder, vet=False)` reads without it.  A file HDF5 cannot
open or read at all (truncated, not HDF5) raises `Refused` too, naming
the file.  `Run.check()` vets the mesh and every frame (or those given) in
one call of the program, for a reader about to read them all.
"""

import builtins
import csv
import json
import os
import re
import shutil
import subprocess
import time as _time

import h5py
import numpy as np

__all__ = ["open", "Run", "Frame", "read_rows", "vet", "Refused"]

_FRAME = re.compile(r"^frame_(\d{6,})\.h5$")


class Refused(OSError):
    """A file the program's vetting refused (or could not vet)."""


def _program():
    """The pointmech program that vets files."""
    found = os.environ.get("POINTMECH") or shutil.which("pointmech")
    if found:
        return found
    here = os.path.dirname(os.path.abspath(__file__))
    built = os.path.join(here, os.pardir, os.pardir, "build", "pointmech")
    if os.access(built, os.X_OK):
        return os.path.normpath(built)
    raise Refused("cannot vet HDF5 files: no pointmech program (set "
                  "POINTMECH to it, put it on the PATH, or open the run "
                  "with vet=False)")


# Files vetted, by path, modification time and size: a frame is vetted
# once however often it is read, and again if it is replaced.
_vetted = set()


def _key(path):
    st = os.stat(path)
    return (os.path.abspath(path), st.st_mtime_ns, st.st_size)


def _h5_files(folder):
    """The .h5 files `pointmech vet FOLDER` reads: the folder's and its
    results/'s."""
    found = []
    for d in (folder, os.path.join(folder, "results")):
        try:
            names = sorted(os.listdir(d))
        except (FileNotFoundError, NotADirectoryError):
            continue
        found += [os.path.join(d, n) for n in names if n.endswith(".h5")]
    return found


def vet(*paths):
    """Have the program read each HDF5 file of `paths` (a run folder: every
    HDF5 file of it and of its results/) whole in a child process, in one
    call of the program: raises Refused with the program's reason for a
    file that stops or loops HDF5.  Files vetted before and unchanged since
    are not read again."""
    files = []
    for path in paths:
        files += _h5_files(path) if os.path.isdir(path) else [path]
    before = {}
    for f in files:
        try:
            before[f] = _key(f)
        except OSError as e:
            raise Refused("%s: cannot read it: %s" % (
                f, e.strerror or e)) from None
    todo = [f for f in files if before[f] not in _vetted]
    if not todo:
        return
    done = subprocess.run([_program(), "vet"] + todo, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        # The program's reason names the file: "pointmech: error: PATH: ..."
        why = done.stderr.strip()
        if why.startswith("pointmech: error: "):
            why = why[len("pointmech: error: "):]
        raise Refused(why or "%s: refused by pointmech vet (exit status %d)"
                      % (" ".join(todo), done.returncode))
    # What was read is what is known good: a file replaced during the
    # call is vetted again when it is read.
    for f in todo:
        try:
            if _key(f) == before[f]:
                _vetted.add(before[f])
        except OSError:
            pass


def _read_group(path, checked=True, values=True):
    """Every dataset of an HDF5 file as numpy arrays (none when not
    values), and its attributes (the file vetted first when checked).  A
    file HDF5 cannot read raises Refused naming it."""
    if checked:
        vet(path)
    data = {}
    try:
        with h5py.File(path, "r") as f:
            def take(name, obj):
                if isinstance(obj, h5py.Dataset):
                    data[name] = obj[()]
            if values:
                f.visititems(take)
            attrs = {k: (v.item() if hasattr(v, "item") else v)
                     for k, v in f.attrs.items()}
    except (OSError, KeyError, RuntimeError, TypeError, ValueError) as e:
        raise Refused("%s: HDF5 cannot read it: %s" % (path, e)) from None
    return _one_process_order(data), attrs


def _one_process_order(data):
    """A frame written in pieces (a run across ranks) holds its points in
    piece order, with "index" (each row's one-process index) beside: every
    field put back in one process's order, "index" dropped."""
    index = data.pop("index", None)
    if index is None:
        return data
    for name, a in data.items():
        if a.shape[:1] == index.shape:
            whole = np.empty_like(a)
            whole[index] = a
            data[name] = whole
    return data


def read_rows(group, name):
    """Dataset name of an open h5py group (a frame's, or the mesh's, as
    reached through results.h5) as a numpy array in one process's order:
    a frame written in pieces is put back in order by its "index"."""
    data = {k: group[k][()] for k in (name, "index") if k in group}
    return _one_process_order(data)[name]


class Frame:
    """One output frame: its fields by name (numpy arrays, read at the
    first access), `step`, `time` and `index`."""

    def __init__(self, path, index, checked=True):
        self.path = path
        self.index = index
        self._checked = checked
        self._data = None
        self._attrs = None

    def _load(self):
        if self._data is None:
            self._data, self._attrs = _read_group(self.path, self._checked)

    def _load_attrs(self):
        """step and time alone: a reader choosing frames by time reads
        no field of the others."""
        if self._attrs is None:
            _, self._attrs = _read_group(self.path, self._checked, False)

    def __getitem__(self, name):
        self._load()
        try:
            return self._data[name]
        except KeyError:
            raise KeyError("frame %d (%s) has no field %r; it has %s" % (
                self.index, self.path, name,
                ", ".join(sorted(self._data)))) from None

    def __contains__(self, name):
        self._load()
        return name in self._data

    def keys(self):
        self._load()
        return self._data.keys()

    @property
    def step(self):
        self._load_attrs()
        return int(self._attrs.get("step", -1))

    @property
    def time(self):
        self._load_attrs()
        return float(self._attrs.get("time", float("nan")))

    def __repr__(self):
        return "<pointmech.Frame %d of %s>" % (self.index, self.path)


class _Frames:
    """The frames on disk now, in order: len(), [i] (negative too), and
    iteration.  Listed afresh at each call, so a running run's new frames
    appear."""

    def __init__(self, folder, checked=True):
        self._dir = os.path.join(folder, "results")
        self._checked = checked

    def _paths(self):
        try:
            names = os.listdir(self._dir)
        except FileNotFoundError:
            return []
        found = sorted((int(m.group(1)), n) for n in names
                       for m in [_FRAME.match(n)] if m)
        return [(i, os.path.join(self._dir, n)) for i, n in found]

    def __len__(self):
        return len(self._paths())

    def __getitem__(self, k):
        paths = self._paths()
        if isinstance(k, slice):
            return [Frame(p, i, self._checked) for i, p in paths[k]]
        i, p = paths[k]
        return Frame(p, i, self._checked)

    def __iter__(self):
        return iter([Frame(p, i, self._checked) for i, p in self._paths()])


class Run:
    """A run folder (`pointmech run ... --out FOLDER`), or its results.h5
    (the folder it is in: its files are read by their own names, not
    through the index's links)."""

    def __init__(self, folder, vet=True):
        if os.path.isfile(folder):
            folder = os.path.dirname(os.path.abspath(folder))
        if not os.path.isdir(folder):
            raise FileNotFoundError("no run folder %r" % folder)
        self.folder = folder
        self.vet = vet
        self.frames = _Frames(folder, vet)
        self._mesh = None

    @property
    def summary(self):
        """summary.json as a dict (read afresh: "status" is "running"
        until the run ends)."""
        with builtins.open(os.path.join(self.folder, "summary.json")) as f:
            return json.load(f)

    @property
    def history(self):
        """history.csv as a dict of numpy arrays, one per column."""
        path = os.path.join(self.folder, "history.csv")
        with builtins.open(path, newline="") as f:
            rows = list(csv.reader(f))
        if not rows:
            return {}
        head, body = rows[0], rows[1:]
        cols = {}
        for k, name in enumerate(head):
            values = [r[k] for r in body if len(r) == len(head)]
            try:
                cols[name] = np.array(values, dtype=float)
            except ValueError:
                cols[name] = np.array(values)
        return cols

    @property
    def mesh(self):
        """results/mesh.h5: "coordinates" (reference, one row a point),
        "cells", and "surface" where the run has a membrane."""
        if self._mesh is None:
            self._mesh, _ = _read_group(
                os.path.join(self.folder, "results", "mesh.h5"), self.vet)
        return self._mesh

    def check(self, frames=None):
        """Vet results/mesh.h5 and the frames given (default: every frame)
        in one call of the program, for a reader about to read them all;
        raises Refused naming a file HDF5 cannot read."""
        if not self.vet:
            return
        if frames is None:
            frames = self.frames[:]
        mesh = os.path.join(self.folder, "results", "mesh.h5")
        vet(*([mesh] if os.path.exists(mesh) else []) +
            [f.path for f in frames])

    def positions(self, frame=-1):
        """The points' reference and deformed positions at frame `frame`
        (its index among the frames; -1 the last), both [n][3], and the
        Frame: the mesh and the frame vetted in one call of the program;
        raises Refused naming what is missing or of the wrong shape."""
        frames = self.frames[:]
        if not frames:
            raise Refused("%s/results: no frame" % self.folder)
        if not -len(frames) <= frame < len(frames):
            raise Refused("%s: frame %d out of range (%d frames)" %
                          (self.folder, frame, len(frames)))
        fr = frames[frame]
        self.check([fr])
        if "coordinates" not in self.mesh:
            raise Refused("%s/results/mesh.h5: missing /coordinates" %
                          self.folder)
        if "displacement" not in fr:
            raise Refused("%s: missing /displacement" % fr.path)
        X = np.asarray(self.mesh["coordinates"], dtype=float)
        u = np.asarray(fr["displacement"], dtype=float)
        if X.ndim != 2 or X.shape[1] != 3 or u.shape != X.shape:
            raise Refused("%s: coordinates %s and displacement %s must "
                          "both be [n][3]" % (self.folder, X.shape, u.shape))
        return X, X + u, fr

    def running(self):
        """Whether the run is still going (summary.json says so)."""
        try:
            return self.summary.get("status") == "running"
        except (FileNotFoundError, ValueError):
            return True  # not written yet, or being replaced

    def follow(self, poll=0.5, timeout=None):
        """Yield every frame in order, waiting for new ones while the run
        goes on; stops when the run has ended and its last frame was
        yielded, or after `timeout` seconds without a new frame."""
        seen = 0
        idle_since = _time.monotonic()
        while True:
            paths = self.frames._paths()
            for i, p in paths[seen:]:
                yield Frame(p, i, self.vet)
            if len(paths) > seen:
                seen = len(paths)
                idle_since = _time.monotonic()
            if not self.running():
                # the end: frames written before the summary's last word
                paths = self.frames._paths()
                for i, p in paths[seen:]:
                    yield Frame(p, i, self.vet)
                return
            if timeout is not None and \
                    _time.monotonic() - idle_since > timeout:
                return
            _time.sleep(poll)

    def __repr__(self):
        return "<pointmech.Run %s: %d frames>" % (self.folder,
                                                 len(self.frames))


def open(folder, vet=True):
    """Open the run folder `folder` (or its results.h5); its HDF5 files
    are vetted by the program before they are read, unless vet is False."""
    return Run(folder, vet)
