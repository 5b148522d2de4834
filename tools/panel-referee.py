#!/usr/bin/env python3
"""Finite-element referee of the tapered panel (the user guide's tutorial)
by CalculiX.

The panel: 10 m long, 4 m high at the clamped edge x = 0 and 2 m at the
tip x = 10 (corners (0, 0), (10, 1), (10, 3), (0, 4)), plane strain, the
gel of the block cases (neo-Hookean, E = 3000 Pa, nu = 0.45), clamped
(u = 0) on x = 0 and loaded by a nominal traction t_y = 10 Pa on the tip
(a dead load of 20 N per metre of depth).  Each mesh of the ladder is a
structured mesh of 5N x 2N CPE8 (or CPE8R) elements mapped onto the
panel (its edges are straight, so the map is exact), solved by a
nonlinear static step (NLGEOM) to full load.  Read back: the tip's mean
displacement (the edge's integral mean, by the quadratic edge's
weights), the displacement of the tip's middle node and the clamp's
reaction; written to cases/fe/panel-tapered/ladder.csv with the
Richardson limit of the three finest meshes.

    tools/panel-referee.py --run --ladder 2,4,8,16
    tools/panel-referee.py --ladder 4 --work /tmp/panel   # the deck only

Needs CalculiX (Debian: apt-get install calculix-ccx) and numpy.
"""

import argparse
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fe_referee.cases import moduli  # noqa: E402
from fe_referee.ccx import ccx_version, last_block, read_dat  # noqa: E402
from fe_referee.deck import id_lines, number  # noqa: E402

LENGTH, NU, TRACTION = 10.0, 0.45, 10.0
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "cases", "fe", "panel-tapered")


def edges(x):
    """The panel's lower and upper edges at x."""
    return 0.1 * x, 4.0 - 0.1 * x


def make_mesh(n):
    """Nodes (id -> (x, y)) and CPE8 connectivity of the 5n x 2n mesh, the
    tip's node ids bottom to top and the clamp's."""
    nx, ny = 5 * n, 2 * n
    ids, xy = {}, []
    for j in range(2 * ny + 1):
        for i in range(2 * nx + 1):
            if i % 2 and j % 2:
                continue  # an element's centre: no node of a CPE8
            x = LENGTH * i / (2 * nx)
            lo, hi = edges(x)
            xy.append((x, lo + (hi - lo) * j / (2 * ny)))
            ids[i, j] = len(xy)
    conn = []
    for ej in range(ny):
        for ei in range(nx):
            i, j = 2 * ei, 2 * ej
            conn.append([ids[i, j], ids[i + 2, j], ids[i + 2, j + 2],
                         ids[i, j + 2], ids[i + 1, j], ids[i + 2, j + 1],
                         ids[i + 1, j + 2], ids[i, j + 1]])
    tip = [ids[2 * nx, j] for j in range(2 * ny + 1)]
    clamp = [ids[0, j] for j in range(2 * ny + 1)]
    return np.array(xy), conn, tip, clamp


def edge_weights(m):
    """The quadratic edge's weights of m = 2k + 1 nodes (k elements), as
    fractions of the edge: h/6, 2h/3, h/6 per element."""
    w = np.zeros(m)
    for e in range(0, m - 1, 2):
        w[e:e + 3] += (1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0)
    return w / w.sum()


def write_deck(path, n, reduced):
    xy, conn, tip, clamp = make_mesh(n)
    mu, kappa = moduli(NU)
    kind = "CPE8R" if reduced else "CPE8"
    out = ["*HEADING", "tapered panel, N = %d, %s" % (n, kind), "*NODE"]
    out += ["%d,%s,%s,0" % (i + 1, number(p[0]), number(p[1]))
            for i, p in enumerate(xy)]
    out.append("*ELEMENT,TYPE=%s,ELSET=EALL" % kind)
    out += [",".join(str(v) for v in [e + 1] + c) for e, c in enumerate(conn)]
    text = "\n".join(out) + "\n"
    text += "*NSET,NSET=NTIP\n" + id_lines(tip)
    text += "*NSET,NSET=NCLAMP\n" + id_lines(clamp)
    # CalculiX: U = C10 (Ibar1 - 3) + (J - 1)^2 / D1, pointmech's
    # neo-hookean with C10 = mu / 2, D1 = 2 / K.
    text += "*MATERIAL,NAME=GEL\n*HYPERELASTIC,NEO HOOKE\n"
    text += "%s,%s\n" % (number(mu / 2.0), number(2.0 / kappa))
    text += "*SOLID SECTION,ELSET=EALL,MATERIAL=GEL\n1.\n"
    text += "*STEP,NLGEOM,INC=10000\n*STATIC\n0.05,1.,1e-7,0.1\n"
    text += "*CONTROLS,PARAMETERS=FIELD\n1e-7,1e-6\n"
    text += "*CONTROLS,PARAMETERS=TIME INCREMENTATION\n4,8,9,40,10,4,0,10\n"
    text += "*BOUNDARY\nNCLAMP,1,2,0.\n*CLOAD\n"
    force = TRACTION * 2.0 * edge_weights(len(tip))  # the tip is 2 m long
    text += "".join("%d,2,%s\n" % (i, number(f)) for i, f in zip(tip, force))
    text += "*NODE PRINT,NSET=NTIP\nU\n"
    text += "*NODE PRINT,NSET=NCLAMP,TOTALS=ONLY\nRF\n*END STEP\n"
    with open(path, "w") as f:
        f.write(text)
    return len(xy), tip


