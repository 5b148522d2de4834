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

usage: tools/nrmse-map.py RUN_DIR/fe-errors.csv [--referee cases/fe/CASE]
       [--plot out.png]
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("errors", nargs="+", help="fe-errors.csv files")
    ap.add_argument("--referee", help="the FE folder (cases/fe/CASE)")
    ap.add_argument("--plot", help="a PNG of the error on the mid plane")
    a = ap.parse_args()
    for path in a.errors:
        t = read_csv(path)
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
