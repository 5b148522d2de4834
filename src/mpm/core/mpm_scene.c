/* mpm_scene: the mpm section's keys and the checks of a scene run by MPM. */
#include "mpm_scene.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "mpm_kind.h"
#include "pm_rigid.h"

static const pm_name shape_names[] = {
    {"linear", MPM_BASIS_LINEAR}, {"quadratic", MPM_BASIS_QUADRATIC}, {0}};
static const pm_name update_names[] = {
    {"usf", MPM_USF}, {"usl", MPM_USL}, {"musl", MPM_MUSL}, {0}};
static const pm_name energy_update_names[] = {
    {"iterative", MPM_ENERGY_ITERATIVE},
    {"non-iterative", MPM_ENERGY_NON_ITERATIVE},
    {0}};
static const pm_name grid_mode_names[] = {
    {"kept", MPM_GRID_KEPT}, {"reset", MPM_GRID_RESET}, {0}};
static const pm_name operator_names[] = {
    {"assembled", MPM_OP_ASSEMBLED}, {"matrix-free", MPM_OP_MATRIX_FREE}, {0}};
static const pm_name convergence_names[] = {
    {"residual", MPM_CONV_RESIDUAL}, {"paper", MPM_CONV_PAPER}, {0}};
static const pm_name fbar_names[] = {{"none", MPM_FBAR_NONE},
                                     {"cell", MPM_FBAR_CELL},
                                     {"patch", MPM_FBAR_PATCH},
                                     {0}};
static const pm_name axis_names[] = {
    {"x", 1u << 0}, {"y", 1u << 1}, {"z", 1u << 2}, {0}};

#define O(field) offsetof(mpm_settings, field)

static const pm_key fluid_keys[] = {
    {.name = "energy_update",
     .type = PM_KEY_ENUM,
     .offset = O(fluid.energy_update),
     .def = "iterative",
     .names = energy_update_names,
     .doc = "iterative (steps 1-6 of the fluid paper) or non-iterative "
            "(eq. 27)"},
    {.name = "tolerance",
     .type = PM_KEY_NUMBER,
     .offset = O(fluid.tolerance),
     .def = "1e-10",
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "relative change of the energy that ends the iteration"},
    {.name = "max_iterations",
     .type = PM_KEY_INTEGER,
     .offset = O(fluid.max_iterations),
     .def = "50",
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 1,
     .hi = 10000,
     .doc = "cap on the iterations of one particle-step"},
    {0}};

static const pm_key implicit_keys[] = {
    {.name = "grid",
     .type = PM_KEY_ENUM,
     .offset = O(implicit.grid),
     .def = "kept",
     .names = grid_mode_names,
     .doc = "kept: the grid moves with the particles (the implicit paper's "
            "modified algorithm); reset: back to its rectilinear place after "
            "each load step (the standard algorithm)"},
    {.name = "operator",
     .type = PM_KEY_ENUM,
     .offset = O(implicit.op),
     .def = "assembled",
     .names = operator_names,
     .doc = "assembled (the tangent as a sparse matrix) or matrix-free (the "
            "tangent applied particle by particle, preconditioned by its "
            "diagonal: cg-jacobi)"},
    {.name = "convergence",
     .type = PM_KEY_ENUM,
     .offset = O(implicit.convergence),
     .def = "residual",
     .names = convergence_names,
     .doc = "residual (time.quasi_static.tolerance, relative to the first "
            "iteration) or paper (eq. 9: displacement and energy norms, "
            "both)"},
    {.name = "displacement_tolerance",
     .type = PM_KEY_NUMBER,
     .offset = O(implicit.dtol),
     .def = "1e-8",
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "convergence paper: |du_k| over the step's displacement"},
    {.name = "energy_tolerance",
     .type = PM_KEY_NUMBER,
     .offset = O(implicit.etol),
     .def = "1e-14",
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "convergence paper: |du_k . Q_k| over |du_0 . Q_0|"},
    {0}};

