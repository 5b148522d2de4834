/* pointmech: the command-line program.  The only layer that knows every
 * backend: it loads the scene and hands it to the backend of its method. */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_driver.h"
#include "mpm_driver.h"
#include "pm_error.h"
#include "pm_probe.h"
#include "pm_scene.h"
#include "pm_study.h"

enum { EXIT_OK = 0, EXIT_INPUT = 1, EXIT_NUMERIC = 2, EXIT_NOT_CONVERGED = 3 };

#define MAX_SETS 64

static void usage(FILE *out) {
  fprintf(out,
          "usage: pointmech run SCENE [--out DIR] [--set KEY=VALUE]... "
          "[--quiet]\n"
          "       pointmech plan SCENE [--set KEY=VALUE]...\n"
          "       pointmech probe OUT --points FILE.csv [--frame N]\n"
          "       pointmech convergence SCENE --set-ladder KEY=V1,V2,... "
          "[--set-ladder ...]\n"
          "                 [--reference analytic|last|DIR] [--out DIR] "
          "[--set KEY=VALUE]...\n"
          "       pointmech --help | --version\n"
          "\n"
          "  run    simulate SCENE (YAML); writes OUT/results.h5 + "
          "results.xdmf,\n"
          "         history.csv and summary.json (default OUT: out/NAME)\n"
          "  plan   print the pipeline, counts, time step, steps, memory and "
          "an\n"
          "         estimated run time without running\n"
          "  probe  print the displacement of a run's last (or N-th) frame "
          "at the\n"
          "         reference coordinates of FILE.csv (x,y,z per line), by "
          "moving\n"
          "         least squares, as CSV\n"
          "  convergence  run SCENE once per ladder value (several ladders "
          "go in\n"
          "         step) and tabulate h, points, steps, NRMSE against the "
          "analytic\n"
          "         field or a reference run (default: the last value), the "
          "rate q\n"
          "         and wall time in OUT/convergence.{md,csv} (default OUT:\n"
          "         out/NAME-convergence); plot with "
          "tools/plot-convergence.py\n"
          "  --set  override any scene value by its dotted key, e.g.\n"
          "         --set discretization.mesh_size=8.02e-3 --set "
          "boundary.3.displacement.z=-0.06\n"
          "\n"
          "exit status: 0 success, 1 bad input, 2 numerical failure, 3 "
          "quasi-static run not converged\n");
}

static int report(pm_err e) {
  fprintf(stderr, "pointmech: error: %s\n", pm_error_message());
  if (getenv("POINTMECH_TRACE"))
    fprintf(stderr, "trace:\n%s", pm_error_traceback());
  switch (e) {
  case PM_ERR_UNSTABLE:
  case PM_ERR_LINALG: return EXIT_NUMERIC;
  case PM_ERR_NOT_CONVERGED: return EXIT_NOT_CONVERGED;
  default: return EXIT_INPUT;
  }
}

typedef struct {
  const char *scene;
  const char *out;
  const char *points;
  const char *reference;
  int n_ladders;
  const char *ladders[PM_STUDY_MAX_KEYS];
  long frame;
  bool quiet;
  int n_sets;
  const char *sets[MAX_SETS];
} cli_args;

static int parse_args(int argc, char **argv, int first, cli_args *a) {
  memset(a, 0, sizeof *a);
  a->frame = -1;
  for (int k = first; k < argc; k++) {
    const char *arg = argv[k];
    bool has_next = k + 1 < argc;
    if (strcmp(arg, "--out") == 0 && has_next)
      a->out = argv[++k];
    else if (strcmp(arg, "--points") == 0 && has_next)
      a->points = argv[++k];
    else if (strcmp(arg, "--reference") == 0 && has_next)
      a->reference = argv[++k];
    else if (strcmp(arg, "--set-ladder") == 0 && has_next) {
      if (a->n_ladders == PM_STUDY_MAX_KEYS) {
        fprintf(stderr, "pointmech: at most %d --set-ladder options\n",
                PM_STUDY_MAX_KEYS);
        return -1;
      }
      a->ladders[a->n_ladders++] = argv[++k];
    } else if (strcmp(arg, "--frame") == 0 && has_next) {
      char *end;
      a->frame = strtol(argv[++k], &end, 10);
      if (*end || a->frame < 0) {
        fprintf(stderr, "pointmech: --frame expects an integer >= 0, got %s\n",
                argv[k]);
        return -1;
      }
    } else if (strcmp(arg, "--set") == 0 && has_next) {
      if (a->n_sets == MAX_SETS) {
        fprintf(stderr, "pointmech: at most %d --set options\n", MAX_SETS);
        return -1;
      }
      a->sets[a->n_sets++] = argv[++k];
    } else if (strncmp(arg, "--set=", 6) == 0 && a->n_sets < MAX_SETS)
      a->sets[a->n_sets++] = arg + 6;
    else if (strcmp(arg, "--quiet") == 0)
      a->quiet = true;
    else if (arg[0] == '-') {
      fprintf(stderr, "pointmech: unknown option %s%s\n", arg,
              has_next ? "" : " (or missing value)");
      return -1;
    } else if (!a->scene)
      a->scene = arg;
    else {
      fprintf(stderr, "pointmech: unexpected argument %s\n", arg);
      return -1;
    }
  }
  return 0;
}

