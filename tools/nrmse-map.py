#!/usr/bin/python3
"""Where a block run's displacement error lives, and what its NRMSE is under
each reading of the FPM paper's eq. 28.

Reads the fe-errors.csv that `pointmech convergence` (or `compare`) writes
beside each run compared with a finite-element referee (one row a lattice
point: position, the referee's and the run's displacement), and prints:

  * the NRMSE three ways: the project's (every lattice point alike, over
    max |u_fe|), the interior one (off the lattice's faces), and the
    paper's sampling (each point weighted by the volume it stands for, as a
    dense mesh's nodes spread evenly through the block, over
    max |u_fe| - min |u_fe|); and the same with the range of the pooled
    components (max u - min u over all components) as the normaliser;
  * the same against the referee's previous mesh (lattice-N<k>.csv) and
    against the Richardson limit of the two (order from tolerance.csv's
    lattice_nrmse row), to show how much of the figure is the referee's
    own error;
  * the share of the squared error in each region: the clamped faces'
    edges (the singular lines), the rest of the clamped faces, the free
    lateral faces, the bands next to the clamped faces inside the block,
    and the interior (3-D block cases, clamped or loaded on zmin and
    zmax, as F3 and F4).

With --fe-run WORK (a referee run kept by `tools/fe-referee.py CASE --run
--ladder N --keep --work WORK --out DIR`) it also reads the run's own
points (RUN_DIR/results) and prints what the mapping costs: the referee's
field evaluated at the run's points and mapped back to the lattice by a
twin of pointmech's moving least squares (pm_mls: linear, cubic B-spline
over 2.2 mean spacings) and by a quadratic one, the run against the
referee under each, and the run at its own points (no mapping, each point
weighted by its share of the Delaunay volume), split into its local
smooth part and its point-to-point part.

usage: tools/nrmse-map.py RUN_DIR/fe-errors.csv [--referee cases/fe/CASE]
       [--plot out.png] [--fe-run WORK --case f4-compression-20 --n 12]
"""
import argparse
import glob
import os
import sys

import numpy as np


def read_csv(path):
    rows = [l for l in open(path) if l.strip() and not l.startswith("#")]
    head = rows[0].strip().split(",")
    data = np.array([[float(v) for v in l.split(",")] for l in rows[1:]])
    return {h: data[:, k] for k, h in enumerate(head)}


def nrmse(d, u, w, scale):
    """Weighted RMS of |d| over scale."""
    return np.sqrt(np.sum(w * np.sum(d * d, 1)) / np.sum(w)) / scale


def weights(x):
    lo, hi = x.min(0), x.max(0)
    tol = 1e-9 * (hi - lo)
    on = (x <= lo + tol) | (x >= hi - tol)
    return np.prod(np.where(on, 0.5, 1.0), 1), on


def figures(x, u_run, u_fe):
    d = u_run - u_fe
    mag = np.linalg.norm(u_fe, axis=1)
    w, on = weights(x)
    one = np.ones(len(x))
    inside = ~on.any(1)
    pooled = u_fe.max() - u_fe.min()
    return {
        "project (all points, / max|u|)": nrmse(d, u_fe, one, mag.max()),
        "interior (off the faces, / max|u|)":
            np.sqrt(np.sum(d[inside] ** 2, 1).mean()) / mag.max(),
        "paper's sampling (volume, / range|u|)":
            nrmse(d, u_fe, w, mag.max() - mag.min()),
        "all points, / pooled component range": nrmse(d, u_fe, one, pooled),
        "volume, / pooled component range": nrmse(d, u_fe, w, pooled),
    }


def regions(x, d):
    lo, hi = x.min(0), x.max(0)
    tol = 1e-9 * (hi - lo)
    on = (x <= lo + tol) | (x >= hi - tol)
    clamped = on[:, 2]
    lateral = on[:, 0] | on[:, 1]
    step = np.min(np.diff(np.unique(x[:, 2])))
    band = ((x[:, 2] <= lo[2] + step + tol[2])
            | (x[:, 2] >= hi[2] - step - tol[2]))
    names = [
        ("clamped edges (clamped face and lateral face)", clamped & lateral),
        ("clamped faces, inside their edges", clamped & ~lateral),
        ("free lateral faces", lateral & ~clamped),
        ("one lattice step from a clamped face, inside", band & ~on.any(1)),
        ("interior, farther", ~band & ~on.any(1)),
    ]
    e2 = np.sum(d * d, 1)
    total = e2.sum()
    out = []
    for name, m in names:
        out.append((name, int(m.sum()), e2[m].sum() / total,
                    np.sqrt(e2[m].mean()) if m.any() else np.nan))
    return out


