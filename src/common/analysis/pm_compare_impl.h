/* pm_compare_impl: what a comparison holds once its methods ran, shared by
 * the driver (pm_compare.c), its lattice (pm_compare_lattice.c), its errors
 * (pm_compare_errors.c) and its tables (pm_compare_report.c). */
#ifndef PM_COMPARE_IMPL_H
#define PM_COMPARE_IMPL_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_compare.h"
#include "pm_fe.h"
#include "pm_files.h"
#include "pm_mls.h"
#include "pm_run.h"
#include "pm_scene.h"

#define CMP_NAME_MAX PM_COMPARE_NAME_MAX
#define CMP_MESSAGE_MAX PM_COMPARE_MESSAGE_MAX

/* One method's run and its figures on the lattice. */
typedef struct {
  char name[CMP_NAME_MAX];   /* its label: the method's name or LABEL */
  char method[CMP_NAME_MAX]; /* the method it runs */
  char dir[PM_PATH_MAX + 1];
  pm_err err;                    /* of its load or run (PM_SUCCESS: none) */
  char status[32];               /* pm_status_name, "refused" or "not-run" */
  char message[CMP_MESSAGE_MAX]; /* why it failed ("" when it did not) */
  pm_outcome out;                /* its run's outcome (zero when refused) */
  int n_bcs;                     /* conditions of its scene */
  bool mapped;                   /* its displacement is on the lattice */
  double *u;                     /* [m][3] at the lattice, NaN where flagged */
  long flagged;                  /* lattice points without a regular fit */
  double von_mises_centre; /* at the centre, Pa (NaN: no fit, no stress) */
  /* NRMSE against the analytic field at the lattice (at its own points:
   * out.nrmse_vector), against the FE lattice (all of it and its interior,
   * with the reaction and mean SED errors), against a reference run; NaN
   * where there is no such reference. */
  double e_analytic, e_fe, e_fe_interior, reaction_fe, sed_fe, e_run;
  double tip_fe; /* a traction case's tip error against FE (pm_fe_errors) */
  double cpu_seconds; /* CPU (user + system, every thread) over create and
                         run; NaN when it did not run */
} cmp_method;

typedef struct {
  const pm_compare_options *o;
  const pm_scene *base; /* the scene as given: name, conditions, references */
  char out_dir[PM_PATH_MAX + 1];
  /* The lattice: m points, those every mapped method and reference fits
   * (valid), its centre and what it is. */
  int dim;
  long m, n_valid;
  double *x; /* [m][3] */
  bool *valid;
  long side[3]; /* regular lattice: points per axis (0: the FE's) */
  double centre[3];
  char lattice_label[PM_PATH_MAX + 256];
  /* References. */
  bool analytic;             /* the scene's reference.displacement is used */
  const pm_fe_reference *fe; /* FE referee, or NULL */
  char run_dir[PM_PATH_MAX + 1]; /* reference run ("" when none) */
  double *run_u;                 /* its displacement at the lattice */
  double scale;                  /* largest |u| of the pairwise normaliser, m */
  char scale_label[128];
  int n;
  cmp_method meth[PM_COMPARE_MAX_METHODS];
  double pair[PM_COMPARE_MAX_METHODS][PM_COMPARE_MAX_METHODS];
} cmp_study;

/* Components of the lattice's dimension (bit mask). */
static inline unsigned cmp_mask(const cmp_study *c) {
  return c->dim == 2 ? 3u : 7u;
}

/* c's lattice: n points along the shortest axis of the bodies' box, the
 * other axes at about the same spacing (regular), or the FE referee's
 * points (fe).  PM_ERR_MEMORY, or PM_ERR_SCENE for a degenerate box. */
pm_err cmp_regular_lattice(cmp_study *c, long n);
pm_err cmp_fe_lattice(cmp_study *c);

/* The field f (ncomp components) of the cloud mls at q into v when q lies
 * on the cloud and a regular fit reaches it; false (v NaN) when q is
 * flagged. */
bool cmp_fit_on_cloud(pm_mls *mls, const double *q, int ncomp, const double *f,
                      double *v);

/* The field u of the cloud mls at every lattice point into out ([m][3]),
 * NaN where flagged; returns the flagged count.  part: the scene of the
 * run that made the cloud, whose symmetry planes fold a lattice point
 * outside it onto its image (pm_scene_mirror.h); a method's scene has its
 * own overrides, which may give the planes. */
long cmp_map_lattice(const cmp_study *c, const pm_scene *part, pm_mls *mls,
                     const double *u, double *out);

/* The last frame of the reference run c->run_dir, on the lattice
 * (c->run_u). */
pm_err cmp_map_run(cmp_study *c);

/* Every method against the references and the pairs against each other,
 * over the lattice points every mapped field fits (c->valid). */
pm_err cmp_compute_errors(cmp_study *c);

/* The analytic field at the lattice at time t into ref ([m][3], 0 where
 * the scene gives no component). */
void cmp_analytic(const cmp_study *c, double t, double *ref);

/* Write OUT/compare.md, OUT/compare.csv and OUT/midplane.csv, and print
 * compare.md to out (may be NULL). */
pm_err cmp_write_report(const cmp_study *c, FILE *out);

#endif
