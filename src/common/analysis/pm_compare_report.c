/* pm_compare_report: a comparison's tables (compare.md, compare.csv) and
 * its lattice's middle plane (midplane.csv, for tools/plot-compare.py). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_compare_impl.h"

#define MIB (1024.0 * 1024.0)
#define NUM_MAX PM_TABLE_NUMBER

const char *pm_table_number(char b[PM_TABLE_NUMBER], double v, int digits) {
  if (isfinite(v))
    snprintf(b, PM_TABLE_NUMBER, "%.*g", digits, v);
  else
    b[0] = 0;
  return b;
}

static const char *num(char b[NUM_MAX], double v) {
  return pm_table_number(b, v, 4);
}

static const char *cnum(char b[NUM_MAX], double v) {
  return pm_table_number(b, v, 10);
}

/* The components of condition b that a reaction is reported for. */
static unsigned bc_mask(const pm_scene *s, int b) {
  return s->bcs[b].disp_mask | s->bcs[b].velocity_mask;
}

/* Method M's reaction of condition b along k (NaN when it has none). */
static double reaction(const cmp_method *M, int b, int k) {
  return b < M->n_bcs && M->out.fig.status != PM_STATUS_NOT_RUN
             ? M->out.fig.reaction[b][k]
             : NAN;
}

void pm_csv_text(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; s++) {
    if (*s == '"') fputc('"', f);
    fputc(*s == '\n' || *s == '\r' ? ' ' : *s, f);
  }
  fputc('"', f);
}

void pm_md_text(FILE *f, const char *s) {
  for (; *s; s++) fputc(*s == '|' ? '/' : *s == '\n' ? ' ' : *s, f);
}

/* ---- compare.md --------------------------------------------------------- */

static void md_accuracy(const cmp_study *c, FILE *m) {
  char b[8][NUM_MAX];
  const bool fe = c->fe != NULL, run = c->run_u != NULL;
  const bool tip = fe && c->fe->tip_face >= 0;
  fprintf(m, "## Accuracy\n\n| method | status | points | h (m) | steps |");
  int cols = 6;
  if (c->analytic) {
    fprintf(m, " NRMSE analytic | NRMSE analytic (own points) |");
    cols += 2;
  }
  if (fe) {
    fprintf(m, " NRMSE FE | NRMSE FE (interior) | reaction error (FE) | SED "
               "error (FE) |");
    cols += 4;
  }
  if (tip) {
    fprintf(m, " tip error (FE) |");
    cols++;
  }
  if (run) {
    fprintf(m, " NRMSE reference run |");
    cols++;
  }
  fprintf(m, " flagged points |\n|");
  for (int k = 0; k < cols; k++) fprintf(m, "---|");
  fprintf(m, "\n");
  for (int k = 0; k < c->n; k++) {
    const cmp_method *M = &c->meth[k];
    const pm_figures *f = &M->out.fig;
    bool ran = f->status != PM_STATUS_NOT_RUN;
    fprintf(m, "| %s | %s |", M->name, M->status);
    if (ran)
      fprintf(m, " %ld | %.4g | %ld |", f->points, f->h, f->steps);
    else
      fprintf(m, " | | |");
    if (c->analytic)
      fprintf(m, " %s | %s |", num(b[0], M->e_analytic),
              num(b[1], M->mapped ? M->out.nrmse_vector : NAN));
    if (fe)
      fprintf(m, " %s | %s | %s | %s |", num(b[2], M->e_fe),
              num(b[3], M->e_fe_interior), num(b[4], M->reaction_fe),
              num(b[5], M->sed_fe));
    if (tip) fprintf(m, " %s |", num(b[7], M->tip_fe));
    if (run) fprintf(m, " %s |", num(b[6], M->e_run));
    if (M->mapped)
      fprintf(m, " %ld |\n", M->flagged);
    else
      fprintf(m, " |\n");
  }
}

