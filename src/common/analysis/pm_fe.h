/* pm_fe: finite-element reference solutions of the block cases, stored as
 * text under cases/fe/CASE/ (written by tools/fe-referee.py from CalculiX
 * runs), and the comparison of a run against one. */
#ifndef PM_FE_H
#define PM_FE_H

#include <stdbool.h>
#include <stddef.h>

#include "pm_error.h"
#include "pm_files.h"
#include "pm_run.h"

#define PM_FE_TEXT_MAX 32

/* One mesh of the ladder (a row of ladder.csv). */
typedef struct {
  int n; /* N: elements per edge (2-D: per m) */
  long nodes, dofs;
  char element[PM_FE_TEXT_MAX]; /* CalculiX element type */
  double h;                     /* element edge, m */
  double reaction[3];           /* on the loaded face, N (2-D: N/m) */
  double mean_sed;              /* strain energy / volume, J/m^3 */
  double von_mises_centre;      /* Cauchy von Mises at the centre, Pa */
  long increments;              /* converged load increments */
  double wall_seconds;
  char ccx_version[PM_FE_TEXT_MAX];
  double load_fraction; /* share of the prescribed displacement reached */
  bool converged;       /* reached the full load */
  double tip_u;         /* a traction case's tip displacement (m): the mean of u
                           along the reference's tip_axis over the lattice points
                           on its tip_face; NaN when the ladder has none */
  double cpu_seconds;   /* ccx's CPU time (user + system); NaN when absent */
  double memory_bytes;  /* ccx's peak resident memory; NaN when absent */
} pm_fe_row;

/* The relative tolerances the case is claimed converged to (tolerance.csv:
 * the change between the two finest converged meshes, rounded up). */
typedef struct {
  double reaction, mean_sed, von_mises_centre, lattice_nrmse, tip;
} pm_fe_tolerance;

typedef struct {
  char name[PM_FE_TEXT_MAX * 2]; /* the case: the folder's name */
  char dir[PM_PATH_MAX + 1];
  int n_rows;
  pm_fe_row *rows;  /* the ladder, coarsest first */
  int finest;       /* index of the finest converged row */
  int previous;     /* the converged row before it, -1 when none */
  long n;           /* lattice points */
  double *x, *u;    /* [n][3]: reference points and their displacement on
                       the finest converged mesh (lattice.csv) */
  int dim;          /* 2 when the lattice lies in z = 0, else 3 */
  double centre[3]; /* the lattice's centre: where von_mises_centre is */
  /* The referee's figures: the finest converged row's, or the Richardson
   * limits of the ladder where tolerance.csv gives them (extrapolated)
   * with an uncertainty below the finest mesh's estimated error (the
   * reaction along its largest component).  rows[finest] keeps the mesh's
   * own. */
  double reaction[3], mean_sed, von_mises_centre;
  pm_fe_tolerance tolerance; /* NaN where tolerance.csv gives none */
  /* tolerance.csv's columns extrapolated (the Richardson limit, in the
   * quantity's units) and extrapolation_uncertainty (relative); NaN where
   * it gives none. */
  pm_fe_tolerance extrapolated, extrapolation_uncertainty;
  /* Its column estimated_error: the finest mesh's error (relative). */
  pm_fe_tolerance estimated_error;
  /* A traction-loaded case (ladder columns tip_face, tip_axis, tip_u): its
   * figure is the tip displacement, the reaction being the applied load.
   * tip_face: the lattice's bounding face (0..5: xmin, xmax, ..., zmax),
   * tip_axis: the component (0..2); both -1 and tip_u NaN otherwise. */
  int tip_face, tip_axis;
  double tip_u;
} pm_fe_reference;

/* Read DIR/ladder.csv, DIR/lattice.csv and (when present)
 * DIR/tolerance.csv.  Malformed files fail with PM_ERR_ARG naming the file,
 * the line and what was expected; missing files with PM_ERR_IO.  *out is
 * released by pm_fe_free. */
