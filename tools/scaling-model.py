"""Predict the time per step of an MPM run on P ranks from what one process
measures and what the decomposition gives, and its efficiency against the
first count of ranks.

The work of a step is measured on one process (pointmech plan: seconds per
step on one thread for the explicit MPM; for the implicit MPM the seconds
of a run by solver phase and its linear iterations, given as options).  The
shares come from `pointmech plan SCENE --ranks P`: the busiest rank's
particles over the mean (imbalance) and its ghost nodes, from which follow
the bytes of node sums it sends.  The network is two numbers, assumed, not
measured here: the latency of a message or of one stage of a collective
(--alpha, s) and a rank's bandwidth (--beta, bytes/s).

Explicit MPM, per step on P ranks:
  T = imbalance * T1 / P                                  the particles' work
    + exchanges * 2 * neighbours * alpha                  node sums: messages
    + bytes / beta                                        node sums: volume
    + collectives * alpha * ceil(log2 P)                  agreements, dt, sums
    + 2 * neighbours * alpha                              migration (counts,
                                                          then particles)
with 2 exchanges a step (MUSL: the transfer, the remap), the busiest rank's
neighbours as the plan counts them, and 16 collectives (an agreement after each of about 8
stages, the stable step, the step's figures, the migration's two, the
observer's two).
Implicit MPM, per run on P ranks (--implicit):
  T = imbalance * (assembly + residual) / P
    + iterations * (linear / iterations / P
                    + halos * (2 * neighbours * alpha + 24 * ghosts / beta)
                    + reductions * alpha * ceil(log2 P))
with, per linear iteration, 8 halo exchanges and 3 reductions for GMRES +
GAMG (a Krylov step and a multigrid cycle of a few levels; the coarse
grids' solve is left out: it does not shrink with P), or 1 and 3 for CG +
Jacobi (one product with the tangent; PETSc's CG reduces (p, Ap),
(z, r) and the norm of z): --per-iteration HALOS,REDUCTIONS.

Usage:
  /usr/bin/python3 tools/scaling-model.py POINTMECH SCENE --ranks 20,60,120,200
      [--set KEY=VALUE]... [--alpha 1.5e-6] [--beta 1e10]
      [--implicit ASSEMBLY,RESIDUAL,LINEAR,ITERATIONS]
      [--per-iteration HALOS,REDUCTIONS]   (8,3: GMRES + GAMG; 1,3: CG +
                                            Jacobi)
"""
import argparse
import math
import os
import re
import subprocess
import sys


def plan(pointmech, scene, sets, ranks=None):
    cmd = [pointmech, 'plan', scene]
    for s in sets:
        cmd += ['--set', s]
    if ranks:
        cmd += ['--ranks', str(ranks)]
    env = dict(os.environ, OMP_NUM_THREADS='1')
    out = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if out.returncode != 0:
        sys.exit('plan failed: %s' % out.stderr.strip())
    return out.stdout


def number(pattern, text, what):
    m = re.search(pattern, text)
    if not m:
        sys.exit('the plan does not give %s' % what)
    return [float(g) for g in m.groups()]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('pointmech')
    ap.add_argument('scene')
    ap.add_argument('--ranks', default='20,60,120,200')
    ap.add_argument('--set', action='append', default=[])
    ap.add_argument('--alpha', type=float, default=1.5e-6)
    ap.add_argument('--beta', type=float, default=1e10)
    ap.add_argument('--implicit', default=None)
    ap.add_argument('--per-iteration', default='8,3')
    a = ap.parse_args()
    ranks = [int(r) for r in a.ranks.split(',')]
    halos, reductions = [int(x) for x in a.per_iteration.split(',')]
    one = plan(a.pointmech, a.scene, a.set)
    n, = number(r'particles +(\d+)', one, 'the particles')
    if not a.implicit:
        t1, = number(r'estimate +([0-9.e+-]+) s per step', one,
                     'the seconds per step')
        print('one process, one thread: %d particles, %.3g s per step '
              '(%.3g us per particle-step)' % (n, t1, t1 / n * 1e6))
    else:
        asm, res, lin, its = [float(x) for x in a.implicit.split(',')]
        print('one process: %d particles; assembly %.3g s, residuals %.3g s, '
              'linear solves %.3g s over %d iterations (%d halo exchanges '
              'and %d reductions each)' % (n, asm, res, lin, its, halos,
                                           reductions))
    print('network (assumed): alpha %.2g s, beta %.2g bytes/s' %
          (a.alpha, a.beta))
    rows = []
    for p in ranks:
        text = plan(a.pointmech, a.scene, a.set, p)
        lo, hi, imb = number(
            r'particles per rank (\d+) to (\d+) \(imbalance ([0-9.]+)', text,
            'the particles per rank')
        gmean, gmax, ratio, nbr = number(
            r'ghost nodes per rank (\d+) on average, (\d+) at most '
            r'\(([0-9.]+) of its own at most\), (\d+) neighbour', text,
            'the ghost nodes')
        bmax, = number(r'per step on average, (\d+) at most', text,
                       'the bytes per step')
        cuts = number(r'cuts along x (\d+), y (\d+), z (\d+)', text,
                      'the cuts')
        lg = math.ceil(math.log2(p))
        if not a.implicit:
            work = imb * t1 / p
            comm = (2 * 2 * nbr * a.alpha + bmax / a.beta +
                    16 * a.alpha * lg + 2 * nbr * a.alpha)
        else:
            work = imb * (asm + res) / p + lin / p
            comm = its * (halos * (2 * nbr * a.alpha + 24 * gmax / a.beta) +
                          reductions * a.alpha * lg)
        rows.append((p, cuts, imb, gmax, ratio, nbr, bmax, work, comm))
    base = rows[0][0] * (rows[0][7] + rows[0][8])
    unit = 's per step' if not a.implicit else 's'
    print('| ranks | cuts x, y, z | imbalance | ghost nodes (busiest) | over '
          'its own | neighbours | node bytes per step | work (%s) | '
          'communication (%s) | total | efficiency against %d |' %
          (unit, unit, rows[0][0]))
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for p, cuts, imb, g, ratio, nbr, b, w, c in rows:
        print('| %d | %d, %d, %d | %.3f | %d | %.2f | %d | %d | %.3g | %.3g | '
              '%.3g | %.0f%% |' % (p, *cuts, imb, g, ratio, nbr, b, w, c,
                                   w + c, 100 * base / (p * (w + c))))


main()
