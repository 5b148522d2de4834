/* f2-library: case F2 (a cube compressed by 40%) through pointmech.h.
 *
 *   f2-library SCENE [KEY=VALUE]...
 *
 * loads SCENE with the overrides, runs it without files, prints the
 * progress at each frame, then the top face's reaction and the
 * displacement read back (the largest lateral expansion, u_x, and the
 * range of u_z), each as %.17g for comparison with `pointmech run`. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <pointmech.h>

static int fail(const char *what, pointmech_code c) {
  fprintf(stderr, "f2-library: %s: %s: %s\n", what, pointmech_code_name(c),
          pointmech_error_message());
  return 1;
}

/* The caller's copy of a field, grown as needed. */
typedef struct {
  double *v;
  size_t size;
} buffer;

static int read_field(pointmech *p, const char *name, buffer *b) {
  int ncomp = 0;
  if (pointmech_field_components(p, name, &ncomp)) return 1;
  const size_t need = (size_t)pointmech_point_count(p) * (size_t)ncomp;
  if (need > b->size) {
    double *v = realloc(b->v, need * sizeof *v);
    if (!v) return 1;
    b->v = v, b->size = need;
  }
  return pointmech_field_read(p, name, b->v, b->size) != POINTMECH_OK;
}

/* At every frame: the step, time, residual and the largest displacement,
 * read from the state as it runs. */
static int progress(pointmech *p, const pointmech_step *st, void *ctx) {
  buffer *b = ctx;
  if (!st->frame) return 0;
  const long n = pointmech_point_count(p);
  if (read_field(p, "displacement", b)) return 1;
  const double *u = b->v;
  double umax = 0;
  for (long i = 0; i < 3 * n; i++) umax = fmax(umax, fabs(u[i]));
  printf("step %6ld  t = %.4f s  residual %.2e  max |u| = %.4e m  %3.0f%%\n",
         st->step, st->time, st->residual, umax, 100 * st->progress);
  return 0;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: f2-library SCENE [KEY=VALUE]...\n");
    return 2;
  }
  printf("pointmech %s\n", pointmech_version());
  pointmech *p = NULL;
  pointmech_code c = pointmech_create(&p);
  if (c) return fail("create", c);
  for (int k = 2; k < argc; k++)
    if ((c = pointmech_set(p, argv[k]))) return fail("set", c);
  if ((c = pointmech_load_file(p, argv[1]))) return fail("load", c);
  printf("%s (%s)\n", pointmech_scene_name(p), pointmech_method(p));

  buffer b = {NULL, 0};
  c = pointmech_run(p, NULL, 0, progress, &b);
  /* Not reaching a quasi-static tolerance still leaves a state to read. */
  if (c && c != POINTMECH_ERR_NOT_CONVERGED) return fail("run", c);
  printf("status %s\n", pointmech_status(p));

  const long n = pointmech_point_count(p);
  double *x = malloc(3 * (size_t)n * sizeof *x);
  if (!x) return fail("malloc", POINTMECH_ERR_MEMORY);
  if ((c = pointmech_points(p, x, 3 * (size_t)n))) return fail("points", c);
  if (read_field(p, "displacement", &b))
    return fail("displacement", POINTMECH_ERR_ARG);
  const double *u = b.v;
  double uxmax = -INFINITY, umin = INFINITY, umax = -INFINITY, top = 0;
  for (long i = 0; i < n; i++) {
    top = fmax(top, x[3 * i + 2]);
    uxmax = fmax(uxmax, u[3 * i]);
    umin = fmin(umin, u[3 * i + 2]);
    umax = fmax(umax, u[3 * i + 2]);
  }
  double f[3], steps = 0;
  if ((c = pointmech_reaction(p, "zmax", f))) return fail("reaction", c);
  if ((c = pointmech_figure(p, "steps", &steps))) return fail("figure", c);
  printf("points %ld, height %g m\n", n, top);
  printf("steps %.0f\n", steps);
  printf("reaction_zmax %.17g %.17g %.17g\n", f[0], f[1], f[2]);
  printf("u_x_max %.17g\n", uxmax);
  printf("u_z_min %.17g\n", umin);
  printf("u_z_max %.17g\n", umax);
  free(x);
  free(b.v);
  pointmech_destroy(p);
  return 0;
}