static const pm_key mpm_keys[] = {
    {.name = "shape",
     .type = PM_KEY_ENUM,
     .offset = O(shape),
     .def = "quadratic",
     .names = shape_names,
     .doc = "grid basis: linear or quadratic B-splines (default quadratic; "
            "linear for method mpm-implicit, the implicit paper's basis, "
            "whose conditions on the nodes at and beyond a face hold a "
            "linear field exactly)"},
    {.name = "update",
     .type = PM_KEY_ENUM,
     .offset = O(update),
     .def = "musl",
     .names = update_names,
     .doc = "usf, usl or musl"},
    {.name = "flip",
     .type = PM_KEY_NUMBER,
     .offset = O(flip),
     .def = "1",
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .hi = 1,
     .unit = "",
     .doc = "FLIP fraction of the particle velocity update (1 FLIP, 0 PIC)"},
    {.name = "particles_per_cell",
     .type = PM_KEY_NUMBERS,
     .offset = O(ppc_given),
     .count_offset = O(n_ppc_given),
     .def = "2",
     .flags = PM_KEY_WHOLE,
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 1,
     .hi = 64,
     .min_count = 1,
     .max_count = 3,
     .doc = "per direction: [n] or [nx, ny(, nz)]"},
    {.name = "null_velocity",
     .type = PM_KEY_FLAGS,
     .offset = O(null_velocity),
     .names = axis_names,
     .doc = "grid velocity components held at zero (1-D runs in the 3-D "
            "code)"},
    {.name = "fbar",
     .type = PM_KEY_ENUM,
     .offset = O(fbar),
     .def = "none",
     .names = fbar_names,
     .doc = "F-bar for solids against volumetric locking: the stress sees "
            "J averaged over the particles of each cell (cell) or over the "
            "nodes' patches (patch); none: each particle's own.  Method "
            "mpm-implicit without the key: cell when a material's Poisson "
            "ratio is 0.45 or more, else none"},
    {.name = "rebalance",
     .type = PM_KEY_NUMBER,
     .offset = O(rebalance),
     .def = "1.1",
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "across ranks (explicit steps without dynamic relaxation): "
            "when the busiest rank holds more than this many times the "
            "mean of the particles (looked at every 20 steps), the boxes "
            "are cut anew where the particles are and each goes to its new "
            "rank (a checkpoint keeps the cut); 0: the cut of the start is "
            "kept"},
    {.name = "fluid",
     .type = PM_KEY_MAPPING,
     .keys = fluid_keys,
     .doc = "{energy_update, tolerance, max_iterations}"},
    {.name = "implicit",
     .type = PM_KEY_MAPPING,
     .keys = implicit_keys,
     .doc = "{grid, operator, convergence, displacement_tolerance, "
            "energy_tolerance}: method mpm-implicit"},
    {0}};

static pm_err check_section(const pm_scene *s, void *opts) {
  mpm_settings *o = opts;
  if (o->n_ppc_given != 1 && o->n_ppc_given != s->dimension)
    return pm_scene_fail(s, "mpm.particles_per_cell", false,
                         "expected 1 or %d integers (dimension %d), got %d",
                         s->dimension, s->dimension, o->n_ppc_given);
  for (int c = 0; c < 3; c++)
    o->ppc[c] = c >= s->dimension     ? 1
                : o->n_ppc_given == 1 ? (int)o->ppc_given[0]
                                      : (int)o->ppc_given[c];
  /* The implicit solver prescribes the nodes at and beyond a held face:
   * with linear B-splines a homogeneous state is then exact (F2 to round
   * off); with quadratic ones the nodes beyond the face, held at the
   * face's value, bend the field (F2's NRMSE 3e-2 at 0.02 m cells). */
  if (!pm_scene_has(s, "mpm.shape") && strcmp(s->method, "mpm-implicit") == 0)
    o->shape = MPM_BASIS_LINEAR;
  if (o->rebalance > 0 && o->rebalance <= 1)
    return pm_scene_fail(s, "mpm.rebalance", false,
                         "expected 0 (never) or an imbalance above 1, got %g",
                         o->rebalance);
  if (s->dimension == 2 && (o->null_velocity & 4u))
    return pm_scene_fail(s, "mpm.null_velocity", false,
                         "expected a list of x, y (dimension 2), got z");
  return PM_SUCCESS;
}

