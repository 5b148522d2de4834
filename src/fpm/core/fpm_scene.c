/* fpm_scene: the fpm section's keys and the checks of a scene run by FPM. */
#include "fpm_scene.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "gm_cells.h"

static const pm_name flux_names[] = {
    {"iipg", FPM_FLUX_IIPG}, {"sipg", FPM_FLUX_SIPG}, {NULL, 0}};

static const pm_name jump_names[] = {
    {"linear", FPM_JUMP_LINEAR}, {"quadratic", FPM_JUMP_QUADRATIC}, {NULL, 0}};

static const pm_name volumetric_names[] = {
    {"standard", FPM_VOLUMETRIC_STANDARD},
    {"averaged", FPM_VOLUMETRIC_AVERAGED},
    {NULL, 0}};

static const pm_name spacing_names[] = {{"reference", FPM_SPACING_REFERENCE},
                                        {"current", FPM_SPACING_CURRENT},
                                        {NULL, 0}};

static const pm_name formulation_names[] = {
    {"default", FPM_FORMULATION_DEFAULT},
    {"paper", FPM_FORMULATION_PAPER},
    {NULL, 0}};

/* The paper's formulation: the defaults of the keys it sets. */
#define PAPER_PENALTY 20.0

static const pm_key fpm_keys[] = {
    {.name = "formulation",
     .type = PM_KEY_ENUM,
     .offset = offsetof(fpm_options, formulation),
     .def = "default",
     .names = formulation_names,
     .doc = "default (IIPG flux, quadratic jump, penalty 0.05, averaged "
            "volume: within 0.6-1.6% of converged FE on the "
            "near-incompressible F3 blocks at 1851 points) or paper (the FPM "
            "paper's flux: "
            "linear jump, penalty 20, standard volume; 18-28% stiff at nu = "
            "0.495, but it holds at the largest strains); fpm keys given "
            "beside it override its values"},
    {.name = "penalty",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(fpm_options, penalty),
     .def = "0.05",
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "interior penalty p: beta = p E / h per interface (20 with "
            "formulation: paper)"},
    {.name = "boundary_penalty",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(fpm_options, boundary_penalty),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "with the quadratic jump, a second penalty p_b (beta = p_b E / "
            "h) on the jump of the points' linear fields across every "
            "interface of a point on the body's boundary, where the "
            "quadratic fits are one-sided (ignored with the linear jump)"},
    {.name = "stiffening",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(fpm_options, stiffening),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "a penalty that stiffens with the jump: the energy p_s E / h^3 "
            "|e| |[[u]]|^4 / 4 on the jump of the points' linear fields "
            "across every interface, negligible where the field is smooth "
            "(jump O(h^2)) and strong where the fits part (jump O(h))"},
    {.name = "stiffening_jump",
     .type = PM_KEY_ENUM,
     .offset = offsetof(fpm_options, stiffening_jump),
     .def = "linear",
     .names = jump_names,
     .doc =
         "the jump fpm.stiffening measures: linear (each point's linear "
         "field) or quadratic (the quadratic fits' jump, O(h^3) where the "
         "field is smooth, so weaker there; the linear jump's with fpm.jump: "
         "linear)"},
    {.name = "stiffening_onset",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(fpm_options, stiffening_onset),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "where fpm.stiffening begins, as a jump relative to the points' "
            "spacing: its energy becomes p_s E / h^3 |e| phi(g) / 4, g = "
            "|[[u]]|^2 - (tau h)^2, phi = g^3 / (g + (tau h)^2) where "
            "|[[u]]| > tau h and nil below, so it costs nothing where every "
            "jump stays under tau h (0: the plain quartic, acting at every "
            "jump)"},
    {.name = "stiffening_spacing",
     .type = PM_KEY_ENUM,
     .offset = offsetof(fpm_options, stiffening_spacing),
     .def = "reference",
     .names = spacing_names,
     .doc = "the spacing h of fpm.stiffening_onset: reference (the two "
            "points' distance in the reference configuration) or current "
            "(their deformed distance |x_k + u_k - x_i - u_i|, so the onset "
            "grows where the body stretches and shrinks where it is "
            "compressed; the energy stays exact, its force and tangent "
            "include the onset's derivative)"},
    {.name = "volume_penalty",
     .type = PM_KEY_NUMBER,
     .offset = offsetof(fpm_options, volume_penalty),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "a penalty that grows with the points' volume change: the energy "
            "p_v E / (2 h) |e| phi |[[u]]|^2 on the jump of the points' "
            "linear fields, phi = ((ln J_i)^2 + (ln J_k)^2) / 2, nil where J "
            "= 1 and without bound as a point collapses (J -> 0)"},
    {.name = "flux",
     .type = PM_KEY_ENUM,
     .offset = offsetof(fpm_options, flux),
     .def = "iipg",
     .names = flux_names,
     .doc = "iipg (the paper's eq. 16) or sipg (symmetric, energy-"
            "conserving)"},
    {.name = "jump",
     .type = PM_KEY_ENUM,
     .offset = offsetof(fpm_options, jump),
     .def = "quadratic",
     .names = jump_names,
     .doc = "the reconstruction whose interface jump the penalty measures: "
            "linear (each point's linear field, the paper) or quadratic (a "
            "least-squares quadratic fit about each point, the default: the "
            "penalty then vanishes on quadratic fields and does not stiffen "
            "near-incompressible solids)"},
    {.name = "volumetric",
     .type = PM_KEY_ENUM,
     .offset = offsetof(fpm_options, volumetric),
     .def = "averaged",
     .names = volumetric_names,
     .doc = "the volumetric stress: averaged (the default: an F-bar kind, "
            "each point's J averaged over its support, the exact gradient "
            "of sum V U(Jbar); for models split as W_iso + U(J): "
            "neo-hookean, neo-hookean-log, mooney-rivlin, ogden, "
            "holzapfel-gasser-ogden; IIPG flux) or standard "
            "(U'(J) of each point's own J; what formulation: paper, the "
            "SIPG flux and other models get when the key is not given)"},
    {.name = "cells",
     .type = PM_KEY_STRING,
     .offset = offsetof(fpm_options, cells),
     .def = "median-dual",
     .doc = "the partition into subdomains: median-dual (of the gmsh "
            "mesh's simplices) or voronoi (Voronoi cells of the mesh nodes "
            "clipped to the domain box; box domains only)"},
    {0}};

