#!/usr/bin/env python3
"""Finite-element referee for the FPM block cases (F1-F4) by CalculiX.

For each case and each mesh of its ladder this writes a CalculiX deck
(structured mesh of quadratic serendipity elements, the standard
neo-Hookean material, a nonlinear static step with automatic
incrementation), runs ccx when asked, and reads back the reaction on the
loaded face, the total strain energy, the Cauchy stress at the block's
centre and the displacement at a fixed lattice of reference points.  The
results go to cases/fe/CASE/ladder.csv (one row per mesh) and
lattice.csv / lattice-N<k>.csv (the lattice of the finest and the
second-finest converged mesh).

    tools/fe-referee.py --all --run          # every case, every mesh
    tools/fe-referee.py f3-extension-60 --run --ladder 2,4,8
    tools/fe-referee.py f3-extension-60 --ladder 8   # write the deck only
    tools/fe-referee.py --list                   # the cases
    tools/fe-referee.py --summary                # tables of cases/fe
    tools/fe-referee.py f4-plates-40 --run --model eighth --ladder 8 \
        --increment 0.02,0.05 --slope 3e8        # the part, steps, contact

Needs CalculiX (Debian: apt-get install calculix-ccx) and numpy.
"""

import argparse
import datetime
import math
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_ROOT = os.path.join(ROOT, "cases", "fe")

# ---- material and cases -----------------------------------------------------

YOUNG = 3000.0  # Pa


def moduli(nu):
    """Shear and bulk moduli of the gel for Poisson's ratio nu."""
    mu = YOUNG / (2.0 * (1.0 + nu))
    kappa = YOUNG / (3.0 * (1.0 - 2.0 * nu))
    return mu, kappa


def case(dim, faces, load, ladder, nu=0.495, about="", increment=(0.05, 0.1),
         mirrors=(), traction=None, singular=(), grading=1.0,
         element="reduced", model="quarter", slope=None):
    """A case: dimension, the prescribed components per face of the part
    solved (face -> {component: value}), the loaded face and component, the
    mesh ladder, Poisson's ratio, a description, the first and largest load
    increments of the static step, and the planes of symmetry (axis, plane)
    the part solved is mirrored about to give the whole block: the part is
    the block's side of each plane at higher coordinates.  A traction case
    (traction = (face, component, nominal traction in Pa)) loads that face
    instead; its figure is the tip displacement (see TRACTION below).
    singular: the planes (axis, coordinate) whose edges with the free
    faces are singular lines, which a mesh graded with exponent grading
    (> 1; 1: uniform) refines towards (see graded_edges).  element:
    "reduced" (C3D20R/CPE8R) or "full" integration (C3D20/CPE8).  model:
    the part solved where the case is symmetric about its mid-plane too
    ("quarter" or "eighth", see to_eighth).  slope: the plates' contact
    slope (Pa/m) where it is not CONTACT's."""
    return dict(dim=dim, faces=faces, load=load, ladder=ladder, nu=nu,
                about=about, increment=increment, mirrors=mirrors,
                traction=traction, singular=singular, grading=grading,
                element=element, model=model, slope=slope)


LADDER_3D = [2, 4, 8, 12, 16, 20]
LADDER_2D = [1, 2, 4, 8, 16]  # k: 10k x 4k elements
# F2's exact state is homogeneous, which every mesh reproduces: a short
# ladder of the whole cube checks the deck.
LADDER_F2 = [2, 4, 8]


# F3 and F4 are symmetric about x = 0.05 and y = 0.05: the quarter
# x, y >= 0.05 is solved, with u_x = 0 and u_y = 0 on those planes.
QUARTER = ((0, 0.05), (1, 0.05))
# Their singular lines: the edges of the clamped faces z = 0 and z = 0.1
# with the free lateral faces x, y = 0 and 0.1.
CUBE_FACES = tuple((a, c) for a in range(3) for c in (0.0, 0.1))


def constrained(uz, about, ladder=LADDER_3D, **options):
    """F3/F4: the cube with its bottom fixed and its top held laterally and
    moved by uz (m), solved on the quarter."""
    faces = {"zmin": {0: 0.0, 1: 0.0, 2: 0.0},
             "zmax": {0: 0.0, 1: 0.0, 2: uz},
             "xmin": {0: 0.0}, "ymin": {1: 0.0}}
    return case(3, faces, ("zmax", 2), ladder, about=about,
                mirrors=QUARTER, singular=CUBE_FACES, **options)


SLOW = dict(increment=(0.02, 0.05))  # smaller load steps for large strains
# The clamped F4: the free faces fold over the clamped edges, where the
# uniform meshes converge at order 0.7 and the reduced C3D20R's smallest
# elements invert once graded: meshes graded towards the clamped edges
# (q = 2) of the fully integrated C3D20 (see cases/fe/README.md).
LADDER_F4 = [4, 8, 12, 16]
F4_MESH = dict(grading=2.0, element="full", ladder=LADDER_F4)
# F4 40%: the eighth (the quarter's numbers to all printed digits at N = 8
# and 12, for less than half the CPU) and the even meshes to N = 14, where
# the clamped ladder stops (the free surface folds round the clamped edge
# and N = 14 cuts its increments below the minimum at 36% compression;
# cases/fe/README.md, "F4 40%").
F4_40 = dict(F4_MESH, ladder=[4, 8, 10, 12, 14], model="eighth")


# ---- F4 between rigid plates (contact) ----------------------------------------
# The faces on the plates stick from the start and are pressed throughout:
# they are held as the plates move (the clamped conditions).  The lateral
# faces meet the plates as they roll over: face-to-face contact with
# each plate's face and a stiff linear pressure-overclosure law (see
# CONTACT for the friction).  Each plate is a rigid slab of one linear
# brick over the quarter's side, larger than the barrelled block, every
# node moved as the plate.  The reaction is the top face's plus the top plate's.
PLATE_REACH = 0.2  # m: the plates' extent along x and y (the block: 0.1)
PLATE_THICKNESS = 0.01  # m
# Contact: normal slope (Pa/m) and the tension at large clearance (Pa),
# Coulomb coefficient (0: frictionless) and stick slope (Pa/m).  The
# lateral faces that roll onto the plates slide on them: CalculiX's
# face-to-face friction (mu 5, stick slope 3e8 Pa/m) stops the graded
# C3D20 N = 8 at 61.5% of F4 40%, where the contact band forms;
# frictionless it reaches the load (--friction MU for the study,
# cases/fe/README.md, "F4 between plates").
CONTACT = dict(slope=3.0e8, tension=1.0e-3, friction=0.0, stick=3.0e8)
# Face-to-face penalty contact: CalculiX's node-to-face contact is not
# meant for quadratic faces (a pressure on an 8-node face pulls its
# corners, which node-to-face remedies by changing the nodes' weights):
# between frictionless plates it gives F2's homogeneous state 39% low at
# N = 2 (a corner node lifts off), face-to-face to 4e-4.
CONTACT_TYPE = "SURFACE TO SURFACE"
SLOPE_OPTION = None  # --slope


# F3 and F4 are also symmetric about the mid-plane z = 0.05 once the
# bottom face moves up by half the travel and the top face down by half
# (a rigid shift along z, which changes no force nor energy): the eighth
# x, y, z >= 0.05 is solved (N/2 x N/2 x N/2 elements, the top half of the
# quarter's mesh, graded alike), with u_z = 0 on z = 0.05 and the top face
# moved by half the travel; the displacement is shifted back by that half
# so that the bottom face is fixed as in the scenes.  (--model eighth.)
def to_eighth(spec):
    """The constrained case (F3/F4, quarter) solved on the eighth."""
    uz = spec["faces"]["zmax"][2]
    out = dict(spec)
    out["faces"] = dict(spec["faces"], zmin={2: 0.0},
                        zmax={0: 0.0, 1: 0.0, 2: 0.5 * uz})
    out["mirrors"] = QUARTER + ((2, 0.05),)
    out["shift"] = (0.0, 0.0, 0.5 * uz)
    return out


def between_plates(uz, about, **options):
    """F4 between plates: as constrained(uz), with the lateral faces in
    contact with the two rigid plates (CONTACT: frictionless)."""
    spec = constrained(uz, about, **options)
    spec["plates"] = "sticking"
    return spec


