/* pm_study: ladders of runs, errors against an analytic field, a
 * reference run or a finite-element reference (mapped by moving least
 * squares), rates and wall times. */
#include "pm_study.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_fe.h"
#include "pm_files.h"
#include "pm_memory.h"
#include "pm_metrics.h"
#include "pm_probe.h"

#define VALUE_MAX 128

typedef struct {
  char key[VALUE_MAX];
  int n;
  char value[PM_STUDY_MAX_LEVELS][VALUE_MAX];
} ladder_key;

typedef struct {
  pm_outcome out;
  pm_err err;
  double error; /* NRMSE against the reference; NaN when none */
  double rate;  /* against the previous level; NaN when none */
  /* Against a finite-element reference (NaN otherwise): the relative
   * errors of the reaction on the loaded face and of the mean strain
   * energy density, and the reaction error's rate; a traction case's
   * tip displacement error (pm_fe_errors), whose rate reaction_rate then
   * holds. */
  double reaction_error, reaction_rate, sed_error, tip_error;
  double error_interior; /* NRMSE off the lattice's faces (FE only) */
  double error_volume;   /* NRMSE weighted by volume (FE only) */
  char dir[PM_PATH_MAX + 1];
} level;

/* Split "key=v1,v2,..." into k. */
static pm_err parse_ladder(const char *spec, ladder_key *k) {
  const char *eq = strchr(spec, '=');
  PM_CHECK(eq && eq > spec && (size_t)(eq - spec) < VALUE_MAX, PM_ERR_SCENE,
           "--set-ladder %s: expected KEY=V1,V2,...", spec);
  memcpy(k->key, spec, (size_t)(eq - spec));
  k->key[eq - spec] = 0;
  k->n = 0;
  for (const char *p = eq + 1;;) {
    const char *end = strchr(p, ',');
    size_t len = end ? (size_t)(end - p) : strlen(p);
    PM_CHECK(len > 0 && len < VALUE_MAX, PM_ERR_SCENE,
             "--set-ladder %s: expected non-empty values of at most %d "
             "characters separated by commas",
             spec, VALUE_MAX - 1);
    PM_CHECK(k->n < PM_STUDY_MAX_LEVELS, PM_ERR_SCENE,
             "--set-ladder %s: at most %d values", spec, PM_STUDY_MAX_LEVELS);
    memcpy(k->value[k->n], p, len);
    k->value[k->n][len] = 0;
    k->n++;
    if (!end) break;
    p = end + 1;
  }
  return PM_SUCCESS;
}

/* Load the scene of level lv (every --set, then the ladder values). */
static pm_err load_level(const pm_study_options *o, const ladder_key *keys,
                         int lv, pm_scene **s) {
  const char *sets[64 + PM_STUDY_MAX_KEYS];
  char buf[PM_STUDY_MAX_KEYS][2 * VALUE_MAX + 2];
  int n = 0;
  PM_CHECK(o->n_sets <= 64, PM_ERR_ARG, "at most 64 --set options");
  for (int k = 0; k < o->n_sets; k++) sets[n++] = o->sets[k];
  for (int k = 0; k < o->n_keys; k++) {
    snprintf(buf[k], sizeof buf[k], "%s=%s", keys[k].key, keys[k].value[lv]);
    sets[n++] = buf[k];
  }
  return pm_scene_load(o->scene, n, sets, s);
}

/* Error of run dir of scene s (points x, n) against the reference (rx,
 * ru, rn); a reference point outside a part mirrored about the scene's
 * symmetry planes takes its image's value (pm_probe_map). */
static pm_err error_against(const pm_scene *s, const char *dir, int dim,
                            long rn, const double *rx, const double *ru,
                            double *work, double *err) {
  long n;
  double *x = NULL, *u = NULL;
  pm_err ret = PM_SUCCESS;
  unsigned mask = dim == 2 ? 3u : 7u;
  PM_TRY(pm_results_read(dir, -1, &n, &x, &u));
  bool same = n == rn;
  for (long i = 0; same && i < 3 * n; i++)
    same = fabs(x[i] - rx[i]) <= 1e-12 * (1 + fabs(rx[i]));
  if (same) {
    *err = pm_nrmse_vector(rn, mask, u, ru);
  } else {
    PM_TRY(pm_probe_map(dir, -1, s, rn, rx, work));
    *err = pm_nrmse_vector(rn, mask, work, ru);
  }
done:
  free(x);
  free(u);
  return ret;
}

static void fmt_num(char *b, size_t size, double v) {
  if (isfinite(v))
    snprintf(b, size, "%.4g", v);
  else
    b[0] = 0;
}

