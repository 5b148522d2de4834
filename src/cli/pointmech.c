/* pointmech: the command-line program.  It knows the methods only through
 * the backend table (pm_app registers them): it loads the scene, whose
 * method names its backend, and runs it through the one run driver. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gm_gmsh.h"
#include "mpm_isonormal.h"
#include "pm_app.h"
#include "pm_compare.h"
#include "pm_error.h"
#include "pm_h5_vet.h"
#include "pm_memory.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_probe.h"
#include "pm_bench.h"
#include "pm_run.h"
#include "pm_scene.h"
#include "pm_spawn.h"
#include "pm_study.h"
#include "pm_wait_policy.h"

enum {
  EXIT_OK = 0,
  EXIT_INPUT = 1,
  EXIT_NUMERIC = 2,
  EXIT_NOT_CONVERGED = 3,
  EXIT_INTERRUPTED = 4
};

#define MAX_SETS 64

static void usage(FILE *out) {
  fprintf(
      out,
      "usage: pointmech run SCENE [--out DIR] [--set KEY=VALUE]... "
      "[--overwrite] [--quiet]\n"
      "                 [--force-memory]\n"
      "       pointmech resume OUT [--quiet]\n"
      "       pointmech plan SCENE [--set KEY=VALUE]... [--force-memory] "
      "[--ranks N]\n"
      "       pointmech probe OUT [--at lattice|points] [--points FILE.csv] "
      "[--frame N]\n"
      "       pointmech convergence SCENE --set-ladder KEY=V1,V2,... "
      "[--set-ladder ...]\n"
      "                 [--reference analytic|last|fe:DIR|DIR] [--out DIR] "
      "[--set KEY=VALUE]... [--overwrite]\n"
      "                 [--force-memory]\n"
      "       pointmech compare SCENE --methods M1,M2,... "
      "[--reference analytic|fe:DIR|DIR]\n"
      "                 [--set [METHOD:]KEY=VALUE]... [--lattice N] "
      "[--out DIR] [--overwrite]\n"
      "                 [--force-memory]\n"
      "       pointmech bench SUITE [--only NAME,...] [--set KEY=VALUE]... "
      "[--out DIR]\n"
      "                 [--overwrite] [--quiet]\n"
      "       pointmech vet PATH...\n"
      "       pointmech keys\n"
      "       pointmech normals\n"
      "       pointmech --help | --version\n"
      "\n"
      "  run    simulate SCENE (YAML); writes OUT/results.h5 + "
      "results.xdmf,\n"
      "         history.csv and summary.json (default OUT: out/NAME); "
      "every frame\n"
      "         is on disk as it is written (open results.xdmf in "
      "ParaView while\n"
      "         the run goes on); an OUT holding another run's files is "
      "refused\n"
      "         unless --overwrite\n"
      "  resume continue the run in OUT from its last checkpoint "
      "(output.checkpoint,\n"
      "         or the one SIGINT/SIGTERM writes), appending to its "
      "results; on the\n"
      "         same thread count it ends bit-identical to an "
      "uninterrupted run\n"
      "  plan   print the pipeline, counts, time step, steps, memory and "
      "an\n"
      "         estimated run time without running; with --ranks N "
      "(mpm, fpm),\n"
      "         also how N MPI ranks would share the run: boxes, "
      "particles, ghost\n"
      "         nodes or points and ghosts, bytes sent per step (under "
      "mpirun, plan\n"
      "         prints the run's own)\n"
      "  probe  print the displacement of a run's last (or N-th) frame "
      "at the\n"
      "         reference coordinates of FILE.csv (x,y,z per line), by "
      "moving\n"
      "         least squares, as CSV (--at lattice, the default); --at "
      "points:\n"
      "         every field at the points themselves (every point, or the "
      "one at\n"
      "         each coordinate of FILE.csv), no fit\n"
      "  vet    read each HDF5 file of PATH (a run folder: its results "
      "and\n"
      "         checkpoint; or one file) whole by HDF5 in a child "
      "process, and\n"
      "         refuse a file that stops or loops HDF5, with the reason: "
      "what a\n"
      "         reader outside the program (the Python module) asks "
      "before it\n"
      "         opens them\n"
      "  convergence  run SCENE once per ladder value (several ladders "
      "go in\n"
      "         step) and tabulate h, points, steps, NRMSE against the "
      "analytic\n"
      "         field, a reference run (default: the last value) or a "
      "finite-element\n"
      "         reference (fe:DIR, a cases/fe folder, the default when the "
      "scene\n"
      "         names one in reference.fe; adds the reaction and mean "
      "strain energy\n"
      "         errors), the rate q and wall time in "
      "OUT/convergence.{md,csv}\n"
      "         (default OUT: out/NAME-convergence); plot with\n"
      "         tools/plot-convergence.py\n"
      "  compare  run SCENE once per method into OUT/M, one after "
      "the other (method=M,\n"
      "         then every --set; --set M:KEY=VALUE for method M alone); "
      "map the\n"
      "         displacements onto one lattice (the FE referee's, else N "
      "points\n"
      "         along the bodies' shortest side, default 9) by moving "
      "least squares;\n"
      "         tabulate the NRMSE of every pair and against the "
      "analytic field, the\n"
      "         FE referee or a run's folder DIR, reactions, mean strain "
      "energy\n"
      "         density, von Mises stress at the centre, smallest J, "
      "wall time and\n"
      "         memory in OUT/compare.{md,csv} (default OUT: "
      "out/NAME-compare);\n"
      "         the mid-plane in OUT/midplane.csv, drawn by "
      "tools/plot-compare.py; a\n"
      "         method that fails is tabulated with its diagnosis and "
      "the others run\n"
      "  bench  run a benchmark suite (cases/bench/*.yaml: scenes, "
      "methods as\n"
      "         {label, method, set}, resolutions): each case at each "
      "resolution is\n"
      "         one compare into OUT/CASE/h-RES; OUT/bench.{md,csv} "
      "tabulate every\n"
      "         run's NRMSE and reaction error against the FE referee "
      "(or the\n"
      "         analytic field) beside its wall time and memory, and a "
      "case's key\n"
      "         fe: {ladder: [N, ...], threads} runs CalculiX on those "
      "meshes, timed,\n"
      "         in rows fe beside the methods' (else the referee's "
      "recorded ladder);\n"
      "         OUT/accuracy-cost.png by tools/plot-bench.py "
      "(default OUT:\n"
      "         out/NAME-bench); a failed case is listed with its "
      "diagnosis and the\n"
      "         suite goes on; --only runs the cases whose name holds "
      "one of NAME,...\n"
      "  keys   print every scene key: meaning, type, range, unit, "
      "default\n"
      "  normals print the membrane-normals paper's static cases (M6: "
      "Tables I-III,\n"
      "         figs. 4-11) beside ours, with the time per fit\n"
      "  --set  override any scene value by its dotted key, e.g.\n"
      "         --set discretization.mesh_size=8.02e-3 --set "
      "boundary.3.displacement.z=-0.06\n"
      "  --force-memory  run, plan or study a scene whose memory estimate "
      "exceeds\n"
      "         the memory available (MemAvailable, the cgroup limit or\n"
      "         POINTMECH_MEMORY_LIMIT), which is otherwise refused before "
      "setup\n"
      "\n"
      "exit status: 0 success, 1 bad input, 2 numerical failure, 3 "
      "quasi-static run not converged, 4 interrupted (SIGINT or "
      "SIGTERM; results up to the last step kept, and a checkpoint to "
      "resume from)\n");
}

static int report(pm_err e) {
  /* Across ranks every rank has the same error: rank 0 says it. */
  if (pm_par_root())
    fprintf(stderr, "pointmech: error: %s\n", pm_error_message());
  if (getenv("POINTMECH_TRACE"))
    fprintf(stderr, "trace:\n%s", pm_error_traceback());
  switch (e) {
  case PM_ERR_UNSTABLE:
  case PM_ERR_LINALG: return EXIT_NUMERIC;
  case PM_ERR_NOT_CONVERGED: return EXIT_NOT_CONVERGED;
  case PM_ERR_INTERRUPTED: return EXIT_INTERRUPTED;
  default: return EXIT_INPUT;
  }
}

