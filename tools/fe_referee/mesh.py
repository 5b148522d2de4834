"""The structured (graded) mesh of quadratic serendipity elements of the part
solved, its shape functions, node sets and lattice points, and the strain
energy of a displacement field on it."""

import math

import numpy as np

from .cases import AXIS, BOX, LATTICE, SHAPE, moduli


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


def lattice_points(dim):
    step, count = LATTICE[dim]
    axes = [np.arange(c) * s for s, c in zip(step, count)]
    grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(dim, -1).T
    return grid


def make_mesh(spec, n):
    """The mesh of ladder value n of a case, graded as the case says."""
    return Mesh(spec["dim"], n, spec["mirrors"], spec["grading"],
                spec["singular"])
