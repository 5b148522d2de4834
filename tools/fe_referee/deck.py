"""The CalculiX input deck of a case on a mesh: nodes, elements, sets, the
neo-Hookean material, the static step, conditions, loads, the plates'
contact and the output requests."""

import numpy as np

from . import cases
from .cases import (AXIS, CENTRE, CONTACT, PLATE_REACH, PLATE_THICKNESS,
                    contact_slope, moduli, travel)


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
                  "%s,%s\n" % ((cases.CONTACT_TYPE,) + p) for p in pairs))
    text["boundary"] = (("NPBOT,1,3,0.\n" if bottom else "")
                        + "NPTOP,1,2,0.\nNPTOP,3,3,%s\n" % number(top))
    text["output"] = "*NODE PRINT,NSET=NPTOP,TOTALS=ONLY\nRF\n"
    return text


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


def job_name(name, spec, n, reduced):
    g = spec["grading"]
    return "%s-N%d-%s%s%s" % (name, n, element_type(spec["dim"], reduced),
                              "" if g == 1.0 else "-q%g" % g,
                              "-eighth" if len(spec["mirrors"]) == 3 else "")
