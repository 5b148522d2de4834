/* pm_bench_report: a bench suite's report: bench.md (tables and the
 * cross-validation verdict) and bench.csv, one row per method and run. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_bench_impl.h"
#include "pm_files.h"

/* The NRMSE a run is judged by, and against what: the FE referee's
 * lattice, else the analytic field, else a reference run. */
double pm_bench_judged(const pm_compare_row *r, const char **against) {
  if (isfinite(r->e_fe)) return *against = "FE", r->e_fe;
  if (isfinite(r->e_analytic)) return *against = "analytic", r->e_analytic;
  if (isfinite(r->e_run)) return *against = "run", r->e_run;
  *against = "";
  return NAN;
}

double pm_bench_fe_error(const pm_compare_row *r) {
  return isfinite(r->reaction_fe) ? r->reaction_fe : r->tip_fe;
}

void pm_bench_res_text(char *b, size_t size, double res) {
  if (isfinite(res))
    snprintf(b, size, "%g", res);
  else
    snprintf(b, size, "scene");
}

/* Whether a run reached a state its figures are of. */
static bool reached(const pm_compare_row *r) {
  return strcmp(r->status, "converged") == 0 ||
         strcmp(r->status, "completed") == 0;
}

/* Cross-validation: for each case with an FE referee and each method run
 * at two or more resolutions, the reaction error of its finest run
 * against the change its last refinement made.  A method converging
 * toward the referee at first order or better has an error no larger than
 * that change (h halved: e_f = (e_c - e_f) / (2^q - 1) <= e_c - e_f for q
 * >= 1); an error well beyond it (more than twice) is the method's bias,
 * which its own refinement does not show. */
static void md_verdict(const pm_bench_suite *S, const pm_bench_comparison *runs,
                       int n_runs, const pm_bench_fe *fe, FILE *m) {
  bool header = false;
  char b[4][PM_TABLE_NUMBER];
  for (int c = 0; c < S->n_cases; c++) {
    const pm_bench_case *C = &S->c[c];
    if (!fe[c].have) continue;
    for (int k = 0; k < C->n_methods; k++) {
      const pm_compare_row *coarse = NULL, *fine = NULL;
      for (int i = 0; i < n_runs; i++) {
        if (runs[i].c != c || k >= runs[i].n_rows) continue;
        const pm_compare_row *r = &runs[i].rows[k];
        if (!reached(r) || !isfinite(pm_bench_fe_error(r))) continue;
        if (!fine || r->points > fine->points) {
          coarse = fine;
          fine = r;
        } else if (!coarse || r->points > coarse->points) {
          coarse = r;
        }
      }
      if (!coarse) continue;
      if (!header) {
        fprintf(m, "\n## Convergence toward the referee\n\n| case | "
                   "method | points | reaction (tip) error (%%) | change "
                   "by the "
                   "last refinement (%%) | NRMSE | verdict |\n"
                   "|---|---|---|---|---|---|---|\n");
        header = true;
      }
      const double e = pm_bench_fe_error(fine);
      const double d = pm_bench_fe_error(coarse) - e;
      const double tol = fe[c].tol;
      const char *verdict =
          isfinite(tol) && fabs(e) <= tol
              ? "agrees with FE within its tolerance"
          : fabs(e) >= fabs(e + d)
              ? "not converging toward FE: its error grew with refinement"
          : fabs(e) <= 2 * fabs(d)
              ? "converging toward FE"
              : "biased: its refinement does not show its error";
      fprintf(m, "| %s | %s | %ld -> %ld | %s | %s | %s | %s |\n", C->name,
              fine->name, coarse->points, fine->points,
              pm_table_number(b[0], 100 * e, 3),
              pm_table_number(b[1], 100 * d, 3),
              pm_table_number(b[2], fine->e_fe, 3), verdict);
    }
  }
  if (header)
    fprintf(m, "\nA method whose error at its finest run is at most twice "
               "the change its last refinement made converges toward the "
               "referee (at order 1 or better in h); one whose error shrank "
               "by less than that is biased: a denser run of it alone "
               "would agree with itself and not with FE.\n");
}