# Between frictionless plates nothing holds the faces on the plates: they
# are the slave surface of frictionless contact (no *FRICTION) with the
# plates' faces, and the body is held only by the plates and the planes
# of symmetry.  The exact state is F2's homogeneous one, which checks the
# contact deck: the reaction is the top plate's alone.
def between_frictionless_plates(uz, about, **options):
    """F4 between frictionless plates: the quarter cube on its planes of
    symmetry, squeezed by uz (m) through frictionless contact."""
    spec = case(3, {"xmin": {0: 0.0}, "ymin": {1: 0.0}}, ("zmax", 2),
                LADDER_F2, about=about, mirrors=QUARTER, **options)
    spec.update(plates="frictionless", travel=uz)
    return spec


def travel(spec):
    """The loaded face's prescribed displacement: its condition's, or the
    top plate's where no condition holds it."""
    face, axis = spec["load"]
    return spec.get("travel", spec["faces"].get(face, {}).get(axis))


def plate_blocks(spec, mesh):
    """The deck's additions for the plates (spec["plates"]): their nodes and
    elements, the sets, surfaces, contact pairs and interaction, the
    plates' motion and the top plate's force output, as a dict of text."""
    top = travel(spec)
    n0, e0 = mesh.n_nodes, len(mesh.conn)
    lo, hi = mesh.lo, mesh.hi
    corners = [(lo[0], lo[1]), (PLATE_REACH, lo[1]), (PLATE_REACH, PLATE_REACH),
               (lo[0], PLATE_REACH)]
    nodes, elems = [], []
    # The eighth (mirrored about z = 0.05) has the top plate only.
    slabs = [(hi[2], hi[2] + PLATE_THICKNESS)]
    bottom = not any(a == 2 for a, _ in mesh.mirrors)
    if bottom:
        slabs.insert(0, (-PLATE_THICKNESS, 0.0))
    for k, (z0, z1) in enumerate(slabs):
        first = n0 + 8 * k + 1
        for z in (z0, z1):
            for x, y in corners:
                nodes.append("%d,%s,%s,%s" % (n0 + len(nodes) + 1, number(x),
                                              number(y), number(z)))
        elems.append("%d,%s" % (e0 + k + 1, ",".join(
            str(first + j) for j in range(8))))
    text = dict(mesh="\n".join(nodes) + "\n*ELEMENT,TYPE=C3D8,ELSET=EPLATES\n"
                + "\n".join(elems) + "\n")
    # The lateral faces x = 0.1 (face S4 of C3D20) and y = 0.1 (S5) of the
    # quarter are the slave surface; each plate's face towards the block
    # (bottom plate: S2, top plate: S1) a master.
    # Frictionless: the bottom face z = 0 (S1) and the top face (S2) are
    # the slaves, each against its plate, and no friction.
    index = np.indices(mesh.ne).reshape(3, -1).T

    def surface(axis, end, side):
        at = 0 if end == "lo" else mesh.ne[axis] - 1
        return "\n".join("%d,%s" % (e + 1, side)
                         for e in np.nonzero(index[:, axis] == at)[0])

    c = dict(CONTACT, slope=contact_slope(spec))
    if spec["plates"] == "frictionless":
        slaves = "*SURFACE,NAME=SBOTTOM\n%s\n*SURFACE,NAME=STOP\n%s\n" % (
            surface(2, "lo", "S1"), surface(2, "hi", "S2"))
        pairs, law = (("SBOTTOM", "SPBOT"), ("STOP", "SPTOP")), ""
    else:
        slaves = "*SURFACE,NAME=SLATERAL\n%s\n%s\n" % (
            surface(0, "hi", "S4"), surface(1, "hi", "S5"))
        pairs = (("SLATERAL", "SPBOT"), ("SLATERAL", "SPTOP")) if bottom \
            else (("SLATERAL", "SPTOP"),)
        law = "*FRICTION\n%g,%g\n" % (c["friction"], c["stick"]) \
            if c["friction"] > 0 else ""
    t0 = n0 + 8 * len(slabs) - 8  # the top plate's nodes follow it
    text["model"] = (
        ("*NSET,NSET=NPBOT\n" + id_lines(range(n0 + 1, n0 + 9))
         + "*SURFACE,NAME=SPBOT\n%d,S2\n" % (e0 + 1) if bottom else "")
        + "*NSET,NSET=NPTOP\n" + id_lines(range(t0 + 1, t0 + 9))
        + slaves
        + "*SURFACE,NAME=SPTOP\n%d,S1\n" % (e0 + len(slabs))
        + "*MATERIAL,NAME=PLATE\n*ELASTIC\n1e9,0.3\n"
        + "*SOLID SECTION,ELSET=EPLATES,MATERIAL=PLATE\n"
        + "*SURFACE INTERACTION,NAME=CONTACT\n"
        + "*SURFACE BEHAVIOR,PRESSURE-OVERCLOSURE=LINEAR\n%g,%g\n"
        % (c["slope"], c["tension"]) + law
        + "".join("*CONTACT PAIR,INTERACTION=CONTACT,TYPE=%s\n"
                  "%s,%s\n" % ((CONTACT_TYPE,) + p) for p in pairs))
    text["boundary"] = (("NPBOT,1,3,0.\n" if bottom else "")
                        + "NPTOP,1,2,0.\nNPTOP,3,3,%s\n" % number(top))
    text["output"] = "*NODE PRINT,NSET=NPTOP,TOTALS=ONLY\nRF\n"
    return text


def contact_slope(spec):
    """The plates' contact slope (Pa/m): --slope, else the case's, else
    CONTACT's."""
    return SLOPE_OPTION or spec.get("slope") or CONTACT["slope"]


def plate_force(blocks, load_set):
    """The top plate's force on the block, increment by increment: the
    totals of the face held (load_set) plus those of the plate's nodes
    (NPTOP), written as the load set's blocks.  Returns the last such
    block and the blocks with the load set's replaced by the sums."""
    plate = {b[2]: b[3][0] for b in blocks
             if b[0].startswith("total force") and b[1] == "NPTOP"}
    out = []
    for b in blocks:
        if b[0].startswith("total force") and b[1] == "NPTOP":
            continue
        if b[0].startswith("total force") and b[1] == load_set:
            p = plate.get(b[2], [0.0, 0.0, 0.0])
            b = (b[0], b[1], b[2], [[a + c for a, c in zip(b[3][0], p)]])
        out.append(b)
    return last_block(out, "total force", load_set), out

CASES = {
    "f1-extension": case(
        2, {"xmin": {0: 0.0, 1: 0.0}, "xmax": {0: 2.0}}, ("xmax", 0),
        LADDER_2D, about="F1: 10 x 4 m plane-strain block, u = 0 on x = 0, "
        "u_x = +2 m on x = 10 (20% extension)"),
    "f1-compression": case(
        2, {"xmin": {0: 0.0, 1: 0.0}, "xmax": {0: -2.0}}, ("xmax", 0),
        LADDER_2D, about="F1: 10 x 4 m plane-strain block, u = 0 on x = 0, "
        "u_x = -2 m on x = 10 (20% compression), u_y free there"),
    "f1-compression-guided": case(
        2, {"xmin": {0: 0.0, 1: 0.0}, "xmax": {0: -2.0, 1: 0.0}}, ("xmax", 0),
        LADDER_2D, about="F1: 10 x 4 m plane-strain block, u = 0 on x = 0, "
        "u_x = -2 m and u_y = 0 on x = 10 (20% compression, guided end)"),
    "f2-unconstrained-compression": case(
        3, {"xmin": {0: 0.0}, "ymin": {1: 0.0}, "zmin": {2: 0.0},
            "zmax": {2: -0.04}}, ("zmax", 2), LADDER_F2,
        about="F2: 0.1 m cube on rollers (x = 0, y = 0, z = 0), "
        "u_z = -0.04 m on z = 0.1 (exact: homogeneous, u_z = -0.4 z)"),
    "f3-extension-60": constrained(
        0.06, "F3: 0.1 m cube, bottom fixed, top held laterally, "
        "u_z = +0.06 m"),
    "f3-extension-100": constrained(
        0.10, "F3: as f3-extension-60 with u_z = +0.10 m"),
    "f3-extension-200": constrained(
        0.20, "F3: as f3-extension-60 with u_z = +0.20 m", **SLOW),
    "f4-compression-20": constrained(
        -0.02, "F4: as F3 with u_z = -0.02 m", **F4_MESH),
    "f4-compression-40": constrained(
        -0.04, "F4: as F3 with u_z = -0.04 m", **SLOW, **F4_40),
    "f4-compression-60": constrained(
        -0.06, "F4: as F3 with u_z = -0.06 m", **SLOW, **F4_MESH),
    "f4-plates-20": between_plates(
        -0.02, "F4 between plates: the cube squeezed by 0.02 m between two "
        "rigid plates, the faces on them held", **F4_MESH),
    "f4-plates-40": between_plates(
        -0.04, "F4 between plates: as f4-plates-20 with 0.04 m", **SLOW,
        **F4_40),
    "f4-plates-60": between_plates(
        -0.06, "F4 between plates: as f4-plates-20 with 0.06 m", **SLOW,
        **F4_MESH),
    "f4-plates-40-frictionless": between_frictionless_plates(
        -0.04, "F4 between frictionless plates: the cube squeezed by 0.04 m "
        "(exact: F2's homogeneous state, reaction -21.79225 N)"),
    "f3-extension-60-nu0.3": constrained(
        0.06, "F3 60% with nu = 0.3", nu=0.3),
    "f3-extension-60-nu0.45": constrained(
        0.06, "F3 60% with nu = 0.45", nu=0.45),
}

