"""The command line of tools/fe-referee.py: list, summarise, write the decks
or run the cases and write cases/fe/CASE/*.csv."""

import argparse
import os
import shutil
import sys

from . import cases
from .cases import CASES, CONTACT, with_options
from .ccx import ccx_version, run_case
from .deck import job_name, write_deck
from .extrapolate import write_tolerance
from .fold import fold_table
from .ladder import (describe, provenance, summary, write_ladder,
                     write_lattice)
from .mesh import make_mesh

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
OUT_ROOT = os.path.join(ROOT, "cases", "fe")


def main(epilog=None):
    """Run the command line (sys.argv) with epilog (the command's help text)
    under --help; returns the exit status: 0, or 1 where a case had fewer
    than two meshes at the full load.  Bad arguments exit through
    argparse; a missing ccx exits with a message."""
    ap = argparse.ArgumentParser(
        description="CalculiX referee for the FPM block cases",
        formatter_class=argparse.RawDescriptionHelpFormatter, epilog=epilog)
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
    ap.add_argument("--fold", action="store_true",
                    help="F4: measure the fold at the clamped edges on the "
                    "meshes of --ladder kept under --work (--keep): rise "
                    "past the clamp's plane, smallest J, the reaction away "
                    "from the edges")
    a = ap.parse_args()
    if a.friction is not None:
        CONTACT["friction"] = a.friction
    if a.slope is not None:
        cases.SLOPE_OPTION = a.slope
    if a.contact == "node":
        cases.CONTACT_TYPE = "NODE TO SURFACE"
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
    if a.fold:
        for name in names:
            spec = with_options(CASES[name], a)
            ladder = [int(v) for v in a.ladder.split(",")] if a.ladder \
                else spec["ladder"]
            print("%s (kept under %s)\n" % (name, a.work))
            print(fold_table(name, spec, ladder,
                             spec["element"] == "reduced", a.work))
        return 0
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