def referee_lattices(ref_dir, x):
    """The finest lattice, the previous one and their Richardson limit."""
    from_file = {}
    for p in glob.glob(os.path.join(ref_dir, "lattice*.csv")):
        t = read_csv(p)
        xr = np.c_[t["x"], t["y"], t["z"]]
        if xr.shape != x.shape or np.abs(xr - x).max() > 1e-9:
            continue
        from_file[os.path.basename(p)] = np.c_[t["u_x"], t["u_y"], t["u_z"]]
    tol = [l for l in open(os.path.join(ref_dir, "tolerance.csv"))
           if l.startswith("lattice_nrmse")]
    if "lattice.csv" not in from_file or not tol:
        return None
    f = tol[0].split(",")
    n_fine, n_prev, order = int(f[1]), int(f[2]), float(f[4])
    prev = from_file.get("lattice-N%d.csv" % n_prev)
    if prev is None:
        return None
    fine = from_file["lattice.csv"]
    limit = fine + (fine - prev) / ((n_fine / n_prev) ** order - 1)
    return {"N = %d (the referee)" % n_fine: fine,
            "N = %d" % n_prev: prev,
            "Richardson limit (N = %d, %d, order %.2f)" % (n_prev, n_fine,
                                                           order): limit}


# ---- the mapping and the run's own points (--fe-run) ------------------------


def referee_field(work, case, n):
    """The kept CalculiX run's displacement as a function of points."""
    import importlib.util
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                        "fe-referee.py")
    spec = importlib.util.spec_from_file_location("fe_referee", path)
    fer = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fer)
    c = fer.CASES[case]
    mesh = fer.make_mesh(c, n)
    reduced = c.get("element", "full") == "reduced"
    job = fer.job_name(case, c, n, reduced)
    blocks = fer.read_dat(os.path.join(work, job, job + ".dat"))
    disp = fer.last_block(blocks, "displacements", "NALL")
    u = np.zeros((mesh.n_nodes, 3))
    for r in disp[3]:
        u[int(r[0]) - 1] = r[1:4]
    return lambda pts: np.array([mesh.displacement(p, u) for p in pts])


def mls(x, f, q, quadratic=False, local=None, factor=2.2):
    """pm_mls_fit's twin: the fit a + B (x - q) (plus the quadratic terms)
    weighted by the cubic B-spline of |x - q| / R, R = factor spacings
    (the cloud's mean, or local[k]), grown by half until the fit has
    3 (or 3 x 10 / 4) times its unknowns in points and is regular."""
    h = (np.prod(x.max(0) - x.min(0)) / len(x)) ** (1 / 3)
    need = 30 if quadratic else 12
    out = np.zeros((len(q), f.shape[1]))
    for k, p in enumerate(q):
        R = factor * (local[k] if local is not None else h)
        while True:
            d = np.linalg.norm(x - p, axis=1)
            m = d < R
            if m.sum() >= need:
                s = d[m] / R
                w = np.where(s <= 0.5, 1 - 6 * s**2 + 6 * s**3,
                             2 * (1 - s)**3)
                y = (x[m] - p) / R
                A = np.c_[np.ones(m.sum()), y]
                if quadratic:
                    A = np.c_[A, y**2, y[:, 0] * y[:, 1], y[:, 1] * y[:, 2],
                              y[:, 0] * y[:, 2]]
                M = (A.T * w) @ A
                if np.linalg.cond(M) < 1e10:
                    out[k] = np.linalg.solve(M, (A.T * w) @ f[m])[0]
                    break
            R *= 1.5
    return out