# ---- traction cases: the near-incompressible panel ---------------------------
# A dead (fixed-direction, nominal) traction on a free face, written as
# CLOADs: the consistent nodal forces of the quadratic edges.  Their
# figure is the tip displacement: the mean of u along the loaded component
# over the lattice points on the loaded face (tip_u, beside tip_face and
# tip_axis in the ladder), the reaction on the clamped face being the
# applied load.  Both integrations are run (--element full): nu = 0.499
# locks the fully integrated CPE8 on coarse meshes.
CASES["panel-near-incompressible"] = case(
    2, {"xmin": {0: 0.0, 1: 0.0}}, ("xmin", 1), LADDER_2D, nu=0.499,
    about="10 x 4 m plane-strain panel, nu = 0.499, u = 0 on x = 0, "
    "nominal shear traction t_y = 20 Pa on x = 10 (dead load)",
    traction=("xmax", 1, 20.0))
TIP_COLUMNS = ["tip_face", "tip_axis", "tip_u"]


def traction_loads(mesh, spec):
    """*CLOAD lines of a traction case: uniform nominal traction q on the
    face, per element edge h the quadratic edge's consistent forces q h/6,
    2 q h/3, q h/6 (1 m deep)."""
    face, comp, q = spec["traction"]
    k = 1 - AXIS[face[0]]  # the face's tangential axis (2-D)
    text = "*CLOAD\n"
    for nid in mesh.face(face):
        j, last = mesh.index[nid - 1][k], 2 * mesh.ne[k]
        w = 2.0 / 3.0 if j % 2 else (1.0 / 6.0 if j in (0, last) else 1.0 / 3.0)
        text += "%d,%d,%s\n" % (nid, comp + 1, number(q * w * mesh.h))
    return text


def tip_displacement(spec, lattice):
    """The traction case's tip figures: the loaded face, its component, and
    the mean displacement along it over the lattice points on the face."""
    face, comp, _ = spec["traction"]
    k = AXIS[face[0]]
    plane = 0.0 if face.endswith("min") else BOX[spec["dim"]][k]
    on = np.abs(lattice[:, k] - plane) < 1e-9
    return face, "xyz"[comp], float(np.mean(lattice[on, 3 + comp]))

# Block sizes: the 3-D cube and the 2-D plane-strain block.
BOX = {3: (0.1, 0.1, 0.1), 2: (10.0, 4.0)}
# Elements along each edge for ladder value n: the cube n x n x n, the
# 2-D block 10n x 4n (square elements of 1/n m).
SHAPE = {3: lambda n: (n, n, n), 2: lambda n: (10 * n, 4 * n)}
# The lattice of reference points where displacements are reported.
LATTICE = {3: ((0.0125,) * 3, (9, 9, 9)), 2: ((0.5, 0.5), (21, 9))}
CENTRE = {3: (0.05, 0.05, 0.05), 2: (5.0, 2.0)}

AXIS = {"x": 0, "y": 1, "z": 2}

# ---- structured mesh of quadratic serendipity elements -------------------------