/* What is done with a converged level r of a case's FE referee: err is its
 * reaction's error against the referee's loaded reaction (along axis), a
 * fraction. */
typedef void (*fe_level_fn)(FILE *f, const char *name, const pm_fe_row *r,
                            int axis, double err);

/* fn(f, ...) for each converged level of each case's FE referee, in
 * order. */
static void each_fe_level(const pm_bench_suite *S, const pm_bench_fe *fe,
                          FILE *f, fe_level_fn fn) {
  for (int c = 0; c < S->n_cases; c++) {
    const pm_bench_fe *F = &fe[c];
    if (!F->have) continue;
    for (int k = 0; k < F->n; k++) {
      const pm_fe_row *r = &F->rows[k];
      if (!r->converged) continue;
      double v = F->tip ? r->tip_u : r->reaction[F->axis];
      fn(f, S->c[c].name, r, F->tip ? -1 : F->axis,
         (v - F->reaction) / F->reaction);
    }
  }
}

/* A row of bench.md's table of the referee's ladder (axis -1: a traction
 * case's tip displacement). */
static void md_fe_level(FILE *m, const char *name, const pm_fe_row *r, int axis,
                        double err) {
  char b[3][PM_TABLE_NUMBER];
  fprintf(m, "| %s | %d | %ld | %s | %s | %s | %.3g |\n", name, r->n, r->nodes,
          pm_table_number(b[0], r->h, 4),
          pm_table_number(b[1], axis >= 0 ? r->reaction[axis] : r->tip_u, 6),
          pm_table_number(b[2], 100 * err, 3), r->wall_seconds);
}

/* A row "fe-recorded" of bench.csv (the referee's ladder as recorded when
 * it was made): err under reaction_error_fe, or under tip_error_fe for a
 * traction case (axis -1). */
static void csv_fe_level(FILE *f, const char *name, const pm_fe_row *r,
                         int axis, double err) {
  char b[2][PM_TABLE_NUMBER];
  pm_table_number(b[1], err, 10);
  fprintf(f,
          "fe-recorded,%s,,fe,CalculiX %s,converged,%ld,%s,%ld,,,,,%s,,,%.6g,"
          ",,%s,,,,\n",
          name, r->element, r->nodes, pm_table_number(b[0], r->h, 10),
          r->increments, axis >= 0 ? b[1] : "", r->wall_seconds,
          axis >= 0 ? "" : b[1]);
}

/* The first sentence (up to '.', ';' or a line's end; at most 200
 * characters) of a run's message as a table cell's text, and the row's
 * end. */
static void md_first_line(FILE *m, const char *msg) {
  char cell[204];
  size_t n = 0;
  while (msg[n] && n < sizeof cell - 4 && msg[n] != '\n' && msg[n] != ';' &&
         !(msg[n] == '.' && (msg[n + 1] == ' ' || !msg[n + 1])))
    n++;
  memcpy(cell, msg, n);
  if (msg[n] && msg[n] != '.' && msg[n] != ';' && msg[n] != '\n')
    memcpy(cell + n, "...", 3), n += 3;
  cell[n] = 0;
  pm_md_text(m, cell);
  fprintf(m, " |\n");
}

/* Rows "fe" of bench.md's table: the case's FE ladder as the bench ran
 * it, or why it did not. */
static void md_fe_rows(FILE *m, const char *name, const pm_bench_fe *F) {
  char b[4][PM_TABLE_NUMBER];
  if (F->n_levels == 0 && F->message[0]) {
    fprintf(m, "| %s | | fe | not-run | | | | | | | | | | ", name);
    md_first_line(m, F->message);
  }
  for (int k = 0; k < F->n_levels; k++) {
    const pm_bench_fe_level *L = &F->levels[k];
    fprintf(m,
            "| %s | N %d | fe | %s | %ld | %s | %ld | %s | %s | %s | %.3g | "
            "%.3g | %.1f | CalculiX %s |\n",
            name, L->n, L->status, L->nodes, pm_table_number(b[0], L->h, 4),
            L->increments, pm_table_number(b[1], L->nrmse, 3),
            isfinite(L->nrmse) ? "FE" : "",
            pm_table_number(b[2], 100 * L->error, 3), L->wall_seconds,
            L->cpu_seconds, L->memory_bytes / MIB, L->element);
  }
}