const pm_section mpm_section = {
    .name = "mpm",
    .keys = mpm_keys,
    .size = sizeof(mpm_settings),
    .check = check_section,
};

const mpm_settings *mpm_scene_settings(const pm_scene *s) {
  return pm_scene_section(s, "mpm");
}

static const char *role_name(mpm_body_role r) {
  return r == MPM_BODY_MEMBRANE ? "a membrane"
         : r == MPM_BODY_RIGID  ? "a body with motion"
                                : "a volume body";
}

/* Membranes, moving bodies and their materials: each material makes one
 * kind of particle. */
static pm_err check_bodies(const pm_scene *s) {
  char p[PM_SDOC_PATH];
  for (int i = 0; i < s->n_bodies; i++) {
    const pm_scene_body *b = &s->bodies[i];
    const pm_scene_material *sm = &s->materials[b->material];
    mpm_body_role role = mpm_body_role_of(b);
    if (b->n_ppc != 0 && b->n_ppc != 1 && b->n_ppc != s->dimension)
      return pm_scene_fail(s, PM_PATH(p, "bodies.%d.particles_per_cell", i),
                           false,
                           "expected 1 or %d integers (dimension %d), got %d",
                           s->dimension, s->dimension, b->n_ppc);
    if (b->shape == PM_BODY_IMAGE && b->n_ppc)
      return pm_scene_fail(
          s, PM_PATH(p, "bodies.%d.particles_per_cell", i), true,
          "expected no particles_per_cell for an image body (it is seeded "
          "per voxel: use image.particles_per_voxel), got "
          "particles_per_cell");
    if (b->moving && pm_scene_has(s, PM_PATH(p, "bodies.%d.velocity", i)))
      return pm_scene_fail(s, p, true,
                           "expected motion or velocity, got both (a body "
                           "with motion starts at its motion's velocity)");
    if (role == MPM_BODY_MEMBRANE) {
      if (b->moving)
        return pm_scene_fail(s, PM_PATH(p, "bodies.%d.motion", i), true,
                             "expected a membrane without motion, got "
                             "motion");
      if (b->n_ppc)
        return pm_scene_fail(
            s, PM_PATH(p, "bodies.%d.particles_per_cell", i), true,
            "expected no particles_per_cell for a membrane (its points are "
            "its surface's vertices), got particles_per_cell");
      if (strcmp(sm->mat.model->name, "linear-elastic") != 0)
        return pm_scene_fail(
            s, PM_PATH(p, "materials.%d.model", b->material), false,
            "expected linear-elastic for material %s of membrane bodies.%d "
            "(plane stress in its tangent plane, eqs. 1-2), got %s",
            sm->name, i, sm->mat.model->name);
    }
    for (int j = 0; j < i; j++)
      if (s->bodies[j].material == b->material &&
          mpm_body_role_of(&s->bodies[j]) != role)
        return pm_scene_fail(
            s, PM_PATH(p, "bodies.%d.material", i), false,
            "expected a material of %s only, got %s, which bodies.%d (%s) "
            "uses: give each its own material",
            role_name(role), sm->name, j,
            role_name(mpm_body_role_of(&s->bodies[j])));
  }
  for (int mi = 0; mi < s->n_materials; mi++) {
    if (!s->materials[mi].damage.given) continue;
    bool membrane = false;
    for (int i = 0; i < s->n_bodies; i++)
      if (s->bodies[i].material == mi &&
          mpm_body_role_of(&s->bodies[i]) == MPM_BODY_MEMBRANE)
        membrane = true;
    if (!membrane)
      return pm_scene_fail(s, PM_PATH(p, "materials.%d.damage", mi), true,
                           "expected damage only on a material of membranes "
                           "(eqs. 38-41), got damage on %s",
                           s->materials[mi].name);
  }
  return PM_SUCCESS;
}

/* The loads of method fpm that MPM does not take (yet): body_force,
 * body_curve and a condition's force and at. */