static void md_pairs(const cmp_study *c, FILE *m) {
  char b[NUM_MAX];
  if (c->n < 2) return;
  fprintf(m,
          "\n## Between methods\n\nNRMSE of the difference of each pair: "
          "sqrt(mean |u_a - u_b|^2) over the lattice points, over %s largest "
          "|u| on them (%.6g m).\n\n|  |",
          c->scale_label, c->scale);
  for (int k = 0; k < c->n; k++) fprintf(m, " %s |", c->meth[k].name);
  fprintf(m, "\n|---|");
  for (int k = 0; k < c->n; k++) fprintf(m, "---|");
  fprintf(m, "\n");
  for (int k = 0; k < c->n; k++) {
    fprintf(m, "| %s |", c->meth[k].name);
    for (int l = 0; l < c->n; l++)
      fprintf(m, " %s |", l == k ? "-" : num(b, c->pair[k][l]));
    fprintf(m, "\n");
  }
}

static void md_figures(const cmp_study *c, FILE *m) {
  char b[8][NUM_MAX];
  fprintf(m, "\n## Figures and cost\n\n| method | mean SED (J/m^3) | von Mises "
             "at the centre (Pa) | smallest J | reaction on the loaded face "
             "(N) | wall (s) | setup (s) | memory (MiB) |\n"
             "|---|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < c->n; k++) {
    const cmp_method *M = &c->meth[k];
    const pm_figures *f = &M->out.fig;
    if (f->status == PM_STATUS_NOT_RUN) {
      fprintf(m, "| %s | | | | | | | |\n", M->name);
      continue;
    }
    fprintf(m, "| %s | %s | %s | %s | %s | %.3f | %.3f | %.3g |\n", M->name,
            num(b[0], f->mean_sed), num(b[1], M->von_mises_centre),
            num(b[2], f->min_jacobian), num(b[3], M->out.loaded_reaction),
            f->wall_seconds, f->setup_seconds, (double)f->memory_bytes / MIB);
  }
  if (c->fe) {
    const pm_fe_reference *r = c->fe;
    const pm_fe_row *row = &r->rows[r->finest];
    int axis = -1;
    for (int k = 0; k < c->n && axis < 0; k++)
      if (c->meth[k].out.loaded_axis >= 0) axis = c->meth[k].out.loaded_axis;
    fprintf(m, "| FE (N = %d, %s) | %s | %s | | %s | %.3f | | |\n", row->n,
            row->element, num(b[4], r->mean_sed),
            num(b[5], r->von_mises_centre),
            num(b[6], axis >= 0 ? r->reaction[axis] : NAN), row->wall_seconds);
  }
  fprintf(m,
          "\nThe centre: (%g, %g, %g) m, where the von Mises stress is "
          "mapped by moving least squares from the points' own.  Smallest "
          "J: over the whole run.  Wall: the run's time loop with its "
          "output; setup: discretization and operators; memory: the "
          "method's state, operators and workspace.\n",
          c->centre[0], c->centre[1], c->centre[2]);
}

static void md_reactions(const cmp_study *c, FILE *m) {
  const pm_scene *s = c->base;
  char label[64], b[NUM_MAX];
  int cols = 1;
  fprintf(m, "\n## Reactions (N%s)\n\n| method |",
          s->dimension == 2 ? "/m" : "");
  for (int bc = 0; bc < s->n_bcs; bc++)
    for (int k = 0; k < 3; k++)
      if (bc_mask(s, bc) >> k & 1u) {
        pm_run_bc_label(s, bc, label, sizeof label);
        fprintf(m, " %s %c |", label, "xyz"[k]);
        cols++;
      }
  fprintf(m, "\n|");
  for (int k = 0; k < cols; k++) fprintf(m, "---|");
  fprintf(m, "\n");
  for (int i = 0; i < c->n; i++) {
    fprintf(m, "| %s |", c->meth[i].name);
    for (int bc = 0; bc < s->n_bcs; bc++)
      for (int k = 0; k < 3; k++)
        if (bc_mask(s, bc) >> k & 1u)
          fprintf(m, " %s |", num(b, reaction(&c->meth[i], bc, k)));
    fprintf(m, "\n");
  }
  fprintf(m, "\nThe force each condition's supports apply on the body.\n");
}