/* Whether every material of s is split as W_iso + U(J), which the
 * averaged volume needs. */
static bool materials_split(const pm_scene *s) {
  for (int i = 0; i < s->n_materials; i++)
    if (!pm_material_has_volumetric(&s->materials[i].mat)) return false;
  return true;
}

static pm_err check_section(const pm_scene *s, void *opts) {
  fpm_options *o = opts;
  char what[256];
  if (o->formulation == FPM_FORMULATION_PAPER) {
    if (!pm_scene_has(s, "fpm.jump")) o->jump = FPM_JUMP_LINEAR;
    if (!pm_scene_has(s, "fpm.penalty")) o->penalty = PAPER_PENALTY;
  }
  /* The averaged volume is the default where it applies; the paper's
   * formulation, the SIPG flux and models without the volumetric split
   * keep the standard term unless the scene asks (check_volumetric then
   * refuses what cannot be honoured). */
  if (!pm_scene_has(s, "fpm.volumetric") &&
      (o->formulation == FPM_FORMULATION_PAPER || o->flux == FPM_FLUX_SIPG ||
       !materials_split(s)))
    o->volumetric = FPM_VOLUMETRIC_STANDARD;
  if (gm_cells_find(o->cells)) return PM_SUCCESS;
  size_t used = (size_t)snprintf(what, sizeof what, "one of");
  for (int k = 0; k < gm_cells_count() && used < sizeof what; k++)
    used += (size_t)snprintf(what + used, sizeof what - used, "%s %s",
                             k ? "," : "", gm_cells_at(k)->name);
  return pm_scene_expected(s, "fpm.cells", what);
}

const pm_section fpm_section = {
    .name = "fpm",
    .keys = fpm_keys,
    .size = sizeof(fpm_options),
    .check = check_section,
};

const fpm_options *fpm_scene_options(const pm_scene *s) {
  return pm_scene_section(s, "fpm");
}