static pm_err refuse_fpm_loads(const pm_scene *s) {
  char p[64];
  static const char *const top[] = {"body_force", "body_curve"};
  static const char *const per_bc[] = {"force", "at"};
  for (int k = 0; k < 2; k++)
    if (pm_scene_has(s, top[k]))
      return pm_scene_fail(s, top[k], true,
                           "expected no %s for method %s (FPM only; MPM "
                           "takes gravity), got %s",
                           top[k], s->method, top[k]);
  for (int i = 0; i < s->n_bcs; i++)
    for (int k = 0; k < 2; k++)
      if (pm_scene_has(s, PM_PATH(p, "boundary.%d.%s", i, per_bc[k])))
        return pm_scene_fail(s, p, true,
                             "expected no %s for method %s (FPM only), got "
                             "%s",
                             per_bc[k], s->method, per_bc[k]);
  return PM_SUCCESS;
}

pm_err mpm_check_scene(const pm_scene *s) {
  char p[64], what[192];
  PM_CALL(refuse_fpm_loads(s));
  PM_CALL(check_bodies(s));
  /* The box faces are grid planes, where conditions act. */
  mpm_layout lay;
  if (!mpm_grid_layout(s, &lay)) {
    snprintf(what, sizeof what,
             "a cell size that divides domain.box, or one that can be made "
             "to by at most 4 times as many cells (%g m along x)",
             s->box_max[0] - s->box_min[0]);
    return pm_scene_expected(s, "discretization.mesh_size", what);
  }
  for (int i = 0; i < s->n_bcs; i++) {
    const pm_scene_bc *bc = &s->bcs[i];
    const bool implicit = strcmp(s->method, "mpm-implicit") == 0;
    if (PM_BC_RIGID(bc)) { /* contact: mpm_contact */
      if (pm_scene_has(s, PM_PATH(p, "boundary.%d.penalty", i)))
        return pm_scene_fail(s, p, true,
                             "expected no penalty for method %s (the grid's "
                             "contact sets nodal velocities: it has no "
                             "stiffness), got penalty",
                             s->method);
      continue;
    }
    if (bc->traction_mask && bc->on == PM_ON_REGION)
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.traction", i), true,
          "expected a traction on a face of domain.box or a named surface "
          "(method %s; a region holds particles by a displacement or "
          "velocity), got traction with region",
          s->method);
    if (bc->pressure && bc->on == PM_ON_REGION)
      return pm_scene_fail(s, PM_PATH(p, "boundary.%d.pressure", i), true,
                           "expected a pressure on a face of domain.box or a "
                           "named surface (method %s; the particles at it "
                           "carry it), got pressure with region",
                           s->method);
    if (bc->pressure && (bc->disp_mask | bc->velocity_mask | bc->absorbing))
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.pressure", i), true,
          "expected a pressure without a prescribed motion (method %s; it "
          "acts on every component), got pressure with %s",
          s->method,
          bc->disp_mask       ? "displacement"
          : bc->velocity_mask ? "velocity"
                              : "absorbing");
    if (bc->on == PM_ON_SURFACE && bc->absorbing)
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.absorbing", i), true,
          "expected displacement%s or traction on a named surface (method "
          "%s; absorbing acts on faces of domain.box), got absorbing",
          implicit ? "" : ", velocity", s->method);
    if (bc->on == PM_ON_SURFACE && bc->traction_mask &&
        (bc->disp_mask | bc->velocity_mask))
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.traction", i), true,
          "expected a traction or a prescribed motion on a named surface "
          "(method %s; one condition each), got traction with %s",
          s->method, bc->disp_mask ? "displacement" : "velocity");
    if (bc->on == PM_ON_REGION && bc->absorbing)
      return pm_scene_fail(s, PM_PATH(p, "boundary.%d.absorbing", i), true,
                           "expected displacement or velocity on a region "
                           "(a grip), got absorbing");
    if (bc->on == PM_ON_REGION && !(bc->disp_mask | bc->velocity_mask))
      return pm_scene_fail(s, PM_PATH(p, "boundary.%d.region", i), true,
                           "expected displacement or velocity with a region "
                           "(a grip), got neither");
  }
  if (pm_scene_has(s, "stability.max_energy_error"))
    return pm_scene_fail(s, "stability.max_energy_error", true,
                         "expected min_jacobian only for method mpm (its "
                         "transfers dissipate energy by design: the balance "
                         "is reported, not bounded), got max_energy_error");
  if (s->time.dt_rule == PM_DT_SPECTRAL)
    return pm_scene_expected(s, "time.dt_rule",
                             "paper for method mpm (its stable step is the "
                             "CFL bound of every step)");
  return PM_SUCCESS;
}