typedef struct {
  const char *scene;
  const char *out;
  const char *points;
  const char *at; /* probe: lattice or points */
  const char *reference;
  const char *methods;
  const char *only;
  long lattice;
  int n_ladders;
  const char *ladders[PM_STUDY_MAX_KEYS];
  long frame;
  bool quiet;
  bool overwrite;
  int n_sets;
  const char *sets[MAX_SETS];
} cli_args;

static int parse_args(int argc, char **argv, int first, cli_args *a) {
  memset(a, 0, sizeof *a);
  a->frame = -1;
  for (int k = first; k < argc; k++) {
    const char *arg = argv[k];
    bool has_next = k + 1 < argc;
    if ((strcmp(arg, "--out") == 0 || strcmp(arg, "-o") == 0) && has_next)
      a->out = argv[++k];
    else if (strcmp(arg, "--points") == 0 && has_next)
      a->points = argv[++k];
    else if (strcmp(arg, "--at") == 0 && has_next) {
      a->at = argv[++k];
      if (strcmp(a->at, "lattice") != 0 && strcmp(a->at, "points") != 0) {
        fprintf(stderr, "pointmech: --at expects lattice or points, got %s\n",
                a->at);
        return -1;
      }
    } else if (strcmp(arg, "--reference") == 0 && has_next)
      a->reference = argv[++k];
    else if (strcmp(arg, "--methods") == 0 && has_next)
      a->methods = argv[++k];
    else if (strcmp(arg, "--only") == 0 && has_next)
      a->only = argv[++k];
    else if (strcmp(arg, "--lattice") == 0 && has_next) {
      char *end;
      a->lattice = strtol(argv[++k], &end, 10);
      if (*end || a->lattice < 3) {
        fprintf(stderr,
                "pointmech: --lattice expects an integer >= 3, got %s\n",
                argv[k]);
        return -1;
      }
    } else if (strcmp(arg, "--set-ladder") == 0 && has_next) {
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
    else if (strcmp(arg, "--overwrite") == 0)
      a->overwrite = true;
    else if (strcmp(arg, "--force-memory") == 0)
      pm_memory_set_force(true);
    else if (strcmp(arg, "--ranks") == 0 && has_next) {
      char *end;
      long n = strtol(argv[++k], &end, 10);
      if (*end || n < 2 || n > 100000) {
        fprintf(stderr,
                "pointmech: --ranks expects an integer from 2 to 100000, "
                "got %s\n",
                argv[k]);
        return -1;
      }
      pm_par_set_plan_ranks((int)n);
    } else if (arg[0] == '-') {
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

static unsigned run_flags(const cli_args *a) {
  return (a->quiet ? PM_RUN_QUIET : 0u) |
         (a->overwrite ? PM_RUN_OVERWRITE : 0u);
}

static int cmd_run_or_plan(const cli_args *a, bool plan) {
  pm_scene *s = NULL;
  int status = EXIT_OK;
  pm_err e = pm_scene_load(a->scene, a->n_sets, a->sets, &s);
  if (e) return report(e);
  if (plan) {
    e = pm_plan_scene(s, stdout);
    if (e) status = report(e);
  } else {
    char buf[1024];
    const char *out = out_dir(a, s, buf, sizeof buf);
    pm_outcome o;
    e = pm_run_scene(s, out, run_flags(a), &o);
    if (e) status = report(e);
    if (pm_par_root() && access(out, F_OK) == 0)
      fprintf(stderr, "results in %s\n", out);
  }
  pm_scene_destroy(s);
  return status;
}

/* A command that runs many scenes in this process (convergence, compare,
 * bench) opens and starts gmsh here once: each run's meshing child then
 * takes that session instead of loading gmsh's some ninety libraries
 * again (0.15-0.3 s a mesh on this machine).  One process only; a
 * failure is left to the first meshing, which reports it. */
static void warm_gmsh(void) {
  if (!pm_par_active() && gm_gmsh_warm() != PM_SUCCESS) pm_error_clear();
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
      .overwrite = a->overwrite,
  };
  for (int k = 0; k < a->n_ladders; k++) o.ladder[k] = a->ladders[k];
  warm_gmsh();
  pm_err e = pm_study_run(&o, stdout);
  return e ? report(e) : EXIT_OK;
}

/* Draw the pictures of the comparison or bench in dir with the tool
 * (tools/plot-compare.py, tools/plot-bench.py), or say how. */
static void draw_pictures(const char *dir, const char *tool) {
  const char *python = "/usr/bin/python3";
  char *const args[] = {(char *)python, (char *)tool, (char *)dir, NULL};
  const char *why = "no /usr/bin/python3 or no plotting tool here";
  if (access(python, X_OK) == 0 && access(tool, R_OK) == 0) {
    const int st = pm_spawn_wait(args, NULL);
    if (st < 0)
      why = "the plotting tool did not run to its end";
    else if (st == 0)
      return;
    else
      why = st == 3 ? "no matplotlib for /usr/bin/python3"
                    : "the plotting tool failed";
  }
  fprintf(stderr,
          "pointmech: no pictures drawn (%s); draw them with: python3 %s "
          "%s\n",
          why, tool, dir);
}

static int cmd_compare(const cli_args *a) {
  pm_compare_options o = {
      .scene = a->scene,
      .methods = a->methods,
      .n_sets = a->n_sets,
      .sets = a->sets,
      .reference = a->reference,
      .lattice = a->lattice,
      .out_dir = a->out,
      .quiet = a->quiet,
      .overwrite = a->overwrite,
  };
  char dir[1024];
  warm_gmsh();
  pm_err e = pm_compare_run(&o, stdout, dir, sizeof dir);
  fflush(stdout);
  char mid[1100];
  snprintf(mid, sizeof mid, "%s/midplane.csv", dir);
  if (dir[0] && access(mid, R_OK) == 0)
    draw_pictures(dir, PM_TOOLS_DIR "/plot-compare.py");
  return e ? report(e) : EXIT_OK;
}

static int cmd_bench(const cli_args *a) {
  pm_bench_options o = {
      .suite = a->scene,
      .only = a->only,
      .n_sets = a->n_sets,
      .sets = a->sets,
      .out_dir = a->out,
      .quiet = a->quiet,
      .overwrite = a->overwrite,
      .fe_tool = PM_TOOLS_DIR "/fe-referee.py",
  };
  char dir[1024];
  warm_gmsh();
  pm_err e = pm_bench_run(&o, stdout, dir, sizeof dir);
  fflush(stdout);
  char csv[1100];
  snprintf(csv, sizeof csv, "%s/bench.csv", dir);
  if (dir[0] && access(csv, R_OK) == 0)
    draw_pictures(dir, PM_TOOLS_DIR "/plot-bench.py");
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
  if (strcmp(cmd, "run") == 0 || strcmp(cmd, "plan") == 0 ||
      strcmp(cmd, "convergence") == 0 || strcmp(cmd, "compare") == 0 ||
      strcmp(cmd, "bench") == 0)
    pm_wait_policy_apply(argv);
  if (strcmp(cmd, "vet") == 0) {
    /* HDF5 files read by HDF5 in a child, for readers outside the
     * program (the Python module): exit 0 when every one was read. */
    for (int k = 2; k < argc; k++) {
      pm_err e = pm_h5_vet_path(argv[k]);
      if (e) return report(e);
    }
    if (argc > 2) return EXIT_OK;
    fprintf(stderr, "pointmech: vet needs a run folder or HDF5 file\n");
    return EXIT_INPUT;
  }
  pm_err init = pm_app_init();
  if (!init) init = pm_par_init(&argc, &argv);
  if (!init) init = pm_par_attach(MPI_COMM_WORLD); /* the program's ranks */
  if (init) return report(init);
  /* Across ranks, rank 0 prints; the others' output would repeat it. */
  if (!pm_par_root() && !freopen("/dev/null", "w", stdout))
    pm_par_abort(EXIT_INPUT, "cannot silence the output of this rank");
  if (pm_par_active() && strcmp(cmd, "run") != 0 && strcmp(cmd, "plan") != 0 &&
      strcmp(cmd, "resume") != 0) {
    if (pm_par_root())
      fprintf(stderr,
              "pointmech: %s runs on one process (this run has %d ranks): "
              "start it without mpirun; run, plan and resume go across "
              "ranks\n",
              cmd, pm_par_size());
    return EXIT_INPUT;
  }
  cli_args a;
  if (parse_args(argc, argv, 2, &a) != 0) {
    usage(stderr);
    return EXIT_INPUT;
  }
  if (pm_par_plan_ranks() > 1 &&
      (strcmp(cmd, "plan") != 0 || pm_par_active())) {
    if (pm_par_root())
      fprintf(stderr, "pointmech: --ranks is for plan on one process (under "
                      "mpirun, plan prints the decomposition of its ranks)\n");
    return EXIT_INPUT;
  }
  if (strcmp(cmd, "run") == 0 || strcmp(cmd, "plan") == 0) {
    if (!a.scene) {
      fprintf(stderr, "pointmech: %s needs a SCENE file\n", cmd);
      return EXIT_INPUT;
    }
    return cmd_run_or_plan(&a, strcmp(cmd, "plan") == 0);
  }
  if (strcmp(cmd, "resume") == 0) {
    if (!a.scene) {
      fprintf(stderr, "pointmech: resume needs the OUT folder of a run\n");
      return EXIT_INPUT;
    }
    pm_outcome o;
    pm_err e = pm_resume(a.scene, run_flags(&a), &o);
    int status = e ? report(e) : EXIT_OK;
    if (pm_par_root() && access(a.scene, F_OK) == 0)
      fprintf(stderr, "results in %s\n", a.scene);
    return status;
  }
  if (strcmp(cmd, "keys") == 0) {
    pm_scene_print_keys(stdout);
    return EXIT_OK;
  }
  if (strcmp(cmd, "normals") == 0) {
    pm_err e = mpm_iso_tables(stdout, 1);
    return e ? report(e) : EXIT_OK;
  }
  if (strcmp(cmd, "convergence") == 0) {
    if (!a.scene) {
      fprintf(stderr, "pointmech: convergence needs a SCENE file\n");
      return EXIT_INPUT;
    }
    return cmd_convergence(&a);
  }
  if (strcmp(cmd, "compare") == 0) {
    if (!a.scene || !a.methods) {
      fprintf(stderr, "pointmech: compare needs a SCENE file and --methods "
                      "M1,M2,...\n");
      return EXIT_INPUT;
    }
    return cmd_compare(&a);
  }
  if (strcmp(cmd, "bench") == 0) {
    if (!a.scene) {
      fprintf(stderr, "pointmech: bench needs a SUITE file\n");
      return EXIT_INPUT;
    }
    return cmd_bench(&a);
  }
  if (strcmp(cmd, "probe") == 0) {
    const bool at_points = a.at && strcmp(a.at, "points") == 0;
    if (!a.scene || (!a.points && !at_points)) {
      fprintf(stderr, "pointmech: probe needs OUT and --points FILE.csv "
                      "(or --at points)\n");
      return EXIT_INPUT;
    }
    pm_err e = at_points ? pm_probe_points(a.scene, a.points, a.frame, stdout)
                         : pm_probe(a.scene, a.points, a.frame, stdout);
    return e ? report(e) : EXIT_OK;
  }
  fprintf(stderr, "pointmech: unknown command %s\n", cmd);
  usage(stderr);
  return EXIT_INPUT;
}