def run(n, reduced, work):
    job = "panel-N%d-%s" % (n, "CPE8R" if reduced else "CPE8")
    os.makedirs(work, exist_ok=True)
    nodes, tip = write_deck(os.path.join(work, job + ".inp"), n, reduced)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.time()
    env = dict(os.environ, OMP_NUM_THREADS="1")
    with open(os.path.join(work, job + ".log"), "w") as log:
        subprocess.run(["ccx", "-i", job], cwd=work, stdout=log,
                       stderr=subprocess.STDOUT, env=env, check=True)
    wall = time.time() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    blocks = read_dat(os.path.join(work, job + ".dat"))
    u = last_block(blocks, "displacements", "NTIP")
    rf = last_block(blocks, "total force", "NCLAMP")
    rows = {int(r[0]): r[1:] for r in u[3]}
    uy = np.array([rows[i][1] for i in tip])
    ux = np.array([rows[i][0] for i in tip])
    w = edge_weights(len(tip))
    return dict(N=n, element="CPE8R" if reduced else "CPE8", nodes=nodes,
                dofs=2 * nodes, h=LENGTH / (5 * n), load=u[2],
                tip_uy=float(w @ uy), tip_ux=float(w @ ux),
                mid_uy=float(uy[len(tip) // 2]),
                reaction_x=rf[3][0][0], reaction_y=rf[3][0][1],
                wall_seconds=wall, cpu_seconds=cpu)


def richardson(h, q):
    """The limit and observed order of q over the three finest meshes
    (h halving), or None when the differences do not shrink."""
    if len(h) < 3:
        return None, None
    (h1, q1), (h2, q2), (h3, q3) = zip(h[-3:], q[-3:])
    d1, d2 = q2 - q1, q3 - q2
    if d1 == 0 or d2 == 0 or d2 / d1 <= 0 or abs(d2) >= abs(d1):
        return None, None
    p = math.log(abs(d1 / d2)) / math.log(h1 / h2)
    return q3 + d2 / ((h2 / h3) ** p - 1.0), p


COLUMNS = ["N", "element", "nodes", "dofs", "h", "load", "tip_uy", "tip_ux",
           "mid_uy", "reaction_x", "reaction_y", "wall_seconds",
           "cpu_seconds"]


def write(rows, path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("# tools/panel-referee.py, %s, %s\n" % (
            ccx_version(), time.strftime("%Y-%m-%d")))
        f.write("# tapered panel (user guide), plane strain, neo-Hookean "
                "E = 3000 Pa nu = 0.45, t_y = 10 Pa on the tip; tip_*: the "
                "tip's mean displacement (m), mid_uy: its middle node's, "
                "reaction_*: the clamp's (N per m of depth), load: the share "
                "of the load reached\n")
        f.write(",".join(COLUMNS) + "\n")
        for r in rows:
            f.write(",".join(r[c] if isinstance(r[c], str) else "%.9g" % r[c]
                             for c in COLUMNS) + "\n")
        for q in ("tip_uy", "tip_ux", "mid_uy"):
            lim, p = richardson([r["h"] for r in rows], [r[q] for r in rows])
            if lim is not None:
                f.write("# richardson %s: %.9g (order %.2f)\n" % (q, lim, p))


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--ladder", default="2,4,8,16")
    a.add_argument("--run", action="store_true")
    a.add_argument("--reduced", action="store_true", help="CPE8R elements")
    a.add_argument("--work", default="/tmp/panel-referee")
    a.add_argument("--out", default=os.path.join(OUT, "ladder.csv"))
    o = a.parse_args()
    ladder = [int(v) for v in o.ladder.split(",")]
    if not o.run:
        for n in ladder:
            write_deck(os.path.join(o.work, "panel-N%d.inp" % n), n,
                       o.reduced)
        return
    rows = []
    for n in ladder:
        rows.append(run(n, o.reduced, o.work))
        print(",".join(str(rows[-1][c]) for c in COLUMNS), flush=True)
    write(rows, o.out)


if __name__ == "__main__":
    main()