pm_err mpm_implicit_check_scene(const pm_scene *s) {
  char p[PM_SDOC_PATH];
  const mpm_settings *ms = mpm_scene_settings(s);
  if (mpm_scene_settings(s)->fbar == MPM_FBAR_PATCH)
    return pm_scene_expected(s, "mpm.fbar",
                             "none or cell for method mpm-implicit (a node's "
                             "patch would couple cells beyond the tangent's "
                             "stencil)");
  for (int i = 0; i < s->n_bodies; i++) {
    const pm_scene_body *b = &s->bodies[i];
    const pm_scene_material *sm = &s->materials[b->material];
    if (b->shape == PM_BODY_MEMBRANE)
      return pm_scene_fail(s, PM_PATH(p, "bodies.%d.membrane", i), true,
                           "expected a volume body for method mpm-implicit "
                           "(quasi-static solids), got a membrane");
    if (b->moving)
      return pm_scene_fail(s, PM_PATH(p, "bodies.%d.motion", i), true,
                           "expected no motion for method mpm-implicit "
                           "(quasi-static: give displacements on faces)");
    if (pm_material_is_fluid(&sm->mat) || !sm->mat.model->tangent)
      return pm_scene_fail(
          s, PM_PATH(p, "materials.%d.model", b->material), false,
          "expected a solid model with a tangent for method mpm-implicit "
          "(Newton's method on the grid), got %s for material %s",
          sm->mat.model->name, sm->name);
  }
  for (int i = 0; i < s->n_bcs; i++) {
    const pm_scene_bc *bc = &s->bcs[i];
    if (PM_BC_RIGID(bc))
      return pm_rigid_refuse(s, i,
                             "method mpm or fpm for now (the implicit MPM's "
                             "tangent has no contact terms)",
                             "method mpm-implicit");
    if (bc->on == PM_ON_REGION)
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.region", i), true,
          "expected on: a face of domain.box or a named surface "
          "(displacement or traction) for method mpm-implicit (grips on "
          "regions of particles run by method mpm), got region");
    if (bc->pressure && ms->implicit.grid == MPM_GRID_RESET)
      return pm_scene_fail(s, PM_PATH(p, "boundary.%d.pressure", i), true,
                           "expected mpm.implicit.grid kept with a pressure "
                           "(its load stiffness is taken on the kept grid), "
                           "got grid reset");
    const bool cg = pm_scene_has(s, "time.quasi_static.linear_solver") &&
                    (s->time.qs_linear == PM_LINEAR_CG_JACOBI ||
                     s->time.qs_linear == PM_LINEAR_CG_GAMG);
    if (bc->pressure && (ms->implicit.op == MPM_OP_MATRIX_FREE || cg))
      return pm_scene_fail(
          s, PM_PATH(p, "boundary.%d.pressure", i), true,
          "expected an assembled tangent and a linear solver for "
          "unsymmetric matrices with a pressure (its load stiffness is not "
          "symmetric; CG needs a symmetric one), got %s",
          ms->implicit.op == MPM_OP_MATRIX_FREE ? "mpm.implicit.operator "
                                                  "matrix-free"
                                                : "a cg linear_solver");
    if (bc->velocity_mask || bc->absorbing)
      return pm_scene_fail(
          s,
          PM_PATH(p, "boundary.%d.%s", i,
                  bc->absorbing ? "absorbing" : "velocity"),
          true,
          "expected displacement or traction for method mpm-implicit "
          "(quasi-static load steps have no velocity), got %s",
          bc->absorbing ? "absorbing" : "velocity");
  }
  return PM_SUCCESS;
}