static void md_failures(const cmp_study *c, FILE *m) {
  bool any = false;
  for (int k = 0; k < c->n; k++) {
    const cmp_method *M = &c->meth[k];
    if (!M->message[0]) continue;
    if (!any) fprintf(m, "\n## Failures\n\n");
    any = true;
    fprintf(m, "- %s (%s): ", M->name, M->status);
    pm_md_text(m, M->message);
    fprintf(m, "\n");
  }
}

static void md_notes(const cmp_study *c, FILE *m) {
  fprintf(m, "\n## Definitions\n\nNRMSE: FPM paper eq. 28 (root mean square "
             "of the error over the reference's largest |u|; one reference "
             "component: over its range), over the lattice points every "
             "method fits.");
  if (c->analytic)
    fprintf(m, "  Analytic: the scene's reference.displacement at the "
               "lattice; (own points): at the method's own points, as its "
               "run reports it.");
  if (c->fe) {
    const pm_fe_tolerance *t = &c->fe->tolerance;
    fprintf(m,
            "  FE: the referee's displacement at its lattice; interior: "
            "its points off the lattice's bounding faces; reaction and "
            "SED errors: (method - FE) / FE, the reaction on the loaded "
            "face along its prescribed component.  The referee claims "
            "(relative): reaction %g, mean SED %g, von Mises %g, lattice "
            "NRMSE %g; differences below these are not resolved.",
            t->reaction, t->mean_sed, t->von_mises_centre, t->lattice_nrmse);
  }
  if (c->run_u)
    fprintf(m,
            "  Reference run: the last frame of %s mapped onto the "
            "lattice like the methods.",
            c->run_dir);
  fprintf(m, "  Fields are mapped by linear moving least squares (cubic "
             "B-spline weight over 2.2 to 5 mean point spacings); a lattice "
             "point farther from a method's points than 1.5 times their mean "
             "nearest-neighbour distance (off its body), or without enough "
             "of them within that reach, is flagged and left out of every "
             "figure.\n");
}

static void write_md(const cmp_study *c, FILE *m) {
  const pm_compare_options *o = c->o;
  fprintf(m, "# Comparison of methods: %s\n\nScene %s; methods", c->base->name,
          o->scene);
  for (int k = 0; k < c->n; k++) {
    const cmp_method *M = &c->meth[k];
    fprintf(m, "%s %s", k ? "," : "", M->name);
    if (strcmp(M->name, M->method) != 0) fprintf(m, " (%s)", M->method);
  }
  if (o->n_sets) {
    fprintf(m, "; overrides");
    for (int k = 0; k < o->n_sets; k++) fprintf(m, " `%s`", o->sets[k]);
  }
  fprintf(m,
          ".  Runs in %s/LABEL.\n\nLattice: %s; %ld of its %ld points "
          "fitted by every method.\n\n",
          c->out_dir, c->lattice_label, c->n_valid, c->m);
  md_accuracy(c, m);
  md_pairs(c, m);
  md_figures(c, m);
  md_reactions(c, m);
  md_failures(c, m);
  md_notes(c, m);
}

/* ---- compare.csv -------------------------------------------------------- */