/* What the levels are compared with, for the tables. */
typedef struct {
  const char *label;         /* "the scene's analytic field", ... */
  const pm_fe_reference *fe; /* NULL unless a finite-element reference */
  double q_fit, q_reaction;  /* least-squares rates (NaN when none) */
} comparison;

static pm_err write_tables(const char *out_dir, const ladder_key *keys,
                           int n_keys, const level *lv, int n_levels,
                           const level *ref, const comparison *cmp, FILE *out) {
  pm_err ret = PM_SUCCESS;
  pm_afile *csv = NULL, *md = NULL;
  char path[PM_PATH_MAX + 1];
  bool fe = cmp->fe != NULL;
  bool tip = fe && cmp->fe->tip_face >= 0;
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "convergence.csv"));
  PM_TRY(pm_afile_open(path, &csv));
  PM_TRY(pm_path_join(path, sizeof path, out_dir, "convergence.md"));
  PM_TRY(pm_afile_open(path, &md));
  FILE *c = pm_afile_stream(csv), *m = pm_afile_stream(md);
  fprintf(c, "level");
  fprintf(m, "| level |");
  for (int k = 0; k < n_keys; k++) {
    fprintf(c, ",%s", keys[k].key);
    fprintf(m, " %s |", keys[k].key);
  }
  fprintf(c, ",h,points,steps,status,error,rate,wall_seconds,setup_seconds,"
             "mean_strain_energy_density,max_von_mises,reaction,min_jacobian,"
             "energy_balance_error,reaction_error,reaction_rate,sed_error,"
             "error_interior,tip_error,error_volume\n");
  fprintf(m,
          " h (m) | points | steps | NRMSE | q |%s wall (s) | mean SED "
          "(J/m^3) | max von Mises (Pa) | reaction (N) | min J | energy "
          "error | status |\n|",
          !fe   ? ""
          : tip ? " NRMSE (interior) | NRMSE (volume) | tip error | q (tip) "
                  "| SED error |"
                : " NRMSE (interior) | NRMSE (volume) | reaction error | q "
                  "(reaction) | SED error |");
  for (int k = 0; k < n_keys + 13 + (fe ? 5 : 0); k++) fprintf(m, "---|");
  fprintf(m, "\n");
  int total = n_levels + (ref ? 1 : 0);
  for (int r = 0; r < total; r++) {
    const level *L = r < n_levels ? &lv[r] : ref;
    const pm_figures *f = &L->out.fig;
    char e[32], q[32], w[32], sed[32], vm[32], re[32], mj[32], ee[32];
    char rerr[32], rq[32], serr[32], ei[32], terr[32], ev[32];
    fmt_num(e, sizeof e, L->error);
    fmt_num(q, sizeof q, L->rate);
    snprintf(w, sizeof w, "%.3f", f->wall_seconds);
    fmt_num(sed, sizeof sed, f->mean_sed);
    fmt_num(vm, sizeof vm, f->max_von_mises);
    fmt_num(re, sizeof re, L->out.loaded_reaction);
    fmt_num(mj, sizeof mj, f->min_jacobian);
    fmt_num(ee, sizeof ee, f->energy_error);
    fmt_num(rerr, sizeof rerr, L->reaction_error);
    fmt_num(rq, sizeof rq, L->reaction_rate);
    fmt_num(serr, sizeof serr, L->sed_error);
    fmt_num(ei, sizeof ei, L->error_interior);
    fmt_num(terr, sizeof terr, L->tip_error);
    fmt_num(ev, sizeof ev, L->error_volume);
    const char *status = r < n_levels ? pm_status_name(f->status) : "reference";
    if (r < n_levels) {
      fprintf(c, "%d", r + 1);
      fprintf(m, "| %d |", r + 1);
    } else {
      fprintf(c, "ref");
      fprintf(m, "| ref |");
    }
    for (int k = 0; k < n_keys; k++) {
      int idx = r < n_levels ? r : keys[k].n - 1;
      fprintf(c, ",%s", keys[k].value[idx]);
      fprintf(m, " %s |", keys[k].value[idx]);
    }
    fprintf(c,
            ",%.6g,%ld,%ld,%s,%s,%s,%s,%.4g,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s\n",
            f->h, f->points, f->steps, status, e, q, w, f->setup_seconds, sed,
            vm, re, mj, ee, rerr, rq, serr, ei, terr, ev);
    fprintf(m, " %.4g | %ld | %ld | %s | %s |", f->h, f->points, f->steps, e,
            q);
    if (fe)
      fprintf(m, " %s | %s | %s | %s | %s |", ei, ev, tip ? terr : rerr, rq,
              serr);
    fprintf(m, " %s | %s | %s | %s | %s | %s | %s |\n", w, sed, vm, re, mj, ee,
            status);
  }
  fprintf(m,
          "\nError: NRMSE (FPM paper eq. 28, root mean square) of the "
          "displacement against %s.\n",
          cmp->label);
  if (isfinite(cmp->q_fit))
    fprintf(m,
            "Observed rate (least-squares slope of log error against log "
            "h over the levels): q = %.3f.\n",
            cmp->q_fit);
  if (fe) {
    const pm_fe_reference *r = cmp->fe;
    fprintf(m,
            "FE reference: reaction (%.7g, %.7g, %.7g) N, mean SED %.7g "
            "J/m^3, von Mises at (%g, %g, %g) %.6g Pa.  Reaction and SED "
            "errors: (run - FE) / FE, the reaction on the loaded face "
            "along its prescribed component (> 0: the run is stiffer).  "
            "NRMSE (interior): the lattice points off its bounding faces "
            "(away from the clamped edges and the free surface), over the "
            "whole lattice's largest displacement.  NRMSE (volume): the "
            "paper's sampling, every lattice point weighted by the volume it "
            "stands for (1/2 on a face, 1/4 on an edge, 1/8 at a corner), "
            "as a dense mesh's nodes spread evenly through the block; its "
            "rows of pointwise errors are in each level's fe-errors.csv.\n",
            r->reaction[0], r->reaction[1], r->reaction[2], r->mean_sed,
            r->centre[0], r->centre[1], r->centre[2], r->von_mises_centre);
    if (tip)
      fprintf(m,
              "A traction case: its reaction is the applied load; the tip "
              "error is (u - u_FE) / u_FE of the mean u_%c over the "
              "lattice's points on its face %c%s (FE: %.7g m; < 0: the run "
              "is stiffer), tolerance %g.\n",
              "xyz"[r->tip_axis], "xyz"[r->tip_face / 2],
              r -> tip_face % 2 ? "max" : "min", r->tip_u, r->tolerance.tip);
    const pm_fe_tolerance *t = &r->tolerance;
    fprintf(m,
            "The referee claims (relative, between its two finest meshes and "
            "their trend): %s %g, mean SED %g, von Mises %g, lattice "
            "NRMSE %g; differences below these are not resolved.\n",
            tip ? "tip" : "reaction", tip ? t->tip : t->reaction, t->mean_sed,
            t->von_mises_centre, t->lattice_nrmse);
    if (isfinite(cmp->q_reaction))
      fprintf(m, "Observed rate of the %s error: q = %.3f.\n",
              tip ? "tip" : "reaction", cmp->q_reaction);
  }
  PM_TRY(pm_afile_commit(csv));
  csv = NULL;
  PM_TRY(pm_afile_commit(md));
  md = NULL;
  if (out) {
    PM_TRY(pm_path_join(path, sizeof path, out_dir, "convergence.md"));
    FILE *in = fopen(path, "r");
    if (in) {
      char line[1024];
      while (fgets(line, sizeof line, in)) fputs(line, out);
      fclose(in);
    }
  }