/* Whether n cells of the box's first edge divide every edge. */
static bool divides(const pm_scene *s, double h) {
  for (int c = 0; c < s->dimension; c++) {
    double cells = (s->box_max[c] - s->box_min[c]) / h;
    if (fabs(cells - round(cells)) > 1e-6 * cells || round(cells) < 1)
      return false;
  }
  return true;
}

double mpm_bc_largest_displacement(const pm_scene *s, int b, int comp,
                                   double sign) {
  const pm_scene_bc *bc = &s->bcs[b];
  double T = pm_scene_load_end(s), umax = 0;
  if (!bc->disp[comp]) return 0;
  for (int corner = 0; corner < 9; corner++) {
    double x[3];
    for (int a = 0; a < 3; a++)
      x[a] = corner == 8         ? 0.5 * (s->box_min[a] + s->box_max[a])
             : (corner >> a) & 1 ? s->box_max[a]
                                 : s->box_min[a];
    int ax = pm_face_axis(bc->face);
    x[ax] = pm_face_plane(bc->face, s->box_min, s->box_max);
    double u =
        pm_bc_factor(bc, T) * pm_expr_eval(bc->disp[comp], x[0], x[1], x[2], T);
    if (isfinite(u)) umax = fmax(umax, sign != 0 ? sign * u : fabs(u));
  }
  return umax;
}

bool mpm_grid_layout(const pm_scene *s, mpm_layout *lay) {
  memset(lay, 0, sizeof *lay);
  for (int c = 0; c < 3; c++) {
    lay->lo[c] = s->box_min[c];
    lay->hi[c] = s->box_max[c];
  }
  lay->h = s->mesh_size;
  bool fills = false; /* a body is the whole box (region: domain) */
  for (int i = 0; i < s->n_bodies; i++)
    fills = fills || s->bodies[i].shape == PM_BODY_DOMAIN;
  const bool own = divides(s, s->mesh_size);
  if (own && !fills) return true;
  if (!own) {
    /* A scene made for FPM (mesh_size a gmsh element size): the largest
     * cell no larger than it that puts every face on a grid plane, found
     * from the first edge's whole numbers of cells. */
    const double L = s->box_max[0] - s->box_min[0];
    const long n0 = (long)ceil(L / s->mesh_size - 1e-9);
    lay->h = 0;
    for (long n = n0; n <= 4 * n0 && lay->h == 0; n++)
      if (divides(s, L / n)) lay->h = L / n;
    if (lay->h == 0) return false;
  }
  lay->mapped = !own;
  /* Room: beyond each face of the box, for the body to deform into.  A
   * face whose condition holds its normal component gets the outward
   * part of that displacement; a free face the largest displacement any
   * condition prescribes (what a Poisson expansion stays under); each a
   * cell more. */
  double umax = 0;
  for (int b = 0; b < s->n_bcs; b++)
    for (int c = 0; c < s->dimension; c++)
      umax = fmax(umax, mpm_bc_largest_displacement(s, b, c, 0));
  for (int c = 0; c < s->dimension; c++)
    for (int side = 0; side < 2; side++) {
      double need = umax;
      for (int b = 0; b < s->n_bcs; b++) {
        const pm_scene_bc *bc = &s->bcs[b];
        if (bc->on != PM_ON_FACE || pm_face_axis(bc->face) != c) continue;
        const bool is_max = bc->face == PM_FACE_XMAX ||
                            bc->face == PM_FACE_YMAX ||
                            bc->face == PM_FACE_ZMAX;
        if (is_max != (side == 1)) continue;
        if (bc->velocity_mask & (1u << c))
          need = umax;
        else if (bc->disp_mask & (1u << c))
          need = mpm_bc_largest_displacement(s, b, c, is_max ? 1.0 : -1.0);
      }
      const long cells = need > 0 ? (long)ceil(need / lay->h - 1e-9) + 1 : 0;
      lay->room[c][side] = cells;
      lay->mapped = lay->mapped || cells > 0;
      if (side == 0)
        lay->lo[c] = s->box_min[c] - (double)cells * lay->h;
      else
        lay->hi[c] = s->box_max[c] + (double)cells * lay->h;
    }
  return true;
}