static void csv_header(const cmp_study *c, FILE *f) {
  const pm_scene *s = c->base;
  char label[64];
  fprintf(f, "kind,method,against,status,points,h,steps,nrmse_analytic,"
             "nrmse_analytic_points,nrmse_fe,nrmse_fe_interior,"
             "reaction_error_fe,sed_error_fe,nrmse_reference_run,nrmse_pair,"
             "flagged_points,mean_strain_energy_density,von_mises_centre,"
             "min_jacobian,end_min_jacobian,loaded_reaction,wall_seconds,"
             "setup_seconds,memory_bytes,tip_error_fe");
  for (int b = 0; b < s->n_bcs; b++)
    for (int k = 0; k < 3; k++)
      if (bc_mask(s, b) >> k & 1u) {
        pm_run_bc_label(s, b, label, sizeof label);
        fprintf(f, ",reaction_%s_%c", label, "xyz"[k]);
      }
  fprintf(f, ",message\n");
}

static void csv_method(const cmp_study *c, const cmp_method *M, FILE *f) {
  const pm_scene *s = c->base;
  const pm_figures *g = &M->out.fig;
  const bool ran = g->status != PM_STATUS_NOT_RUN;
  char b[16][NUM_MAX];
  fprintf(f, "method,%s,,%s,", M->name, M->status);
  if (ran)
    fprintf(f, "%ld,%.6g,%ld", g->points, g->h, g->steps);
  else
    fprintf(f, ",,");
  fprintf(f, ",%s,%s,%s,%s,%s,%s,%s,,", cnum(b[0], M->e_analytic),
          cnum(b[1], M->mapped ? M->out.nrmse_vector : NAN),
          cnum(b[2], M->e_fe), cnum(b[3], M->e_fe_interior),
          cnum(b[4], M->reaction_fe), cnum(b[5], M->sed_fe),
          cnum(b[6], M->e_run));
  if (M->mapped) fprintf(f, "%ld", M->flagged);
  if (ran)
    fprintf(f, ",%s,%s,%s,%s,%s,%.6g,%.6g,%zu", cnum(b[7], g->mean_sed),
            cnum(b[8], M->von_mises_centre), cnum(b[9], g->min_jacobian),
            cnum(b[10], g->end_min_jacobian),
            cnum(b[11], M->out.loaded_reaction), g->wall_seconds,
            g->setup_seconds, g->memory_bytes);
  else
    fprintf(f, ",,,,,,,,");
  fprintf(f, ",%s", cnum(b[13], M->tip_fe));
  for (int bc = 0; bc < s->n_bcs; bc++)
    for (int k = 0; k < 3; k++)
      if (bc_mask(s, bc) >> k & 1u)
        fprintf(f, ",%s", cnum(b[12], reaction(M, bc, k)));
  fputc(',', f);
  pm_csv_text(f, M->message);
  fputc('\n', f);
}

static void write_csv(const cmp_study *c, FILE *f) {
  const pm_scene *s = c->base;
  char b[NUM_MAX];
  int n_react = 0;
  for (int bc = 0; bc < s->n_bcs; bc++)
    for (int k = 0; k < 3; k++) n_react += bc_mask(s, bc) >> k & 1u;
  csv_header(c, f);
  for (int k = 0; k < c->n; k++) csv_method(c, &c->meth[k], f);
  for (int k = 0; k < c->n; k++)
    for (int l = k + 1; l < c->n; l++) {
      fprintf(f, "pair,%s,%s,,,,,,,,,,,,%s", c->meth[k].name, c->meth[l].name,
              cnum(b, c->pair[k][l]));
      /* flagged .. setup, memory, tip, the reactions and the message:
       * empty. */
      for (int e = 0; e < 11 + n_react; e++) fputc(',', f);
      fputc('\n', f);
    }
}

/* ---- midplane.csv ------------------------------------------------------- */

/* Whether lattice point i lies on the middle plane: y nearest the centre
 * in 3-D (an x-z section), the whole lattice in 2-D. */
static bool on_midplane(const cmp_study *c, long i, double y_mid) {
  if (c->dim == 2) return true;
  return fabs(c->x[3 * i + 1] - y_mid) <= 1e-9 * (1 + fabs(y_mid));
}

static double midplane_y(const cmp_study *c) {
  double best = NAN;
  for (long i = 0; i < c->m; i++) {
    double y = c->x[3 * i + 1];
    if (!(fabs(y - c->centre[1]) >= fabs(best - c->centre[1]))) best = y;
  }
  return best;
}