done:
  if (csv) pm_afile_abort(csv);
  if (md) pm_afile_abort(md);
  return ret;
}

/* Rate of |err| between consecutive levels against x (NaN where either
 * value is missing), and the least-squares rate over all levels. */
/* The run flags of the study's levels. */
static unsigned run_flags(const pm_study_options *o) {
  return (o->quiet ? PM_RUN_QUIET : 0u) |
         (o->overwrite ? PM_RUN_OVERWRITE : 0u);
}

static double rates(int n, const double *x, const double *err, double *rate) {
  double a[PM_STUDY_MAX_LEVELS];
  for (int l = 0; l < n; l++) {
    a[l] = fabs(err[l]);
    rate[l] = NAN;
    if (l > 0 && x[l] > 0 && x[l - 1] > 0 && a[l] > 0 && a[l - 1] > 0 &&
        x[l] != x[l - 1])
      rate[l] = log(a[l] / a[l - 1]) / log(x[l] / x[l - 1]);
  }
  return n >= 2 ? pm_convergence_rate(n, x, a) : NAN;
}

/* The reference a study is against: "analytic", "last", "fe" or "run". */
typedef enum { REF_ANALYTIC, REF_LAST, REF_FE, REF_RUN } ref_mode;

pm_err pm_study_run(const pm_study_options *o, FILE *out) {
  pm_err ret = PM_SUCCESS, first_fail = PM_SUCCESS;
  ladder_key *keys = NULL;
  level *lv = NULL, ref = {.err = PM_SUCCESS};
  pm_scene *s = NULL;
  pm_fe_reference *fe = NULL;
  double *rx = NULL, *ru = NULL, *work = NULL;
  long rn = 0;
  char out_dir[PM_PATH_MAX + 1], ref_label[PM_PATH_MAX + 128];
  char fe_dir[PM_PATH_MAX + 1] = "";
  PM_ENSURE(o->n_keys >= 1, PM_ERR_SCENE,
            "convergence needs at least one --set-ladder KEY=V1,V2,...");
  PM_TRY(PM_ALLOC(keys, o->n_keys, "ladder"));
  for (int k = 0; k < o->n_keys; k++) {
    PM_TRY(parse_ladder(o->ladder[k], &keys[k]));
    PM_ENSURE(keys[k].n == keys[0].n, PM_ERR_SCENE,
              "--set-ladder %s has %d values but %s has %d: every ladder "
              "needs the same number",
              keys[k].key, keys[k].n, keys[0].key, keys[0].n);
  }
  int n_all = keys[0].n;
  /* Validate every level's scene, and its memory estimate, before running
   * anything. */
  bool analytic = false;
  for (int l = 0; l < n_all; l++) {
    PM_TRY(load_level(o, keys, l, &s));
    PM_TRY(pm_memory_check(s));
    if (l == 0) {
      analytic = s->reference_mask != 0;
      if (s->reference_fe)
        snprintf(fe_dir, sizeof fe_dir, "%s", s->reference_fe);
      if (o->out_dir)
        snprintf(out_dir, sizeof out_dir, "%s", o->out_dir);
      else
        snprintf(out_dir, sizeof out_dir, "out/%s-convergence", s->name);
    }
    pm_scene_destroy(s);
    s = NULL;
  }
  /* Without --reference: the scene's FE referee, else its analytic field,
   * else the last ladder value. */
  ref_mode mode;
  if (!o->reference)
    mode = fe_dir[0] ? REF_FE : analytic ? REF_ANALYTIC : REF_LAST;
  else if (strcmp(o->reference, "analytic") == 0)
    mode = REF_ANALYTIC;
  else if (strcmp(o->reference, "last") == 0)
    mode = REF_LAST;
  else if (pm_fe_names_reference(o->reference, fe_dir, sizeof fe_dir))
    mode = REF_FE;
  else
    mode = REF_RUN;
  PM_ENSURE(mode != REF_ANALYTIC || analytic, PM_ERR_SCENE,
            "%s: --reference analytic: the scene has no reference field",
            o->scene);
  PM_ENSURE(strncmp(o->reference ? o->reference : "", "fe:", 3) != 0 ||
                mode == REF_FE,
            PM_ERR_SCENE, "--reference %s: expected fe:DIR", o->reference);
  int n_levels = mode == REF_LAST ? n_all - 1 : n_all;
  PM_ENSURE(n_levels >= 1, PM_ERR_SCENE,
            "--reference last needs at least two ladder values (the last "
            "one is the reference run)");
  if (mode == REF_FE) PM_TRY(pm_fe_load(fe_dir, &fe));
  PM_TRY(pm_mkdir_p(out_dir));
  PM_TRY(PM_ALLOC(lv, n_levels, "ladder levels"));

  /* The reference run comes first so each level's error is known at once. */
  if (mode == REF_LAST) {
    PM_TRY(pm_path_join(ref.dir, sizeof ref.dir, out_dir, "reference"));
    PM_TRY(load_level(o, keys, n_all - 1, &s));
    if (out) fprintf(out, "reference run -> %s\n", ref.dir);
    ref.err = pm_run_scene(s, ref.dir, run_flags(o), &ref.out);
    ref.error = ref.rate = NAN;
    ref.reaction_error = ref.reaction_rate = ref.sed_error = NAN;
    ref.tip_error = NAN;
    ref.error_interior = ref.error_volume = NAN;
    pm_scene_destroy(s);
    s = NULL;
    if (ref.err != PM_SUCCESS) {
      char why[1024];
      snprintf(why, sizeof why, "%s", pm_error_message());
      PM_FAIL(ref.err, "the reference run (%s) failed: %s", ref.dir, why);
    }
    snprintf(ref_label, sizeof ref_label, "the reference run %s", ref.dir);
  } else if (mode == REF_RUN) {
    snprintf(ref.dir, sizeof ref.dir, "%s", o->reference);
    snprintf(ref_label, sizeof ref_label, "the reference run %s", o->reference);
  } else if (mode == REF_FE) {
    const pm_fe_row *f = &fe->rows[fe->finest];
    snprintf(ref_label, sizeof ref_label,
             "the finite-element lattice of %s (%ld points; N = %d, %s, "
             "CalculiX %s)",
             fe->dir, fe->n, f->n, f->element, f->ccx_version);
  } else {
    snprintf(ref_label, sizeof ref_label, "the scene's analytic field");
  }
  if (mode == REF_LAST || mode == REF_RUN) {
    PM_TRY(pm_results_read(ref.dir, -1, &rn, &rx, &ru));
    PM_TRY(PM_ALLOC(work, 3 * rn, "mapped displacement"));
  }
  for (int l = 0; l < n_levels; l++) {
    level *L = &lv[l];
    char name[32];
    snprintf(name, sizeof name, "level-%d", l + 1);
    PM_TRY(pm_path_join(L->dir, sizeof L->dir, out_dir, name));
    PM_TRY(load_level(o, keys, l, &s));
    if (out) {
      fprintf(out, "level %d/%d:", l + 1, n_levels);
      for (int k = 0; k < o->n_keys; k++)
        fprintf(out, " %s=%s", keys[k].key, keys[k].value[l]);
      fprintf(out, " -> %s\n", L->dir);
    }
    L->err = pm_run_scene(s, L->dir, run_flags(o), &L->out);
    L->error = L->rate = NAN;
    L->reaction_error = L->reaction_rate = L->sed_error = NAN;
    L->tip_error = NAN;
    L->error_interior = L->error_volume = NAN;
    if (L->err != PM_SUCCESS) {
      pm_scene_destroy(s);
      s = NULL;
      if (out) fprintf(out, "  %s\n", pm_error_message());
      if (first_fail == PM_SUCCESS) first_fail = L->err;
      continue;
    }
    if (mode == REF_ANALYTIC) {
      L->error = L->out.nrmse_vector;
    } else if (mode == REF_FE) {
      pm_fe_errors e;
      PM_TRY(pm_fe_compare(fe, s, L->dir, &L->out, &e));
      L->error = e.nrmse;
      L->error_interior = e.nrmse_interior;
      L->error_volume = e.nrmse_volume;
      L->reaction_error = e.reaction_error;
      L->sed_error = e.sed_error;
      L->tip_error = e.tip_error;
    } else {
      PM_TRY(error_against(s, L->dir, L->out.fig.dim, rn, rx, ru, work,
                           &L->error));
    }
    pm_scene_destroy(s);
    s = NULL;
  }
  /* Rates: in h for a resolution ladder, else in the first key's value. */
  bool by_h = false;
  for (int l = 1; l < n_levels; l++)
    if (fabs(lv[l].out.fig.h - lv[0].out.fig.h) > 1e-9 * lv[0].out.fig.h)
      by_h = true;
  double xs[PM_STUDY_MAX_LEVELS], es[PM_STUDY_MAX_LEVELS];
  double rs[PM_STUDY_MAX_LEVELS], rate[PM_STUDY_MAX_LEVELS];
  for (int l = 0; l < n_levels; l++) {
    xs[l] = by_h ? lv[l].out.fig.h : strtod(keys[0].value[l], NULL);
    es[l] = lv[l].error;
    rs[l] = fe && fe->tip_face >= 0 ? lv[l].tip_error : lv[l].reaction_error;
  }
  double q_fit = rates(n_levels, xs, es, rate);
  for (int l = 0; l < n_levels; l++) lv[l].rate = rate[l];
  double q_reaction = rates(n_levels, xs, rs, rate);
  for (int l = 0; l < n_levels; l++) lv[l].reaction_rate = rate[l];
  comparison cmp = {.label = ref_label,
                    .fe = fe,
                    .q_fit = by_h ? q_fit : NAN,
                    .q_reaction = by_h ? q_reaction : NAN};
  PM_TRY(write_tables(out_dir, keys, o->n_keys, lv, n_levels,
                      mode == REF_LAST ? &ref : NULL, &cmp, out));
  if (out && !by_h && isfinite(q_fit))
    fprintf(out, "slope of log error against log %s: %.3f\n", keys[0].key,
            q_fit);
  if (out) fprintf(out, "tables in %s/convergence.{md,csv}\n", out_dir);
  if (first_fail != PM_SUCCESS)
    ret = PM_ERROR(first_fail, "%s: some levels failed (see the table)",
                   o->scene);
done:
  pm_scene_destroy(s);
  pm_fe_free(fe);
  free(keys);
  free(lv);
  free(rx);
  free(ru);
  free(work);
  return ret;
}