static const char *out_dir(const cli_args *a, const pm_scene *s, char *buf,
                           size_t size) {
  if (a->out) return a->out;
  snprintf(buf, size, "out/%s", s->name);
  return buf;
}

static int cmd_run_or_plan_mpm(const cli_args *a, pm_scene *s, bool plan) {
  mpm_run *r = NULL;
  int status = EXIT_OK;
  pm_err e = mpm_run_create(s, &r);
  if (e) {
    status = report(e);
  } else if (plan) {
    e = mpm_run_plan(r, stdout);
    if (e) status = report(e);
  } else {
    char buf[1024];
    const char *out = out_dir(a, s, buf, sizeof buf);
    e = mpm_run_go(r, out, a->quiet);
    if (e) status = report(e);
    fprintf(stderr, "results in %s\n", out);
  }
  mpm_run_destroy(r);
  pm_scene_destroy(s);
  return status;
}

static int cmd_run_or_plan(const cli_args *a, bool plan) {
  pm_scene *s = NULL;
  fpm_sim *sim = NULL;
  int status = EXIT_OK;
  pm_err e = pm_scene_load(a->scene, a->n_sets, a->sets, &s);
  if (e) return report(e);
  if (s->method == PM_METHOD_MPM) return cmd_run_or_plan_mpm(a, s, plan);
  if (s->method != PM_METHOD_FPM) {
    fprintf(stderr,
            "pointmech: error: %s: method %s is not available in this build "
            "(available: fpm, mpm)\n",
            a->scene, pm_method_name(s->method));
    pm_scene_destroy(s);
    return EXIT_INPUT;
  }
  e = fpm_sim_create(s, &sim);
  if (e) {
    status = report(e);
    goto done;
  }
  if (plan) {
    e = fpm_sim_plan(sim, stdout);
    if (e) status = report(e);
    goto done;
  }
  char out_default[1024];
  const char *out = out_dir(a, s, out_default, sizeof out_default);
  e = fpm_sim_run(sim, out, a->quiet);
  if (e) status = report(e);
  fprintf(stderr, "results in %s\n", out);
done:
  fpm_sim_destroy(sim);
  pm_scene_destroy(s);
  return status;
}

/* The boundary condition with the largest prescribed displacement at the
 * end (evaluated at its face's centre) and that component: the loaded face. */
static void loaded_face(const pm_scene *s, int *bc, int *comp) {
  double best = -1;
  *bc = -1;
  *comp = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *B = &s->bcs[b];
    double c[3];
    for (int a = 0; a < 3; a++) c[a] = 0.5 * (s->box_min[a] + s->box_max[a]);
    c[pm_face_axis(B->face)] = pm_face_plane(B->face, s->box_min, s->box_max);
    for (int k = 0; k < 3; k++) {
      if (!(B->disp_mask & (1u << k))) continue;
      double v = fabs(pm_expr_eval(B->disp[k], c[0], c[1], c[2], s->time.end));
      if (v > best) {
        best = v;
        *bc = b;
        *comp = k;
      }
    }
  }
}