# Local nodes as offsets (-1, 0, 1) per axis, in CalculiX's order.
# C3D20: corners of the bottom then the top face counter-clockwise, then
# the mid-edge nodes of the bottom face, of the top face, of the verticals.
C3D20_LOCAL = [
    (-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
    (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1),
    (0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1),
    (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
    (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0),
]
# CPE8: corners counter-clockwise, then the mid-edge nodes 1-2, 2-3, 3-4,
# 4-1.
CPE8_LOCAL = [(-1, -1), (1, -1), (1, 1), (-1, 1),
              (0, -1), (1, 0), (0, 1), (-1, 0)]


class Mesh:
    """A structured mesh of the part solved: the block, or the block's side
    of each plane of symmetry.  Nodes lie on the half-element grid where at
    most one index is odd (corners and mid-edge nodes)."""

    def __init__(self, dim, n, mirrors=(), grading=1.0, singular=()):
        self.dim = dim
        self.lo = [0.0] * dim
        self.hi = list(BOX[dim])
        ne = list(SHAPE[dim](n))
        self.h = self.hi[0] / ne[0]  # the uniform mesh's edge
        for axis, plane in mirrors:
            self.lo[axis] = plane
            ne[axis] = int(round((self.hi[axis] - plane) / self.h))
        self.ne = tuple(ne)
        self.mirrors = mirrors
        self.grading = grading
        # Element boundaries along each axis, graded towards the singular
        # planes at the part's ends (see graded_edges).
        self.edges = [graded_edges(self.lo[k], self.hi[k], self.ne[k],
                                   [pl for a, pl in singular if a == k],
                                   grading) for k in range(dim)]
        # Node coordinates along each axis on the half-element grid: the
        # boundaries and the midpoints between them (straight edges).
        self.grid = []
        for e in self.edges:
            g = np.empty(2 * len(e) - 1)
            g[0::2], g[1::2] = e, 0.5 * (e[:-1] + e[1:])
            self.grid.append(g)
        self.h_min = min(float(np.min(np.diff(e))) for e in self.edges)
        self.local = C3D20_LOCAL if dim == 3 else CPE8_LOCAL
        grid = [2 * e + 1 for e in self.ne]
        self.id = -np.ones(grid, dtype=np.int64)
        idx = np.indices(grid).reshape(dim, -1).T
        keep = (idx % 2).sum(axis=1) <= 1
        idx = idx[keep]
        self.id[tuple(idx.T)] = np.arange(1, len(idx) + 1)
        self.index = idx  # grid index of node id - 1
        self.x = np.stack([self.grid[k][idx[:, k]] for k in range(dim)],
                          axis=1)
        elems = np.indices(self.ne).reshape(dim, -1).T
        centre = 2 * elems + 1  # grid index of each element's centre
        self.conn = np.stack(
            [self.id[tuple((centre + np.array(o)).T)] for o in self.local],
            axis=1)
        # Each element's edge along each axis ([elements][dim]).
        self.size = np.stack([np.diff(self.edges[k])[elems[:, k]]
                              for k in range(dim)], axis=1)

    @property
    def n_nodes(self):
        return len(self.x)

    @property
    def share(self):
        """The part's share of the block's volume."""
        return 0.5 ** len(self.mirrors)

    def face(self, name):
        """Node ids on a face of the part (xmin, ..., zmax)."""
        k = AXIS[name[0]]
        at = 0 if name.endswith("min") else 2 * self.ne[k]
        return np.nonzero(self.index[:, k] == at)[0] + 1

    def node_at(self, p):
        """Id of the node at point p, or None when p is not a node."""
        gi = []
        for k in range(self.dim):
            hit = np.nonzero(np.abs(self.grid[k] - p[k]) < 1e-12)[0]
            if len(hit) == 0:
                return None
            gi.append(int(hit[0]))
        nid = int(self.id[tuple(gi)])
        return nid if nid > 0 else None

    def displacement(self, p, u):
        """Displacement at a reference point p of the block: p mirrored into
        the part, interpolated there by the element's shape functions, and
        mirrored back."""
        q, sign = list(p), np.ones(3)
        for axis, plane in self.mirrors:
            if q[axis] < plane:
                q[axis] = 2.0 * plane - q[axis]
                sign[axis] = -1.0
        return sign * self.interpolate(q, u)

    def interpolate(self, p, u):
        """Value at reference point p of the part of the nodal field u
        ([nodes][c]) by the shape functions of the element holding p."""
        e, xi = [], []
        for k in range(self.dim):
            b = self.edges[k]
            ek = int(np.searchsorted(b, p[k], side="right")) - 1
            ek = min(max(ek, 0), self.ne[k] - 1)
            e.append(ek)
            xi.append(2.0 * (p[k] - b[ek]) / (b[ek + 1] - b[ek]) - 1.0)
        centre = np.array([2 * v + 1 for v in e])
        value = 0.0
        for off in self.local:
            nid = self.id[tuple(centre + np.array(off))]
            value = value + serendipity(off, xi) * u[nid - 1]
        return value


def graded_edges(lo, hi, ne, planes, q):
    """The ne + 1 element boundaries of [lo, hi], graded towards those of
    planes (coordinates) that are ends of the interval: with t uniform on
    [0, 1], towards hi x = 1 - (1 - t)^q, towards lo x = t^q, towards both
    each half so (the middle boundary stays at the midpoint); q = 1 is the
    uniform mesh.  An element at a graded end is about q times smaller than
    the uniform one's, and its neighbours grow by (k + 1)^q - k^q."""
    t = np.linspace(0.0, 1.0, ne + 1)
    at_lo = any(abs(p - lo) < 1e-12 for p in planes)
    at_hi = any(abs(p - hi) < 1e-12 for p in planes)
    if q == 1.0 or not (at_lo or at_hi):
        x = t
    elif at_lo and at_hi:
        s = 2.0 * t - 1.0
        x = 0.5 * (1.0 + np.sign(s) * (1.0 - (1.0 - np.abs(s)) ** q))
    elif at_hi:
        x = 1.0 - (1.0 - t) ** q
    else:
        x = t ** q
    x[0], x[-1] = 0.0, 1.0
    return lo + (hi - lo) * x


def serendipity(off, xi):
    """Shape function of the quadratic serendipity node at local offset off
    (entries -1, 0, 1) at natural coordinates xi (2-D or 3-D)."""
    zero = [k for k, a in enumerate(off) if a == 0]
    if not zero:  # corner
        prod, s = 1.0, -(len(off) - 1.0)
        for a, x in zip(off, xi):
            prod *= 1.0 + a * x
            s += a * x
        return prod * s / 2 ** len(off)
    k = zero[0]  # mid-edge node: quadratic along axis k, linear elsewhere
    prod = 1.0 - xi[k] ** 2
    for j, (a, x) in enumerate(zip(off, xi)):
        if j != k:
            prod *= 1.0 + a * x
    return prod / 2 ** (len(off) - 1)


# ---- deck ----------------------------------------------------------------------


def number(v):
    """A real for a CalculiX field: at most 20 characters, as many digits as
    fit (%.12e gives 19 characters for a positive exponent below 100)."""
    for digits in (12, 11, 10):
        s = "%.*e" % (digits, v)
        if len(s) <= 20:
            return s
    raise ValueError("%r does not fit a CalculiX field" % v)


def id_lines(ids, per_line=8):
    """Integers as comma-separated lines of per_line entries (CalculiX
    reads at most 16 entries a line)."""
    ids = list(ids)
    return "".join(",".join(str(i) for i in ids[k:k + per_line]) + ",\n"
                   for k in range(0, len(ids), per_line))


def model_name(mesh):
    return {0: "whole", 1: "half", 2: "quarter",
            3: "eighth"}[len(mesh.mirrors)]


def element_type(dim, reduced):
    if dim == 3:
        return "C3D20R" if reduced else "C3D20"
    return "CPE8R" if reduced else "CPE8"


def write_deck(path, name, spec, n, mesh, reduced):
    """Write the CalculiX input of case name on the mesh of ladder value
    n."""
    dim = spec["dim"]
    mu, kappa = moduli(spec["nu"])
    out = ["*HEADING", "%s, N = %d, %s, %s elements (%s model)" % (
        name, n, element_type(dim, reduced), " x ".join(map(str, mesh.ne)),
        model_name(mesh)), "*NODE"]
    for i, p in enumerate(mesh.x):
        c = list(p) + [0.0] * (3 - dim)
        out.append("%d,%s,%s,%s" % (i + 1, number(c[0]), number(c[1]),
                                    number(c[2])))
    out.append("*ELEMENT,TYPE=%s,ELSET=EALL" % element_type(dim, reduced))
    for e, row in enumerate(mesh.conn):
        ids = [e + 1] + [int(v) for v in row]
        # At most 16 entries a line: the element and 15 nodes, then the rest.
        out.append(",".join(str(v) for v in ids[:16])
                   + ("," if len(ids) > 16 else ""))
        if len(ids) > 16:
            out.append(",".join(str(v) for v in ids[16:]))
    lines = "\n".join(out) + "\n"
    plates = plate_blocks(spec, mesh) if spec.get("plates") else None
    if plates:  # the plates' nodes, then their elements
        head, _, tail = lines.partition("*ELEMENT")
        lines = head + plates["mesh"].split("*ELEMENT")[0] + "*ELEMENT" + tail
        lines += "*ELEMENT" + plates["mesh"].split("*ELEMENT")[1]
    sets = {}
    for face in list(spec["faces"]) + [spec["load"][0]]:
        sets["N" + face.upper()] = mesh.face(face)
    sets["NALL"] = np.arange(1, mesh.n_nodes + 1)
    sets["NCENTRE"] = [mesh.node_at(CENTRE[dim])]
    for sname, ids in sets.items():
        lines += "*NSET,NSET=%s\n" % sname + id_lines(ids)
    lines += "*MATERIAL,NAME=GEL\n*HYPERELASTIC,NEO HOOKE\n"
    # CalculiX: U = C10 (Ibar1 - 3) + (J - 1)^2 / D1.
    lines += "%s,%s\n" % (number(mu / 2.0), number(2.0 / kappa))
    lines += "*SOLID SECTION,ELSET=EALL,MATERIAL=GEL\n"
    if plates:
        lines += plates["model"]
    if dim == 2:
        lines += "1.\n"  # thickness, m: results per metre of depth
    first, largest = spec["increment"]
    lines += "*STEP,NLGEOM,INC=10000\n*STATIC\n"
    lines += "%g,1.,1e-7,%g\n" % (first, largest)
    # Equilibrium to a residual of 1e-7 of the mean force and a correction
    # of 1e-6 of the largest increment (defaults 5e-3 and 1e-2); up to 40
    # iterations and 10 cutbacks an increment (defaults 16 and 5).
    lines += "*CONTROLS,PARAMETERS=FIELD\n1e-7,1e-6\n"
    lines += "*CONTROLS,PARAMETERS=TIME INCREMENTATION\n4,8,9,40,10,4,0,10\n"
    lines += "*BOUNDARY\n"
    for face, comps in spec["faces"].items():
        for c, v in sorted(comps.items()):
            lines += "N%s,%d,%d,%s\n" % (face.upper(), c + 1, c + 1, number(v))
    if spec["traction"]:
        lines += traction_loads(mesh, spec)
    if plates:
        lines += plates["boundary"]
    load = "N" + spec["load"][0].upper()
    # CalculiX uses one output frequency for every request of a step; the
    # default (every increment) keeps the last converged increment of a
    # run that stops early.  The stress goes to the .frd for the centre
    # node only; displacements and totals to the .dat (7 digits).
    lines += "*EL FILE,NSET=NCENTRE\nS\n"
    lines += "*NODE PRINT,NSET=NALL\nU\n"
    lines += "*NODE PRINT,NSET=%s,TOTALS=ONLY\nRF\n" % load
    if plates:
        lines += plates["output"]
    lines += "*END STEP\n"
    with open(path, "w") as f:
        f.write(lines)


# ---- strain energy of the FE displacement field ----------------------------


def serendipity_gradient(off, xi):
    """Derivatives along each natural coordinate of the shape function of
    the node at local offset off, at xi."""
    d = len(off)
    grad = []
    zero = [k for k, a in enumerate(off) if a == 0]
    for k in range(d):
        if not zero:  # corner: prod(1 + a x) (sum(a x) - (d - 1)) / 2^d
            prod = 1.0
            for j in range(d):
                prod *= 1.0 + off[j] * xi[j]
            others = 1.0
            for j in range(d):
                if j != k:
                    others *= 1.0 + off[j] * xi[j]
            s = sum(a * x for a, x in zip(off, xi)) - (d - 1.0)
            grad.append((off[k] * others * s + prod * off[k]) / 2 ** d)
        else:  # mid-edge along m: (1 - x_m^2) prod_{j != m}(1 + a x) / 2^(d-1)
            m = zero[0]
            v = -2.0 * xi[m] if k == m else 1.0 - xi[m] ** 2
            for j in range(d):
                if j == m:
                    continue
                v *= off[j] if j == k else 1.0 + off[j] * xi[j]
            grad.append(v / 2 ** (d - 1))
    return grad


def gauss_rule(points):
    """Tensor-product Gauss rule on [-1, 1]: abscissae and weights."""
    if points == 2:
        a = 1.0 / math.sqrt(3.0)
        return [-a, a], [1.0, 1.0]
    if points == 3:
        a = math.sqrt(0.6)
        return [-a, 0.0, a], [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]
    raise ValueError(points)


def strain_energy(mesh, u, nu, reduced):
    """Total strain energy (J; per metre of depth in 2-D) of the nodal
    displacement u ([nodes][3]) with the element's own quadrature: 2 points
    per direction for the reduced-integration elements, 3 for the full."""
    mu, kappa = moduli(nu)
    dim = mesh.dim
    xs, ws = gauss_rule(2 if reduced else 3)
    points = np.array(np.meshgrid(*[xs] * dim, indexing="ij")).reshape(dim, -1).T
    weights = np.prod(np.array(np.meshgrid(*[ws] * dim, indexing="ij"))
                      .reshape(dim, -1), axis=0)
    ue = u[mesh.conn - 1][:, :, :dim]  # [elements][local nodes][dim]
    # Reference volume per unit natural volume, per element (boxes).
    jac = np.prod(mesh.size / 2.0, axis=1)
    scale = 2.0 / mesh.size  # dN/dX_k = dN/dxi_k * 2 / h_k in a box
    total = 0.0
    for xi, w in zip(points, weights):
        g = np.array([serendipity_gradient(o, xi) for o in mesh.local])
        F = np.tile(np.eye(3), (len(ue), 1, 1))
        F[:, :dim, :dim] += np.einsum("eai,aj,ej->eij", ue, g, scale)
        J = np.linalg.det(F)
        I1 = np.einsum("eij,eij->e", F, F)
        W = 0.5 * mu * (J ** (-2.0 / 3.0) * I1 - 3.0) \
            + 0.5 * kappa * (J - 1.0) ** 2
        total += w * np.dot(jac, W)
    return total


# ---- CalculiX output --------------------------------------------------------


def read_dat(path):
    """The blocks of a .dat file: a list of (title, set, time, rows), rows
    being lists of numbers."""
    blocks = []
    head = re.compile(r"^\s*(.+?) for set (\S+) and time\s+(\S+)\s*$")
    with open(path) as f:
        for line in f:
            m = head.match(line)
            if m:
                blocks.append((m.group(1), m.group(2), float(m.group(3)), []))
            elif blocks and line.strip():
                blocks[-1][3].append([float(v) for v in line.split()])
    return blocks


def last_block(blocks, title, nset):
    found = [b for b in blocks if b[0].startswith(title) and b[1] == nset]
    return found[-1] if found else None


def read_frd_stress(path, node):
    """The six Cauchy stress components (xx, yy, zz, xy, yz, zx) of the last
    STRESS block of a .frd file at node."""
    value, in_stress = None, False
    with open(path) as f:
        for line in f:
            if line.startswith(" -4"):
                in_stress = line.split()[1] == "STRESS"
            elif in_stress and line.startswith(" -1"):
                if int(line[3:13]) == node:
                    value = [float(line[13 + 12 * k:25 + 12 * k])
                             for k in range(6)]
    return value


def von_mises(s):
    xx, yy, zz, xy, yz, zx = s
    return math.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                     + 3.0 * (xy ** 2 + yz ** 2 + zx ** 2))


def read_sta(path):
    """Converged increments, total iterations and the load fraction reached
    (the step time of the last converged increment)."""
    increments, iterations, reached = 0, 0, 0.0
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                v = line.split()
                if len(v) == 7 and v[0].isdigit():
                    increments += 1
                    iterations += int(v[3])
                    reached = float(v[4])
    return increments, iterations, reached


def ccx_version():
    try:
        r = subprocess.run(["ccx", "-v"], capture_output=True, text=True,
                           timeout=30)
        m = re.search(r"Version\s+(\S+)", r.stdout + r.stderr)
        return m.group(1) if m else "unknown"
    except OSError:
        return "unknown"


# ---- one run ----------------------------------------------------------------


def lattice_points(dim):
    step, count = LATTICE[dim]
    axes = [np.arange(c) * s for s, c in zip(step, count)]
    grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(dim, -1).T
    return grid


def make_mesh(spec, n):
    """The mesh of ladder value n of a case, graded as the case says."""
    return Mesh(spec["dim"], n, spec["mirrors"], spec["grading"],
                spec["singular"])


def job_name(name, spec, n, reduced):
    g = spec["grading"]
    return "%s-N%d-%s%s%s" % (name, n, element_type(spec["dim"], reduced),
                              "" if g == 1.0 else "-q%g" % g,
                              "-eighth" if len(spec["mirrors"]) == 3 else "")


def run_ccx(name, spec, n, mesh, reduced, rundir, job, threads):
    """Write the deck into a fresh rundir and run ccx on it with threads
    threads (OMP_NUM_THREADS and CCX_NPROC_EQUATION_SOLVER, _RESULTS and
    _STIFFNESS, which CalculiX reads); returns the wall and CPU times (s,
    CPU: user and system of ccx alone) and ccx's peak resident memory
    (bytes), also kept in rundir/times.txt."""
    shutil.rmtree(rundir, ignore_errors=True)
    os.makedirs(rundir)
    write_deck(os.path.join(rundir, job + ".inp"), name, spec, n, mesh,
               reduced)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads),
               CCX_NPROC_EQUATION_SOLVER=str(threads),
               CCX_NPROC_RESULTS=str(threads),
               CCX_NPROC_STIFFNESS=str(threads))
    t0 = time.perf_counter()
    with open(os.path.join(rundir, "ccx.log"), "w") as log:
        p = subprocess.Popen(["ccx", "-i", job], cwd=rundir, stdout=log,
                             stderr=subprocess.STDOUT, env=env)
        # wait4: this child's own usage (RUSAGE_CHILDREN would mix the
        # peaks of every child so far).
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    cpu = usage.ru_utime + usage.ru_stime
    memory = usage.ru_maxrss * 1024.0  # KiB on Linux
    with open(os.path.join(rundir, "times.txt"), "w") as f:
        f.write("%.6f %.6f %.0f\n" % (wall, cpu, memory))
    return wall, cpu, memory