/* Rows "method" labelled fe of bench.csv: the case's FE ladder as the
 * bench ran it (or one row saying why not), the error under
 * reaction_error_fe or, for a traction case, tip_error_fe. */
static void csv_fe_rows(FILE *f, const char *name, const pm_bench_fe *F) {
  char b[5][PM_TABLE_NUMBER];
  if (F->n_levels == 0 && F->message[0]) {
    fprintf(f, "method,%s,,fe,fe,not-run,,,,,,,,,,,,,,,,,,", name);
    pm_csv_text(f, F->message);
    fputc('\n', f);
  }
  for (int k = 0; k < F->n_levels; k++) {
    const pm_bench_fe_level *L = &F->levels[k];
    pm_table_number(b[2], L->error, 10);
    fprintf(f,
            "method,%s,%s,fe,CalculiX %s,%s,%ld,%s,%ld,%s,%s,,%s,%s,,,%.6g,,"
            "%s,%s,%.6g,%d,%d,",
            name, pm_table_number(b[0], L->h, 10), L->element, L->status,
            L->nodes, b[0], L->increments, pm_table_number(b[1], L->nrmse, 10),
            isfinite(L->nrmse) ? "FE" : "", pm_table_number(b[3], L->nrmse, 10),
            F->tip ? "" : b[2], L->wall_seconds,
            pm_table_number(b[4], L->memory_bytes, 12), F->tip ? b[2] : "",
            L->cpu_seconds, F->threads, L->n);
    pm_csv_text(f, F->message);
    fputc('\n', f);
  }
}

