"""Running ccx on a case's deck and reading back its .dat, .frd and .sta:
the row of the ladder (reaction, energy, centre stress, work, increments,
times) and the displacements at the lattice points."""

import math
import os
import re
import shutil
import subprocess
import time

import numpy as np

from .cases import AXIS, BOX, CENTRE, travel
from .deck import element_type, job_name, model_name, write_deck
from .mesh import lattice_points, make_mesh, strain_energy


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


def tip_displacement(spec, lattice):
    """The traction case's tip figures: the loaded face, its component, and
    the mean displacement along it over the lattice points on the face."""
    face, comp, _ = spec["traction"]
    k = AXIS[face[0]]
    plane = 0.0 if face.endswith("min") else BOX[spec["dim"]][k]
    on = np.abs(lattice[:, k] - plane) < 1e-9
    return face, "xyz"[comp], float(np.mean(lattice[on, 3 + comp]))


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
        lattice += np.array(spec.get("shift", (0.0,) * 3))[: lattice.shape[1]]
        lattice = np.hstack([np.pad(pts, ((0, 0), (0, 3 - dim))), lattice])
    if spec["traction"]:
        face, comp = spec["traction"][0], "xyz"[spec["traction"][1]]
        row.update(tip_face=face, tip_axis=comp, tip_u=math.nan)
        if lattice is not None:
            row["tip_u"] = tip_displacement(spec, lattice)[2]
    return row, lattice