def run_case(name, spec, n, reduced, work, threads, reuse=False):
    """Write and run the deck of case name on mesh n; return the row of the
    ladder and the lattice displacements (None when the run reached no
    load).  reuse: read back the run kept in work (--keep) when it is
    there (its wall and CPU times from its times.txt) instead of running
    ccx again."""
    dim = spec["dim"]
    if dim == 3 and n % 2:
        raise SystemExit("%s: N = %d: the centre is a node only for even N"
                         % (name, n))
    mesh = make_mesh(spec, n)
    job = job_name(name, spec, n, reduced)
    rundir = os.path.join(work, job)
    times = os.path.join(rundir, "times.txt")
    if reuse and os.path.exists(times):
        with open(times) as f:
            v = [float(t) for t in f.read().split()]
        wall, cpu, memory = (v + [math.nan])[:3]  # older runs: no memory
    else:
        wall, cpu, memory = run_ccx(name, spec, n, mesh, reduced, rundir,
                                    job, threads)
    increments, iterations, reached = read_sta(os.path.join(rundir,
                                                            job + ".sta"))
    converged = abs(reached - 1.0) < 1e-9
    row = dict(N=n, nodes=mesh.n_nodes, dofs=dim * mesh.n_nodes,
               element=element_type(dim, reduced), h=mesh.h,
               model=model_name(mesh), grading=mesh.grading,
               h_min=mesh.h_min,
               reaction_x=math.nan, reaction_y=math.nan, reaction_z=math.nan,
               mean_sed=math.nan, von_mises_centre=math.nan,
               increments=increments, iterations=iterations, wall_seconds=wall,
               cpu_seconds=cpu, peak_memory_bytes=memory,
               work_density=math.nan,
               load_fraction=reached,
               status="converged" if converged else "stopped")
    lattice = None
    blocks = read_dat(os.path.join(rundir, job + ".dat"))
    disp = last_block(blocks, "displacements", "NALL")
    load_set = "N" + spec["load"][0].upper()
    force = last_block(blocks, "total force", load_set)
    if spec.get("plates"):  # the face held plus the top plate's contact
        force, blocks = plate_force(blocks, load_set)
    # The part's reactions and energy stand for the whole block's: forces
    # scale with the block's cross-section over the part's, and components
    # normal to a plane of symmetry cancel with their mirror images.
    # On the eighth the loaded face's images are those by the planes
    # across it (x, y), not by the plane along it (z = 0.05).
    volume = np.prod(BOX[dim]) * mesh.share
    face, axis = spec["load"]
    images = 2.0 ** sum(1 for a, _ in mesh.mirrors if a != axis)
    scale = np.array([0.0 if any(a == c != axis for a, _ in mesh.mirrors)
                      else images for c in range(3)])
    history = [b for b in blocks
               if b[0].startswith("total force") and b[1] == load_set]
    if history and not spec["traction"]:  # a traction's work: not here
        t = np.array([0.0] + [b[2] for b in history])
        f = np.array([0.0] + [b[3][0][axis] for b in history])
        row["work_density"] = np.trapz(f, t) * travel(spec) / volume
    if disp and force and disp[2] == force[2] and disp[2] > 0:
        row["load_fraction"] = disp[2]
        u = np.zeros((mesh.n_nodes, 3))
        for r in disp[3]:
            u[int(r[0]) - 1] = r[1:4]
        reaction = np.array(force[3][0][:3]) * scale
        if dim == 2:
            reaction[2] = 0.0
        row["reaction_x"], row["reaction_y"], row["reaction_z"] = reaction
        row["mean_sed"] = strain_energy(mesh, u, spec["nu"], reduced) / volume
        s = read_frd_stress(os.path.join(rundir, job + ".frd"),
                            mesh.node_at(CENTRE[dim]))
        if s:
            # The whole block's nodal average at the centre takes the part's
            # with its mirror images: shear components on a plane of
            # symmetry average to zero.
            for k, (i, j) in enumerate(((0, 1), (1, 2), (2, 0))):
                if any(a in (i, j) for a, _ in mesh.mirrors):
                    s[3 + k] = 0.0
            row["von_mises_centre"] = von_mises(s)
        pts = lattice_points(dim)
        lattice = np.array([mesh.displacement(p, u) for p in pts])
        lattice += np.array(spec.get("shift", (0.0,) * 3))[:dim]
        lattice = np.hstack([np.pad(pts, ((0, 0), (0, 3 - dim))), lattice])
    if spec["traction"]:
        face, comp = spec["traction"][0], "xyz"[spec["traction"][1]]
        row.update(tip_face=face, tip_axis=comp, tip_u=math.nan)
        if lattice is not None:
            row["tip_u"] = tip_displacement(spec, lattice)[2]
    return row, lattice