static void write_md(const pm_bench_suite *S, const pm_bench_comparison *runs,
                     int n_runs, const pm_bench_fe *fe, double seconds,
                     FILE *m) {
  char b[6][PM_TABLE_NUMBER], res[32];
  int n_fail = 0;
  fprintf(m,
          "# Benchmark suite: %s\n\nSuite %s: %d cases, %d comparisons, "
          "%.1f s in all.\n\n## Accuracy and cost\n\n",
          S->name, S->path, S->n_cases, n_runs, seconds);
  fprintf(m, "| case | resolution (m) | method | status | points | h (m) | "
             "steps | NRMSE | against | reaction (tip) error (FE) | wall (s) "
             "| CPU (s) | memory (MiB) | diagnosis |\n|---|---|---|---|---|---|"
             "---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < n_runs; i++) {
    const pm_bench_comparison *R = &runs[i];
    pm_bench_res_text(res, sizeof res, R->res);
    if (R->n_rows == 0) {
      fprintf(m, "| %s | %s | | failed | | | | | | | | | | ", S->c[R->c].name,
              res);
      md_first_line(m, R->message);
      n_fail++;
    }
    for (int k = 0; k < R->n_rows; k++) {
      const pm_compare_row *r = &R->rows[k];
      const char *against;
      double e = pm_bench_judged(r, &against);
      n_fail += r->message[0] != 0;
      fprintf(m, "| %s | %s | %s | %s |", S->c[R->c].name, res, r->name,
              r->status);
      if (r->ran)
        fprintf(m, " %ld | %s | %ld |", r->points,
                pm_table_number(b[0], r->h, 4), r->steps);
      else
        fprintf(m, " | | |");
      fprintf(m, " %s | %s | %s |", pm_table_number(b[1], e, 3), against,
              pm_table_number(b[2], 100 * pm_bench_fe_error(r), 3));
      if (r->ran)
        fprintf(m, " %.3g | %s | %.1f | ", r->wall_seconds,
                pm_table_number(b[3], r->cpu_seconds, 3),
                (double)r->memory_bytes / MIB);
      else
        fprintf(m, " | | | ");
      md_first_line(m, r->message);
    }
    if (i + 1 == n_runs || runs[i + 1].c != R->c)
      md_fe_rows(m, S->c[R->c].name, &fe[R->c]);
  }
  fprintf(m, "\nReaction error in %% of the FE referee's loaded reaction; "
             "for a case loaded by a traction (its reaction is the load), "
             "the tip displacement's error (the mean displacement on the "
             "loaded face, negative when the run is stiffer).  Diagnosis: "
             "the first sentence of why a run stopped (all of it under "
             "Failures).  Rows fe: CalculiX on the case's FE ladder (key "
             "fe), resolution N elements per edge, points its nodes, steps "
             "its load increments, wall and CPU time of ccx alone (the "
             "deck's writing and reading excluded) on the threads said "
             "below; a mesh at or finer than the referee's own is marked "
             "reference and not measured against itself.  CPU: user and "
             "system time of every thread, a method's over its setup and "
             "run (its wall time's span), ccx's over its run.\n");
  for (int c = 0; c < S->n_cases; c++)
    if (fe[c].n_levels)
      fprintf(m,
              "\nFE of %s: ccx with %d thread%s (OMP_NUM_THREADS and "
              "CCX_NPROC_EQUATION_SOLVER, _RESULTS, _STIFFNESS), in "
              "%s.\n",
              S->c[c].name, fe[c].threads, fe[c].threads > 1 ? "s" : "",
              fe[c].run_dir);
  bool any_fe = false;
  for (int c = 0; c < S->n_cases; c++) any_fe = any_fe || fe[c].have;
  if (any_fe) {
    fprintf(m, "\n## The FE referee's recorded ladder\n\n| case | N | "
               "nodes | h (m) | "
               "reaction (N) or tip (m) | error (%%) | wall (s) |\n"
               "|---|---|---|---|---|---|---|\n");
    each_fe_level(S, fe, m, md_fe_level);
    fprintf(m, "\nAs recorded when the referee was made (cases/fe/CASE/"
               "ladder.csv, one thread, another day's load): errors against "
               "the referee's figure (its finest converged level, or the "
               "Richardson limit where surer), whose own uncertainty its "
               "tolerance.csv gives.  The rows fe above are timed in this "
               "bench.\n");
  }
  md_verdict(S, runs, n_runs, fe, m);
  if (n_fail) {
    fprintf(m, "\n## Failures\n\n");
    for (int c = 0; c < S->n_cases; c++)
      if (fe[c].message[0]) {
        fprintf(m, "- %s, fe: ", S->c[c].name);
        pm_md_text(m, fe[c].message);
        fprintf(m, "\n");
      }
    for (int i = 0; i < n_runs; i++) {
      const pm_bench_comparison *R = &runs[i];
      pm_bench_res_text(res, sizeof res, R->res);
      if (R->n_rows == 0) {
        fprintf(m, "- %s at %s: ", S->c[R->c].name, res);
        pm_md_text(m, R->message);
        fprintf(m, "\n");
      }
      for (int k = 0; k < R->n_rows; k++) {
        const pm_compare_row *r = &R->rows[k];
        if (!r->message[0]) continue;
        fprintf(m, "- %s at %s, %s (%s): ", S->c[R->c].name, res, r->name,
                r->status);
        pm_md_text(m, r->message);
        fprintf(m, "\n");
      }
    }
  }
  fprintf(m, "\n## Definitions\n\nEach case runs at each resolution "
             "(discretization.mesh_size) as one `pointmech compare` in "
             "CASE/h-RESOLUTION, whose compare.md has every figure.  NRMSE: "
             "the displacement against the FE referee's lattice when the "
             "scene has one, else against the analytic field "
             "(reference.displacement), mapped by moving least squares.  "
             "Wall time: a method's setup (FPM: meshing, cells and "
             "operators; MPM: seeding) and its run, the CPU time's span.  "
             "Pictures: "
             "accuracy-cost.png (tools/plot-bench.py).\n");
}

