#!/usr/bin/python3
"""Memory per rank past this machine: a model calibrated on measured peaks.

A rank's peak resident memory is modelled as

    M(P) = F + G + b * held(P)

F: the floor of every process (the program and its libraries: MPI, HDF5;
PETSc only where a run solves, gmsh only in the child that meshes),
measured on a scene of a few hundred points; G: what every rank holds
whatever P (a membrane seeded whole, an image read whole); b: bytes per point or particle held; held(P): the
points of the largest rank's share with its ghosts, from `pointmech plan
SCENE --ranks P` (the partition the run would make).  b and G come from
two measured peaks of the scene, one process (held = N) and the largest
rank other than 0 on 4 ranks; the peak on 2 ranks, not used in the fit,
checks the model.  The ranks other than 0 are what every rank would hold
once rank 0 no longer keeps the whole model for the output.

The largest scene on machines of 24 GiB with one rank a core (two ranks a
machine, 12 GiB a rank): the N for which M(P) reaches 12 GiB, scaling G
with N where it is a whole copy of something the scene sizes (membrane,
image, mesh), held(P) as held at the measured N scaled by N (a fixed ghost
fraction: conservative, as larger shares have relatively fewer ghosts).

usage: tools/rank-memory-model.py [BUILD_DIR]   (default build)
"""
import re
import subprocess
import sys

MIB = 2.0 ** 20
RANK_BYTES = 12 * 2.0 ** 30  # a 24 GiB machine of 2 cores, a rank a core
RANKS = [2, 4, 16, 64, 256, 1000]

# Measured peaks, MiB (docs/validation.md: "Memory per rank, the
# exchanges, checkpoints and meshing together (issue 31)", at cae4f27 for
# the blocks, 225f53f for the full oocyte and F3; I2 in pieces, every rank
# without the whole model, "Implicit MPM across ranks in pieces", at
# 6548c40: its largest rank of any, 0 included).  n: points or
# particles; floor: a rank's floor (the disks; FPM's: F3 at 45 points on a
# rank that does not mesh); m1: one process; m2, m4: the largest rank
# other than 0 on 2 and 4 ranks; g_scales: G is a whole copy that grows
# with the scene (a membrane, an image).  FPM's ranks other than 0 hold no
# whole copy since only rank 0 meshes; rank 0's own bound is the text's.
# The construct I1 at its full size was measured on one process only
# (9.2 GB, issue 31): its G is the image every rank reads (8-bit, one
# byte a particle), its b from the one-process peak.
SCENES = [
    {"name": "MPM block, mesh_size 1.25e-3", "scene": "cases/mpm/bench-block.yaml",
     "set": ["discretization.mesh_size=1.25e-3"], "n": 884736, "floor": 30.9,
     "m1": 384.9, "m2": 217.7, "m4": 127.4, "g_scales": False},
    {"name": "full oocyte (M4)", "scene": "cases/mpm/m4-oocyte.yaml", "set": [],
     "n": 176026, "floor": 30.9, "m1": 130.3, "m2": 91.3, "m4": 85.8,
     "g_scales": True},
    {"name": "I2 at 256^2 cells (implicit)", "scene": "cases/mpm/i2-vessel-slice.yaml",
     "set": ["discretization.mesh_size=2.1e-6"], "n": 262144, "floor": 30.9,
     "m1": 395.0, "m2": 245.9, "m4": 150.0, "g_scales": True},
    {"name": "FPM F3 60%, 32715 points", "scene": "cases/fpm/f3-extension-60.yaml",
     "set": ["discretization.mesh_size=2.98e-3"], "n": 32715, "floor": 28.0,
     "m1": 298.0, "m2": 254.7, "m4": 176.9, "g_scales": False},
    {"name": "full construct I1 (implicit)", "scene": "cases/mpm/i1-construct.yaml",
     "set": [], "n": 13631488, "floor": 30.9, "m1": 9.2e9 / MIB, "m2": None,
     "m4": None, "g_scales": True, "g_bytes_per_point": 1.0},
]


def held(build, sc, ranks):
    """Points of the largest share with its ghosts at `ranks`, and the
    node-sum or ghost bytes a rank sends a step at most (None, None when
    the plan cannot cut the scene so)."""
    cmd = [build + "/pointmech", "plan", sc["scene"], "--ranks", str(ranks)]
    for s in sc["set"]:
        cmd += ["--set", s]
    out = subprocess.run(cmd, capture_output=True, text=True)
    text = out.stdout + out.stderr
    h = re.search(r"memory/rank .*its share with its ghosts, (\d+) points", text)
    b = re.search(r"(\d+) at most\b[^\n]*$", text, re.M)
    sends = re.findall(r"(\d+) bytes [^\n]*? (\d+) at most", text)
    if not h:
        why = re.search(r"error: (.*)", text)
        return None, (why.group(1)[:90] if why else "no plan")
    return int(h.group(1)), (int(sends[-1][1]) if sends else None)


def fit(sc, h4):
    n, f = sc["n"], sc["floor"]
    if sc.get("m4") is None:  # one process only: G given, b from m1
        g = sc["g_bytes_per_point"] * n / MIB
        b = (sc["m1"] - f - g) * MIB / n
        return b, g
    b = (sc["m1"] - sc["m4"]) * MIB / (n - h4)
    g = sc["m1"] - f - b * n / MIB
    return b, max(g, 0.0)


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    print("| scene | points | b (bytes a point) | G (MiB, every rank) | "
          "2 ranks: model / measured | " +
          " | ".join("%d ranks" % p for p in RANKS) +
          " | largest scene, 12 GiB a rank; a rank's messages at most |")
    print("|---" * (5 + len(RANKS) + 1) + "|")
    for sc in SCENES:
        h = {p: held(build, sc, p) for p in RANKS}
        h4 = h[4][0]
        b, g = fit(sc, h4 if h4 else sc["n"] / 4)
        cells = []
        for p in RANKS:
            hp, extra = h[p]
            if hp is None:
                cells.append("cannot cut")
                continue
            m = sc["floor"] + g + b * hp / MIB
            cells.append("%.0f MiB" % m)
        check = "-"
        if sc.get("m2") and h[2][0]:
            check = "%.0f / %.0f" % (sc["floor"] + g + b * h[2][0] / MIB,
                                     sc["m2"])
        # the largest N on the most ranks the plan could cut (pmax):
        # F + G(N) + b rho N / pmax <= 12 GiB, rho = held over the even share
        pmax = max(p for p in RANKS if h[p][0])
        rho = h[pmax][0] * pmax / sc["n"]
        g_per = g * MIB / sc["n"] if sc["g_scales"] else 0.0
        room = RANK_BYTES - sc["floor"] * MIB - (0 if sc["g_scales"] else g * MIB)
        nmax = room / (g_per + b * rho / pmax)
        big = "%.2g on %d ranks" % (nmax, pmax)
        if sc["g_scales"] and g_per > 0:
            big += " (its whole copy alone: %.2g)" % (room / g_per)
        sent = h[pmax][1]
        big += "; sends %s a step" % ("%.0f kB" % (sent / 1e3) if sent else "-")
        print("| %s | %d | %.0f | %.1f | %s | %s | %s |" % (
            sc["name"], sc["n"], b, g, check, " | ".join(cells), big))


if __name__ == "__main__":
    main()