# ---- ladder files -------------------------------------------------------------

COLUMNS = ["N", "nodes", "dofs", "element", "h", "reaction_x", "reaction_y",
           "reaction_z", "mean_sed", "von_mises_centre", "increments",
           "wall_seconds", "ccx_version", "model", "iterations",
           "cpu_seconds", "work_density", "load_fraction", "status",
           "grading", "h_min", "peak_memory_bytes"]


def cell(v):
    if isinstance(v, float):
        return "nan" if math.isnan(v) else "%.10g" % v
    return str(v)


def provenance(version):
    return "# generated by tools/fe-referee.py, CalculiX %s, %s\n" % (
        version, datetime.date.today().isoformat())


def describe(name, spec):
    mu, kappa = moduli(spec["nu"])
    dim = spec["dim"]
    text = "# %s: %s\n" % (name, spec["about"])
    text += ("# neo-Hookean W = mu/2 (Ibar1 - 3) + K/2 (J - 1)^2, E = %g Pa, "
             "nu = %g (mu = %.10g Pa, K = %.10g Pa)\n" % (YOUNG, spec["nu"],
                                                           mu, kappa))
    if len(spec["mirrors"]) == 3:
        text += ("# solved on the part x, y, z >= 0.05 (the block is "
                 "symmetric about x = 0.05, y = 0.05 and, the bottom moved "
                 "up by half the travel and the top down by half, z = 0.05) "
                 "with u_x, u_y, u_z = 0 on those planes; figures are the "
                 "whole block's, displacements shifted back by half the "
                 "travel (the bottom face fixed)\n")
    elif spec["mirrors"]:
        text += ("# solved on the part x, y >= 0.05 (the block is symmetric "
                 "about x = 0.05 and y = 0.05) with u_x = 0 and u_y = 0 on "
                 "those planes; figures are the whole block's\n")
    if dim == 3:
        text += "# N: elements per edge of the cube (N x N x N); "
    else:
        text += "# N: elements per metre (10N x 4N plane-strain elements, " \
                "1 m deep); "
    text += ("h: element edge (m); dofs: %d per node; reactions (N): sum over "
             "the nodes of %s; mean_sed: strain energy / reference volume "
             "(J/m^3); von_mises_centre: Cauchy von Mises stress at %s (Pa); "
             "work_density: reaction integrated over the loaded face's "
             "displacement (trapezoids over the increments) / volume; "
             "load_fraction: share of the prescribed displacement reached\n"
             % (dim, spec["load"][0], str(CENTRE[dim])))
    if spec["grading"] != 1.0:
        text += ("# %s elements on meshes graded towards the clamped edges "
                 "(x = 1 - (1 - t)^grading towards each singular face, "
                 "cases/fe/README.md); h: the uniform mesh's edge 0.1/N; "
                 "h_min: the smallest element edge (m)\n"
                 % element_type(dim, spec["element"] == "reduced"))
    if spec.get("plates"):
        c = CONTACT
        held = ("the faces on the plates held as they move; the lateral "
                "faces" if spec["plates"] == "sticking" else
                "nothing held but the planes of symmetry; the faces z = 0 "
                "and z = 0.1")
        text += ("# contact: %s in %s contact (CalculiX *CONTACT PAIR, "
                 "TYPE=%s) with the face of each rigid plate (one C3D8 "
                 "moved as the plate), linear pressure-overclosure %g Pa/m, "
                 "%s; reactions: the loaded face's plus the top plate's\n"
                 % (held, "frictionless" if c["friction"] <= 0 else
                    "frictional", CONTACT_TYPE, contact_slope(spec),
                    "no friction" if c["friction"] <= 0 else
                    "Coulomb mu %g, stick slope %g Pa/m" % (c["friction"],
                                                           c["stick"])))
    if spec["traction"]:
        text += ("# traction case: work_density not computed; tip_u: mean "
                 "displacement along tip_axis (m) over the lattice points on "
                 "tip_face, the case's figure (tolerance.csv: tip)\n")
    return text


def write_ladder(path, header, rows):
    columns = COLUMNS + (TIP_COLUMNS if "tip_u" in rows[0] else [])
    with open(path + ".tmp", "w") as f:
        f.write(header)
        f.write(",".join(columns) + "\n")
        for r in rows:
            f.write(",".join(cell(r[c]) for c in columns) + "\n")
    os.replace(path + ".tmp", path)


def write_lattice(path, header, lattice):
    with open(path + ".tmp", "w") as f:
        f.write(header)
        f.write("x,y,z,u_x,u_y,u_z\n")
        for p in lattice:
            f.write(",".join("%.9e" % v for v in p) + "\n")
    os.replace(path + ".tmp", path)


def nrmse_vector(u, ref):
    """The root-mean-square of |u - ref| over the largest |ref| (as
    pm_nrmse_vector in src/common/analysis/pm_metrics.c)."""
    err = np.sqrt(np.mean(np.sum((u - ref) ** 2, axis=1)))
    return err / np.max(np.sqrt(np.sum(ref ** 2, axis=1)))