static pm_err run_mpm_level(const pm_scene *s, const char *out, bool quiet,
                            pm_run_figures *fig) {
  mpm_run *r = NULL;
  pm_err e = mpm_run_create(s, &r);
  if (e) return e;
  e = mpm_run_go(r, out, quiet);
  fig->status = mpm_status_name(r->status);
  fig->dim = r->model->dim;
  fig->points = r->model->n;
  fig->steps = r->state->step;
  fig->h = r->model->grid.h;
  fig->wall = r->wall;
  fig->setup = r->setup_wall;
  fig->nrmse = r->nrmse_vector;
  mpm_field_figures ff;
  mpm_run_field_figures(r, &ff);
  fig->mean_sed = ff.mean_strain_energy_density;
  fig->max_von_mises = ff.max_von_mises;
  fig->min_jacobian = ff.min_jacobian; /* at the end of the run */
  fig->energy_error = r->energy_error;
  int bc, comp;
  loaded_face(s, &bc, &comp);
  double R[3] = {NAN, NAN, NAN};
  if (bc >= 0) mpm_reaction(r, bc, R);
  fig->reaction = R[comp];
  mpm_run_destroy(r);
  return e;
}

static pm_err run_level(void *ctx, const pm_scene *s, const char *out,
                        bool quiet, pm_run_figures *fig) {
  (void)ctx;
  *fig = (pm_run_figures){.status = "failed", .nrmse = NAN};
  if (s->method == PM_METHOD_MPM) return run_mpm_level(s, out, quiet, fig);
  fpm_sim *sim = NULL;
  pm_err e = fpm_sim_create(s, &sim);
  if (e) return e;
  e = fpm_sim_run(sim, out, quiet);
  fpm_field_figures ff;
  fpm_sim_field_figures(sim, &ff);
  const fpm_model *m = sim->model;
  fig->status = fpm_status_name(sim->status);
  fig->dim = m->dim;
  fig->points = m->n;
  fig->steps = sim->last.step;
  fig->h = sim->mean_edge;
  fig->wall = sim->wall;
  fig->setup = sim->setup_wall;
  fig->nrmse = sim->nrmse_vector;
  fig->mean_sed = ff.mean_strain_energy_density;
  fig->max_von_mises = ff.max_von_mises;
  fig->min_jacobian = sim->run_min_jacobian;
  fig->energy_error = fpm_energy_error(&sim->last);
  int bc, comp;
  loaded_face(s, &bc, &comp);
  fig->reaction = NAN;
  if (bc >= 0) {
    double R[3];
    fpm_reaction(m, sim->state, bc, R);
    fig->reaction = R[comp];
  }
  fpm_sim_destroy(sim);
  return e;
}

static int cmd_convergence(const cli_args *a) {
  pm_study_options o = {
      .scene = a->scene,
      .n_sets = a->n_sets,
      .sets = a->sets,
      .n_keys = a->n_ladders,
      .reference = a->reference,
      .out_dir = a->out,
      .quiet = a->quiet,
  };
  for (int k = 0; k < a->n_ladders; k++) o.ladder[k] = a->ladders[k];
  pm_err e = pm_study_run(&o, run_level, NULL, stdout);
  return e ? report(e) : EXIT_OK;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    usage(stderr);
    return EXIT_INPUT;
  }
  const char *cmd = argv[1];
  if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 ||
      strcmp(cmd, "help") == 0) {
    usage(stdout);
    return EXIT_OK;
  }
  if (strcmp(cmd, "--version") == 0) {
    printf("pointmech %s\n", PM_VERSION);
    return EXIT_OK;
  }
  cli_args a;
  if (parse_args(argc, argv, 2, &a) != 0) {
    usage(stderr);
    return EXIT_INPUT;
  }
  if (strcmp(cmd, "run") == 0 || strcmp(cmd, "plan") == 0) {
    if (!a.scene) {
      fprintf(stderr, "pointmech: %s needs a SCENE file\n", cmd);
      return EXIT_INPUT;
    }
    return cmd_run_or_plan(&a, strcmp(cmd, "plan") == 0);
  }
  if (strcmp(cmd, "convergence") == 0) {
    if (!a.scene) {
      fprintf(stderr, "pointmech: convergence needs a SCENE file\n");
      return EXIT_INPUT;
    }
    return cmd_convergence(&a);
  }
  if (strcmp(cmd, "probe") == 0) {
    if (!a.scene || !a.points) {
      fprintf(stderr, "pointmech: probe needs OUT and --points FILE.csv\n");
      return EXIT_INPUT;
    }
    pm_err e = pm_probe(a.scene, a.points, a.frame, stdout);
    return e ? report(e) : EXIT_OK;
  }
  fprintf(stderr, "pointmech: unknown command %s\n", cmd);
  usage(stderr);
  return EXIT_INPUT;
}