pm_err pm_fe_load(const char *dir, pm_fe_reference **out);
void pm_fe_free(pm_fe_reference *r);

/* The rows of a ladder.csv alone (no lattice, no claim: a ladder just run,
 * whose meshes may all have stopped short of the load) into *rows (*n_rows
 * of them, the caller's to free).  Malformed files fail as pm_fe_load's. */
pm_err pm_fe_read_ladder(const char *path, pm_fe_row **rows, int *n_rows);

/* A lattice file (x,y,z,u_x,u_y,u_z rows under that header) into new
 * [n][3] arrays. */
pm_err pm_fe_read_lattice(const char *path, long *n, double **x, double **u);

/* The FE folder a study reference names: "fe:DIR", or a directory holding
 * ladder.csv.  Copies DIR into buf; false for anything else. */
bool pm_fe_names_reference(const char *spec, char *buf, size_t size);

/* A run against the reference. */
typedef struct {
  double nrmse;          /* displacement at the lattice (pm_nrmse_vector) */
  double nrmse_interior; /* the same over the lattice points off the
                            lattice's bounding faces (away from the clamped
                            edges and the free surface), with the whole
                            lattice's normaliser */
  double nrmse_volume;   /* the paper's sampling (eq. 28 over a dense
                            mesh's nodes, spread evenly through the
                            volume): the lattice's points weighted by the
                            volume each stands for (trapezoid weights: 1/2
                            on a face, 1/4 on an edge, 1/8 at a corner),
                            over max |u_fe| - min |u_fe| */
  double reaction_error; /* (R - R_fe) / R_fe on the loaded face, along
                            the loaded component: > 0 when the run's
                            reaction is the larger (the run is stiffer) */
  double sed_error;      /* (mean SED - FE) / FE */
  double tip_error;      /* a traction case's (tip - FE) / FE, the tip
                            displacement as pm_fe_tip (< 0 when the run is
                            stiffer); NaN for other cases */
} pm_fe_errors;

/* A traction case's tip displacement of mapped (displacements at the
 * lattice, [r->n][3]): the mean of its tip_axis component over the lattice
 * points on tip_face.  NaN when r is not a traction case. */
double pm_fe_tip(const pm_fe_reference *r, const double *mapped);

/* The NRMSE of mapped (a run's displacement at the lattice, [n][3])
 * against the reference over the lattice points off the lattice's
 * bounding faces, divided by the whole lattice's largest |u_fe| (the
 * normaliser of pm_nrmse_vector), so that it compares with the whole
 * lattice's figure; NaN when no point is inside. */
double pm_fe_nrmse_interior(const pm_fe_reference *r, const double *mapped);

/* pm_fe_errors' nrmse_volume of mapped ([r->n][3]) against r; NaN when
 * the reference does not move. */
double pm_fe_nrmse_volume(const pm_fe_reference *r, const double *mapped);

/* Write PATH: one row a lattice point, its position, the reference's and
 * the run's displacement (mapped, [r->n][3]) and |difference|, for maps of
 * where the error lives (tools/nrmse-map.py).  Fails with PM_ERR_IO. */
pm_err pm_fe_write_errors(const pm_fe_reference *r, const double *mapped,
                          const char *path);

/* The errors of a run whose displacement at the lattice is mapped
 * ([r->n][3]) and whose outcome is o. */
void pm_fe_errors_of(const pm_fe_reference *r, const double *mapped,
                     const pm_outcome *o, pm_fe_errors *e);

/* Compare the run of scene s written to out_dir (its last frame, mapped
 * onto the lattice by moving least squares; a lattice point outside a part
 * mirrored about symmetry planes takes its image's value) and its outcome
 * o with r; the pointwise errors go to out_dir/fe-errors.csv
 * (pm_fe_write_errors).  The reaction error is NaN when o has no loaded
 * face. */
pm_err pm_fe_compare(const pm_fe_reference *r, const pm_scene *s,
                     const char *out_dir, const pm_outcome *o, pm_fe_errors *e);

#endif