def claim(change):
    """The tolerance claimed for a measured change: the next value of the
    1-2-5 series at or above it (at least 1e-5)."""
    change = max(abs(change), 1e-5)
    exp = math.floor(math.log10(change))
    for m in (1, 2, 5, 10):
        t = m * 10.0 ** exp
        if t >= change * (1 - 1e-12):
            return float("%.0e" % t)
    return 10.0 ** (exp + 1)


def observed_order(n, d1, d2):
    """The order p of e(N) = C N^-p for which the changes d1 (n[0] -> n[1])
    and d2 (n[1] -> n[2]) are in the ratio observed, or None when they do
    not shrink monotonically or are at round-off."""
    if not (d1 * d2 > 0 and abs(d2) < abs(d1)) or abs(d2) < 1e-9:
        return None  # not shrinking, or already at round-off
    target = abs(d1 / d2)

    def ratio(p):
        return (n[0] ** -p - n[1] ** -p) / (n[1] ** -p - n[2] ** -p)

    lo, hi = 0.05, 12.0
    if not ratio(lo) <= target <= ratio(hi):
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if ratio(mid) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def richardson(n, v):
    """Richardson extrapolation of the values v on the meshes n (the last
    three): the limit v3 + (v3 - v2) / ((n3/n2)^p - 1) with the order p
    they show, or None when they show none."""
    d1, d2 = v[-2] - v[-3], v[-1] - v[-2]
    p = observed_order(n[-3:], d1, d2)
    if not p:
        return None
    return v[-1] + d2 / ((n[-1] / n[-2]) ** p - 1.0)


def extrapolate(n, v):
    """The Richardson limit of v over the three finest meshes n and its
    uncertainty, relative to the limit: the change of the limit when the
    finest mesh is added (the limit of the three meshes before it), or,
    with three meshes only, 1.25 times the distance of the finest from the
    limit (Roache's grid convergence index).  (nan, nan) without one."""
    limit = richardson(n, v) if len(n) >= 3 else None
    if limit is None:
        return math.nan, math.nan
    before = richardson(n[:-1], v[:-1]) if len(n) >= 4 else None
    if before is None:
        return limit, 1.25 * abs(v[-1] - limit) / abs(limit)
    return limit, abs(limit - before) / abs(limit)


def write_tolerance(path, header, spec, rows, lattices):
    """The change of each quantity between the two finest converged meshes,
    the error of the finest estimated from the last three (Richardson: the
    observed order p, then change / ((N3/N2)^p - 1)), the tolerance
    claimed: the next value of 1, 2, 5 x 10^k above both (and above the
    limit's uncertainty where four meshes measure it), and for single
    numbers the Richardson limit with its uncertainty (extrapolate)."""
    comp = "reaction_" + "xyz"[spec["load"][1]]
    converged = [r for r in rows if r["status"] == "converged"]
    done = converged[-3:]
    n = [r["N"] for r in done]
    fine = done[-1]
    result = []
    first = "tip" if spec["traction"] else "reaction"
    for q in (first, "mean_sed", "von_mises_centre", "lattice_nrmse"):
        limit, spread = math.nan, math.nan
        if q == "lattice_nrmse":
            lat = [lattices[k][:, 3:] for k in n]
            # Signed changes are not defined for a field: the NRMSE of each
            # mesh against the next stands for their size.
            d = [nrmse_vector(lat[i], lat[i + 1]) for i in range(len(n) - 1)]
        else:
            key = {"reaction": comp, "tip": "tip_u"}.get(q, q)
            v = [r[key] for r in done]
            d = [(v[i + 1] - v[i]) / abs(fine[key]) for i in range(len(n) - 1)]
            limit, spread = extrapolate([r["N"] for r in converged[-4:]],
                                        [r[key] for r in converged[-4:]])
        change = abs(d[-1])
        p = observed_order(n, d[0], d[1]) if len(d) == 2 else None
        estimate = change / ((n[-1] / n[-2]) ** p - 1.0) if p else math.nan
        worst = change if math.isnan(estimate) else max(change, estimate)
        # With a fourth mesh the limit's move is measured: where the limit
        # moves by more than the finest's estimated error, the order that
        # estimate rests on is not yet the asymptotic one, and the claim
        # covers the move (F4 40% between plates: 4.4% against 1.4%).
        if len(converged) >= 4 and not math.isnan(spread):
            worst = max(worst, spread)
        result.append((q, n[-1], n[-2], change, p, estimate, claim(worst),
                       limit, spread))
    with open(path + ".tmp", "w") as f:
        f.write(header)
        f.write("# relative_change: between the meshes N = %d and N = %d "
                "(lattice: NRMSE of the coarser against the finer); order: "
                "observed over N = %s (empty when the changes do not shrink "
                "monotonically); estimated_error: of the finest mesh, "
                "change / ((N_finest / N_previous)^order - 1); tolerance: "
                "the next value of 1, 2, 5 x 10^k above both (and above "
                "extrapolation_uncertainty where four meshes measure it); "
                "extrapolated: the Richardson limit over the three finest "
                "(same units as the ladder); extrapolation_uncertainty: "
                "relative, the change of that limit when the finest mesh "
                "is added (1.25 x the finest's distance from it with three "
                "meshes only)\n"
                % (n[-2], n[-1], ", ".join(str(k) for k in n)))
        f.write("quantity,finest_N,previous_N,relative_change,order,"
                "estimated_error,tolerance,extrapolated,"
                "extrapolation_uncertainty\n")
        for q, nf, np_, c, p, e, t, lim, spr in result:
            f.write("%s,%d,%d,%.4e,%s,%s,%g,%s,%s\n" % (
                q, nf, np_, c, "%.3f" % p if p else "",
                "%.4e" % e if not math.isnan(e) else "", t,
                "%.7g" % lim if not math.isnan(lim) else "",
                "%.2e" % spr if not math.isnan(spr) else ""))
    os.replace(path + ".tmp", path)
    return result


def read_csv(path):
    """Header and rows (dicts) of a CSV file with '#' comment lines."""
    with open(path) as f:
        lines = [ln.rstrip("\n") for ln in f if not ln.startswith("#")]
    head = lines[0].split(",")
    return [dict(zip(head, ln.split(","))) for ln in lines[1:] if ln]