static void triple(FILE *f, const double *u) {
  for (int k = 0; k < 3; k++) fprintf(f, ",%.10g", u[k]);
}

static pm_err write_midplane(const cmp_study *c, FILE *f) {
  pm_err ret = PM_SUCCESS;
  const pm_scene *s = c->base;
  double *ref = NULL;
  const double y_mid = midplane_y(c);
  fprintf(f, "x,y,z");
  if (c->analytic)
    for (int k = 0; k < 3; k++)
      if (s->reference_mask >> k & 1u) fprintf(f, ",analytic:u_%c", "xyz"[k]);
  if (c->fe) fprintf(f, ",fe:u_x,fe:u_y,fe:u_z");
  if (c->run_u) fprintf(f, ",reference:u_x,reference:u_y,reference:u_z");
  for (int k = 0; k < c->n; k++)
    if (c->meth[k].mapped)
      fprintf(f, ",%s:u_x,%s:u_y,%s:u_z", c->meth[k].name, c->meth[k].name,
              c->meth[k].name);
  fprintf(f, "\n");
  if (c->analytic) {
    PM_TRY(PM_ALLOC(ref, 3 * c->m, "analytic field"));
    cmp_analytic(c, s->time.end, ref);
  }
  for (long i = 0; i < c->m; i++) {
    if (!on_midplane(c, i, y_mid)) continue;
    fprintf(f, "%.10g,%.10g,%.10g", c->x[3 * i], c->x[3 * i + 1],
            c->x[3 * i + 2]);
    if (c->analytic)
      for (int k = 0; k < 3; k++)
        if (s->reference_mask >> k & 1u) fprintf(f, ",%.10g", ref[3 * i + k]);
    if (c->fe) triple(f, c->fe->u + 3 * i);
    if (c->run_u) triple(f, c->run_u + 3 * i);
    for (int k = 0; k < c->n; k++)
      if (c->meth[k].mapped) triple(f, c->meth[k].u + 3 * i);
    fprintf(f, "\n");
  }
done:
  free(ref);
  return ret;
}

/* ---- the files ---------------------------------------------------------- */

pm_err cmp_write_report(const cmp_study *c, FILE *out) {
  pm_err ret = PM_SUCCESS;
  pm_afile *md = NULL, *csv = NULL, *mid = NULL;
  char path[PM_PATH_MAX + 1], *text = NULL;
  size_t len = 0;
  FILE *mem = open_memstream(&text, &len);
  PM_ENSURE(mem, PM_ERR_MEMORY, "compare.md: %s", strerror(errno));
  write_md(c, mem);
  PM_ENSURE(fclose(mem) == 0, PM_ERR_MEMORY, "compare.md: %s", strerror(errno));
  PM_TRY(pm_path_join(path, sizeof path, c->out_dir, "compare.md"));
  PM_TRY(pm_afile_open(path, &md));
  fputs(text, pm_afile_stream(md));
  PM_TRY(pm_afile_commit(md));
  md = NULL;
  PM_TRY(pm_path_join(path, sizeof path, c->out_dir, "compare.csv"));
  PM_TRY(pm_afile_open(path, &csv));
  write_csv(c, pm_afile_stream(csv));
  PM_TRY(pm_afile_commit(csv));
  csv = NULL;
  PM_TRY(pm_path_join(path, sizeof path, c->out_dir, "midplane.csv"));
  PM_TRY(pm_afile_open(path, &mid));
  PM_TRY(write_midplane(c, pm_afile_stream(mid)));
  PM_TRY(pm_afile_commit(mid));
  mid = NULL;
  if (out) fputs(text, out);
done:
  if (md) pm_afile_abort(md);
  if (csv) pm_afile_abort(csv);
  if (mid) pm_afile_abort(mid);
  free(text);
  return ret;
}