static pm_err check_materials(const pm_scene *s) {
  char p[64];
  for (int i = 0; i < s->n_materials; i++) {
    const pm_scene_material *m = &s->materials[i];
    if (pm_material_is_fluid(&m->mat))
      return pm_scene_expected(s, PM_PATH(p, "materials.%d.model", i),
                               "a solid model for method fpm");
    if (pm_scene_has(s, PM_PATH(p, "materials.%d.artificial_viscosity", i)))
      return pm_scene_fail(s, p, true,
                           "expected no artificial viscosity for method fpm "
                           "(a shock viscosity of MPM), got "
                           "artificial_viscosity");
    if (m->damage.given)
      return pm_scene_fail(s, PM_PATH(p, "materials.%d.damage", i), true,
                           "expected no damage for method fpm (the "
                           "elastodamage of MPM membranes), got damage");
  }
  return PM_SUCCESS;
}

static pm_err check_bodies(const pm_scene *s) {
  static const char *const mpm_only[] = {"velocity", "density", "pressure"};
  static const char *const mpm_keys[] = {
      "membrane", "inside", "outside", "motion", "particles_per_cell", "image"};
  char p[64];
  for (int i = 0; i < s->n_bodies; i++) {
    for (int k = 0; k < 6; k++)
      if (pm_scene_has(s, PM_PATH(p, "bodies.%d.%s", i, mpm_keys[k])))
        return pm_scene_fail(s, p, true,
                             "expected a key of an FPM body (material, "
                             "region, box, sphere, cylinder, mesh, fibres), "
                             "got %s (method mpm)",
                             mpm_keys[k]);
    for (int k = 0; k < 3; k++)
      if (pm_scene_has(s, PM_PATH(p, "bodies.%d.%s", i, mpm_only[k])))
        return pm_scene_fail(s, p, true,
                             "expected no initial %s for method fpm (it "
                             "starts at rest in the reference state), got %s",
                             mpm_only[k], mpm_only[k]);
  }
  return PM_SUCCESS;
}

static pm_err check_boundary(const pm_scene *s) {
  char p[64];
  for (int i = 0; i < s->n_bcs; i++) {
    const pm_scene_bc *bc = &s->bcs[i];
    if (bc->velocity_mask || bc->absorbing)
      return pm_scene_fail(
          s,
          PM_PATH(p, "boundary.%d.%s", i,
                  bc->velocity_mask ? "velocity" : "absorbing"),
          true,
          "expected displacement or traction (method fpm), "
          "got %s",
          bc->velocity_mask ? "velocity" : "absorbing");
    if (bc->on == PM_ON_SURFACE &&
        !(s->n_bodies == 1 && s->bodies[0].shape == PM_BODY_MESH))
      return pm_scene_expected(s, PM_PATH(p, "boundary.%d.on", i),
                               "a face of domain.box (xmin, xmax, ymin, ymax, "
                               "zmin, zmax), a region, or the name of a "
                               "physical surface of a gmsh body");
  }
  return PM_SUCCESS;
}

/* fpm.volumetric: averaged needs the volumetric split of every material
 * and the IIPG flux (the SIPG adjoint term would couple the averages). */
static pm_err check_volumetric(const pm_scene *s) {
  const fpm_options *o = fpm_scene_options(s);
  if (!o || o->volumetric != FPM_VOLUMETRIC_AVERAGED) return PM_SUCCESS;
  for (int i = 0; i < s->n_materials; i++)
    if (!pm_material_has_volumetric(&s->materials[i].mat))
      return pm_scene_fail(
          s, "fpm.volumetric", true,
          "expected standard for material %s (%s): averaged needs a model "
          "split as W_iso + U(J) (neo-hookean, neo-hookean-log, "
          "mooney-rivlin, ogden, holzapfel-gasser-ogden), got averaged",
          s->materials[i].name, s->materials[i].mat.model->name);
  if (o->flux == FPM_FLUX_SIPG)
    return pm_scene_fail(s, "fpm.volumetric", true,
                         "expected standard with fpm.flux sipg (averaged "
                         "needs the IIPG flux), got averaged");
  return PM_SUCCESS;
}

pm_err fpm_check_scene(const pm_scene *s) {
  PM_CALL(check_materials(s));
  PM_CALL(check_volumetric(s));
  PM_CALL(check_bodies(s));
  PM_CALL(check_boundary(s));
  return PM_SUCCESS;
}