def summary(folder, names):
    """Markdown tables of the committed results: each case's ladder and the
    change between its two finest converged meshes."""
    out = []
    for name in names:
        path = os.path.join(folder, name, "ladder.csv")
        if not os.path.exists(path):
            continue
        spec = CASES[name]
        comp = "reaction_" + "xyz"[spec["load"][1]]
        figure = "reaction (N%s)" % ("/m" if spec["dim"] == 2 else "")
        if spec["traction"]:  # its reaction is the load: the tip instead
            comp, figure = "tip_u", "tip u_%s (m)" % "xyz"[spec["traction"][1]]
        rows = read_csv(path)
        graded = float(rows[-1].get("grading") or 1.0)
        out.append("**%s** (%s, %s model%s)\n" % (
            name, rows[-1]["element"], rows[-1]["model"],
            ", graded q = %g" % graded if graded != 1.0 else ""))
        out.append("| N | nodes | %s | mean SED (J/m^3) | von "
                   "Mises at centre (Pa) | increments | wall (s) | CPU (s) "
                   "| status |" % figure)
        out.append("|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            status = r["status"] if r["status"] == "converged" else \
                "stopped at %.3g of the load" % float(r["load_fraction"])
            out.append("| %s | %s | %.7g | %.7g | %.6g | %s | %.1f | %.1f | %s |"
                       % (r["N"], r["nodes"], float(r[comp]),
                          float(r["mean_sed"]), float(r["von_mises_centre"]),
                          r["increments"], float(r["wall_seconds"]),
                          float(r["cpu_seconds"]), status))
        tol = os.path.join(folder, name, "tolerance.csv")
        if os.path.exists(tol):
            t = read_csv(tol)
            out.append("\nChange N = %s -> %s (observed order, estimated "
                       "error of the finest, tolerance claimed): " % (
                           t[0]["previous_N"], t[0]["finest_N"])
                       + ", ".join("%s %.2e (%s, %s, %s)" % (
                           q["quantity"], float(q["relative_change"]),
                           q["order"] or "-", q["estimated_error"] or "-",
                           q["tolerance"]) for q in t) + ".")
            limits = ["%s %.7g (+- %.1e)" % (
                q["quantity"], float(q["extrapolated"]),
                float(q["extrapolation_uncertainty"]))
                for q in t if q.get("extrapolated")]
            if limits:
                out.append("Richardson limits (relative uncertainty): "
                           + ", ".join(limits) + ".")
        out.append("")
    return "\n".join(out)


def with_options(spec, a):
    """The case with the grading and element asked for on the command
    line, if any."""
    spec = dict(spec)
    if a.grading is not None:
        spec["grading"] = a.grading
    if a.element is not None:
        spec["element"] = a.element
    if a.increment is not None:
        spec["increment"] = tuple(float(v) for v in a.increment.split(","))
    model = a.model or spec.get("model", "quarter")
    if model == "eighth" and len(spec["mirrors"]) == 2:
        if spec["dim"] != 3 or "zmax" not in spec["faces"] or \
                spec["faces"]["zmin"] != {0: 0.0, 1: 0.0, 2: 0.0}:
            raise SystemExit("--model eighth: only the F3/F4 cases (bottom "
                             "fixed, top held and moved) are symmetric "
                             "about z = 0.05")
        spec = to_eighth(spec)
    return spec


def main():
    ap = argparse.ArgumentParser(
        description="CalculiX referee for the FPM block cases",
        formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("cases", nargs="*", help="case names (see --list)")
    ap.add_argument("--all", action="store_true", help="every case")
    ap.add_argument("--list", action="store_true", help="list the cases")
    ap.add_argument("--summary", action="store_true",
                    help="print markdown tables of the results in --out")
    ap.add_argument("--run", action="store_true",
                    help="run ccx and write cases/fe/CASE/*.csv")
    ap.add_argument("--ladder", help="mesh values, e.g. 2,4,8 (default: the "
                    "case's ladder)")
    ap.add_argument("--element", choices=["reduced", "full"],
                    help="C3D20R/CPE8R (reduced; the default but for F4) "
                    "or C3D20/CPE8 (full integration)")
    ap.add_argument("--grading", type=float,
                    help="exponent of the mesh grading towards the singular "
                    "lines (1: uniform; default: the case's)")
    ap.add_argument("--friction", type=float,
                    help="Coulomb coefficient of the plates' lateral "
                    "contact (f4-plates-*; default 0: frictionless)")
    ap.add_argument("--contact", choices=["face", "node"],
                    help="the plates' contact pairs: face-to-face (the "
                    "default) or node-to-face (the referee before "
                    "2026-12-05)")
    ap.add_argument("--model", choices=["quarter", "eighth"],
                    help="F3/F4: the part solved, the quarter x, y >= 0.05 "
                    "or the eighth x, y, z >= 0.05 (default: the case's)")
    ap.add_argument("--increment", help="FIRST,LARGEST: the static step's "
                    "first and largest load increment, as shares of the load "
                    "(default: the case's)")
    ap.add_argument("--slope", type=float,
                    help="the plates' contact: slope of the linear "
                    "pressure-overclosure law, Pa/m (default %g)"
                    "; the case's where it names one" % CONTACT["slope"])
    ap.add_argument("--out", default=OUT_ROOT,
                    help="results folder (default cases/fe)")
    ap.add_argument("--work", default=os.path.join("/tmp", "fe-referee"),
                    help="where decks run (default /tmp/fe-referee)")
    ap.add_argument("--threads", type=int, default=1,
                    help="threads given to ccx (default 1)")
    ap.add_argument("--lattices", action="store_true",
                    help="also write lattice-N<k>.csv for every mesh that "
                    "reached the full load (pointmech bench measures each "
                    "level's displacement against the case's referee)")
    ap.add_argument("--keep", action="store_true",
                    help="keep the run folders under --work")
    ap.add_argument("--reuse", action="store_true",
                    help="read back the meshes kept under --work (--keep) "
                    "instead of running them again")
    a = ap.parse_args()
    global CONTACT_TYPE, SLOPE_OPTION
    if a.friction is not None:
        CONTACT["friction"] = a.friction
    if a.slope is not None:
        SLOPE_OPTION = a.slope
    if a.contact == "node":
        CONTACT_TYPE = "NODE TO SURFACE"
    if a.list:
        for name, spec in CASES.items():
            print("%-30s %s" % (name, spec["about"]))
        return 0
    names = list(CASES) if a.all else a.cases
    if a.summary:
        print(summary(a.out, names or list(CASES)))
        return 0
    unknown = [n for n in names if n not in CASES]
    if unknown or not names:
        ap.error("name cases (or --all): %s" % ", ".join(CASES))
    os.makedirs(a.work, exist_ok=True)
    if not a.run:
        for name in names:
            spec = with_options(CASES[name], a)
            reduced = spec["element"] == "reduced"
            ladder = [int(v) for v in a.ladder.split(",")] if a.ladder \
                else spec["ladder"]
            for n in ladder:
                job = job_name(name, spec, n, reduced)
                path = os.path.join(a.work, job + ".inp")
                write_deck(path, name, spec, n, make_mesh(spec, n), reduced)
                print(path)
        return 0
    if shutil.which("ccx") is None:
        sys.exit("fe-referee: ccx not found (apt-get install calculix-ccx)")
    version = ccx_version()
    status = 0
    for name in names:
        spec = with_options(CASES[name], a)
        reduced = spec["element"] == "reduced"
        ladder = [int(v) for v in a.ladder.split(",")] if a.ladder \
            else spec["ladder"]
        folder = os.path.join(a.out, name)
        os.makedirs(folder, exist_ok=True)
        header = provenance(version) + describe(name, spec)
        rows, lattices = [], {}
        for n in ladder:
            row, lattice = run_case(name, spec, n, reduced, a.work, a.threads,
                                    a.reuse)
            row["ccx_version"] = version
            rows.append(row)
            if row["status"] == "converged":
                lattices[n] = lattice
            print("%-30s N %3d %-7s nodes %6d  R %.7g  SED %.7g  VM %.6g  "
                  "W %.6g  inc %3d  wall %7.1f s  %s %.4g" % (
                      name, n, row["element"], row["nodes"],
                      row["reaction_" + "xyz"[spec["load"][1]]],
                      row["mean_sed"], row["von_mises_centre"],
                      row["work_density"], row["increments"],
                      row["wall_seconds"], row["status"],
                      row["load_fraction"]), flush=True)
            if "tip_u" in row:
                print("%-30s N %3d tip u_%s on %s: %.7g m" % (
                    name, n, row["tip_axis"], row["tip_face"], row["tip_u"]),
                    flush=True)
            write_ladder(os.path.join(folder, "ladder.csv"), header, rows)
            if not a.keep:
                shutil.rmtree(os.path.join(a.work, job_name(
                    name, spec, n, reduced)), ignore_errors=True)
        done = [r for r in rows if r["status"] == "converged"]
        for old in os.listdir(folder):
            if old.startswith("lattice") or old == "tolerance.csv":
                os.remove(os.path.join(folder, old))
        if a.lattices:
            for row in done:
                write_lattice(os.path.join(folder, "lattice-N%d.csv"
                                           % row["N"]),
                              header + "# lattice of the mesh N = %d (%s)\n"
                              % (row["N"], row["element"]),
                              lattices[row["N"]])
        # A referee needs two meshes at the full load to say how far it is
        # converged; otherwise the ladder alone records what was reached.
        if len(done) < 2:
            print("%s: %d mesh(es) reached the full load: no referee, the "
                  "ladder only" % (name, len(done)))
            status = 1
            continue
        fine, prev = done[-1], done[-2]
        for row, path in ((fine, "lattice.csv"),
                          (prev, "lattice-N%d.csv" % prev["N"])):
            write_lattice(os.path.join(folder, path),
                          header + "# lattice of the mesh N = %d (%s)\n"
                          % (row["N"], row["element"]), lattices[row["N"]])
        result = write_tolerance(os.path.join(folder, "tolerance.csv"), header,
                                 spec, rows, lattices)
        for q, nf, np_, c, p, e, t, lim, spr in result:
            print("%-30s %-18s change N %d -> %d: %.3e, order %s, estimated "
                  "error %.3e (tolerance %g), extrapolated %.7g +- %.2e"
                  % (name, q, np_, nf, c, "%.2f" % p if p else "-", e, t,
                     lim, spr))
    return status


if __name__ == "__main__":
    sys.exit(main())
