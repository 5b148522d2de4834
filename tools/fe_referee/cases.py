"""The block cases the referee solves (F1-F4, the panel): the material, each
case's conditions, mesh ladder and part solved, the plates' contact
settings, and the command line's changes to a case."""

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
# cases/fe/README.md, "F4 40%").  Clamped, the material at the edge is
# squeezed past the clamp's plane (J at the corner's Gauss points 0.28,
# 0.093, 0.039 at N = 8, 10, 12, inverted at points of the clamped face
# from N = 8: --fold), so every finer edge element must squeeze it
# further: q = 3 (edge 0.78 mm at N = 8) stops N = 10 at 98.8% with
# inverted Gauss points, C3D20R N = 8 at 68.6%.  q = 2 stays.
F4_40 = dict(F4_MESH, ladder=[4, 8, 10, 12, 14], model="eighth")
# Between plates the plate holds the fold (J >= 0.37 at every Gauss point
# to N = 14), and the ladder goes on to N = 14 once the increments are
# halved: at 0.02, 0.05 N = 14 failed where the lateral faces reach the
# plates (56.5% of the load), at 0.01, 0.02 it converges; N = 8, 10 and
# 12 give the same reactions at either (to 1.2e-5).  N = 16 at 0.01, 0.02
# fails there too (61.5%).
F4_40_PLATES = dict(F4_40, increment=(0.01, 0.02))


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


def contact_slope(spec):
    """The plates' contact slope (Pa/m): --slope, else the case's, else
    CONTACT's."""
    return SLOPE_OPTION or spec.get("slope") or CONTACT["slope"]


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
        -0.04, "F4 between plates: as f4-plates-20 with 0.04 m",
        **F4_40_PLATES),
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


# Block sizes: the 3-D cube and the 2-D plane-strain block.
BOX = {3: (0.1, 0.1, 0.1), 2: (10.0, 4.0)}
# Elements along each edge for ladder value n: the cube n x n x n, the
# 2-D block 10n x 4n (square elements of 1/n m).
SHAPE = {3: lambda n: (n, n, n), 2: lambda n: (10 * n, 4 * n)}
# The lattice of reference points where displacements are reported.
LATTICE = {3: ((0.0125,) * 3, (9, 9, 9)), 2: ((0.5, 0.5), (21, 9))}
CENTRE = {3: (0.05, 0.05, 0.05), 2: (5.0, 2.0)}

AXIS = {"x": 0, "y": 1, "z": 2}


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