def run_points(run_dir):
    """The run's points, last displacement and each point's share of the
    Delaunay volume (results/mesh.h5 and the last frame, read through the
    project's Python module: the program vets each file before h5py opens
    it, and a damaged one is refused with its name and the reason)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__))), "python"))
    import pointmech
    try:
        r = pointmech.open(run_dir)
        if len(r.frames) == 0:
            sys.exit(f"nrmse-map: {run_dir}/results: no frame")
        last = r.frames[-1]
        r.check([last])  # the mesh and the last frame, in one call
        mesh = r.mesh
        for name in ("coordinates", "cells"):
            if name not in mesh:
                sys.exit(f"nrmse-map: {run_dir}/results/mesh.h5: no {name}")
        if "displacement" not in last:
            sys.exit(f"nrmse-map: {last.path}: no displacement")
        x, cells, u = mesh["coordinates"], mesh["cells"], last["displacement"]
    except (pointmech.Refused, OSError) as e:
        sys.exit(f"nrmse-map: {e}")
    if cells.ndim != 2 or cells.shape[1] != 4 or u.shape != x.shape:
        sys.exit(f"nrmse-map: {run_dir}: expected tetrahedra and one "
                 f"displacement a point (cells {cells.shape}, points "
                 f"{x.shape}, displacement {u.shape})")
    a, b, c, e = (x[cells[:, i]] for i in range(4))
    vol = np.abs(np.einsum("ij,ij->i", b - a, np.cross(c - a, e - a))) / 6
    share = np.zeros(len(x))
    for i in range(4):
        np.add.at(share, cells[:, i], vol / 4)
    return x, u, share


def mapping_report(points, q, fe_at):
    x, u, share = points
    fq, fx = fe_at(q), fe_at(x)
    scale = np.linalg.norm(fq, axis=1).max()
    w, _ = weights(q)
    one = np.ones(len(q))
    print("| mapping | exact FE field (lattice / volume) | run against FE "
          "(lattice / volume) |")
    print("|---|---|---|")
    for label, quad in (("linear MLS (pointmech's)", False),
                        ("quadratic MLS", True)):
        mf, mu = mls(x, fx, q, quad), mls(x, u, q, quad)
        print("| %s | %.3e / %.3e | %.3e / %.3e |" % (
            label, nrmse(mf - fq, fq, one, scale), nrmse(mf - fq, fq, w, scale),
            nrmse(mu - fq, fq, one, scale), nrmse(mu - fq, fq, w, scale)))
    d = u - fx
    dist = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    near = np.argsort(dist, 1)[:, 1:9]
    smooth = mls(x, d, x, local=np.cbrt(share[near].mean(1)))
    print("\nat the run's points (volume-weighted): %.3e, its smooth part "
          "%.3e, point to point %.3e" % (nrmse(d, fx, share, scale),
                                        nrmse(smooth, fx, share, scale),
                                        nrmse(d - smooth, fx, share, scale)))
    e2 = share * np.sum(d * d, 1)
    lo, hi = x[:, 2].min(), x[:, 2].max()
    band = (x[:, 2] < lo + 0.15 * (hi - lo)) | (x[:, 2] > hi - 0.15 * (hi - lo))
    print("within 15%% of the height of zmin or zmax: %.1f%% of the volume, "
          "%.1f%% of the squared error\n" % (100 * share[band].sum() /
                                             share.sum(),
                                             100 * e2[band].sum() / e2.sum()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("errors", nargs="+", help="fe-errors.csv files")
    ap.add_argument("--referee", help="the FE folder (cases/fe/CASE)")
    ap.add_argument("--plot", help="a PNG of the error on the mid plane")
    ap.add_argument("--fe-run", help="a kept referee run's work folder")
    ap.add_argument("--case", default="f4-compression-20",
                    help="its case (default f4-compression-20)")
    ap.add_argument("--n", type=int, default=12, help="its mesh N (12)")
    a = ap.parse_args()
    fe_at = None
    for path in a.errors:
        t = read_csv(path)
        points = None
        if a.fe_run:  # the run's own files first: refused before any work
            points = run_points(os.path.dirname(os.path.abspath(path)))
            fe_at = fe_at or referee_field(a.fe_run, a.case, a.n)
        x = np.c_[t["x"], t["y"], t["z"]]
        u = np.c_[t["u_x"], t["u_y"], t["u_z"]]
        fe = np.c_[t["u_fe_x"], t["u_fe_y"], t["u_fe_z"]]
        print("# %s (%d lattice points)" % (path, len(x)))
        refs = {"the file's referee": fe}
        if a.referee:
            more = referee_lattices(a.referee, x)
            if more:
                refs.update(more)
        names = list(figures(x, u, fe).keys())
        print("| NRMSE | " + " | ".join(refs) + " |")
        print("|---|" + "---|" * len(refs))
        table = {k: figures(x, u, r) for k, r in refs.items()}
        for n in names:
            print("| %s | " % n +
                  " | ".join("%.3e" % table[k][n] for k in refs) + " |")
        print()
        print("| region | points | share of squared error | RMS error (m) |")
        print("|---|---|---|---|")
        for name, m, share, rms in regions(x, u - fe):
            print("| %s | %d | %.1f%% | %.2e |" % (name, m, 100 * share, rms))
        print()
        if points is not None:
            mapping_report(points, x, fe_at)
        if a.plot:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
            mid = np.abs(x[:, 1] - np.median(np.unique(x[:, 1]))) < 1e-9
            e = np.linalg.norm(u - fe, axis=1)
            fig, ax = plt.subplots(figsize=(5, 4))
            sc = ax.scatter(x[mid, 0], x[mid, 2], c=e[mid], s=80, cmap="magma")
            fig.colorbar(sc, label="|u - u_FE| (m)")
            ax.set_xlabel("x (m)")
            ax.set_ylabel("z (m)")
            ax.set_title(os.path.basename(os.path.dirname(path)) or path)
            fig.tight_layout()
            fig.savefig(a.plot, dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