static void write_csv(const pm_bench_suite *S, const pm_bench_comparison *runs,
                      int n_runs, const pm_bench_fe *fe, FILE *f) {
  char b[12][PM_TABLE_NUMBER];
  fprintf(f, "kind,case,resolution,label,method,status,points,h,steps,"
             "nrmse,against,nrmse_analytic,nrmse_fe,reaction_error_fe,"
             "sed_error_fe,min_jacobian,wall_seconds,setup_seconds,"
             "memory_bytes,tip_error_fe,cpu_seconds,threads,fe_n,message\n");
  for (int i = 0; i < n_runs; i++) {
    const pm_bench_comparison *R = &runs[i];
    const char *cname = S->c[R->c].name;
    pm_table_number(b[0], R->res, 10);
    if (R->n_rows == 0) {
      fprintf(f, "method,%s,%s,,,failed,,,,,,,,,,,,,,,,,,", cname, b[0]);
      pm_csv_text(f, R->message);
      fputc('\n', f);
    }
    for (int k = 0; k < R->n_rows; k++) {
      const pm_compare_row *r = &R->rows[k];
      const char *against;
      double e = pm_bench_judged(r, &against);
      fprintf(f, "method,%s,%s,%s,%s,%s,", cname, b[0], r->name, r->method,
              r->status);
      if (r->ran)
        fprintf(f, "%ld,%s,%ld", r->points, pm_table_number(b[1], r->h, 10),
                r->steps);
      else
        fprintf(f, ",,");
      fprintf(f, ",%s,%s,%s,%s,%s,%s,%s,", pm_table_number(b[2], e, 10),
              against, pm_table_number(b[3], r->e_analytic, 10),
              pm_table_number(b[4], r->e_fe, 10),
              pm_table_number(b[5], r->reaction_fe, 10),
              pm_table_number(b[6], r->sed_fe, 10),
              pm_table_number(b[7], r->min_jacobian, 10));
      if (r->ran)
        fprintf(f, "%.6g,%.6g,%zu,", r->wall_seconds, r->setup_seconds,
                r->memory_bytes);
      else
        fprintf(f, ",,,");
      fprintf(f, "%s,%s,,,", pm_table_number(b[8], r->tip_fe, 10),
              pm_table_number(b[9], r->cpu_seconds, 6));
      pm_csv_text(f, r->message);
      fputc('\n', f);
    }
    if (i + 1 == n_runs || runs[i + 1].c != R->c)
      csv_fe_rows(f, cname, &fe[R->c]);
  }
  each_fe_level(S, fe, f, csv_fe_level);
}

pm_err pm_bench_write_report(const char *dir, const pm_bench_suite *S,
                             const pm_bench_comparison *runs, int n_runs,
                             const pm_bench_fe *fe, double seconds, FILE *out) {
  pm_err ret = PM_SUCCESS;
  pm_afile *md = NULL, *csv = NULL;
  char path[PM_PATH_MAX + 1], *text = NULL;
  size_t len = 0;
  FILE *mem = open_memstream(&text, &len);
  PM_ENSURE(mem, PM_ERR_MEMORY, "cannot build the bench report");
  write_md(S, runs, n_runs, fe, seconds, mem);
  fclose(mem);
  PM_TRY(pm_path_join(path, sizeof path, dir, "bench.md"));
  PM_TRY(pm_afile_open(path, &md));
  fputs(text, pm_afile_stream(md));
  PM_TRY(pm_afile_commit(md));
  md = NULL;
  PM_TRY(pm_path_join(path, sizeof path, dir, "bench.csv"));
  PM_TRY(pm_afile_open(path, &csv));
  write_csv(S, runs, n_runs, fe, pm_afile_stream(csv));
  PM_TRY(pm_afile_commit(csv));
  csv = NULL;
  if (out) fprintf(out, "report in %s/bench.{md,csv}\n", dir);
done:
  if (md) pm_afile_abort(md);
  if (csv) pm_afile_abort(csv);
  free(text);
  return ret;
}
