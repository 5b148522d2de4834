/* test_isolate: reading in a child process (pm_isolate): a result passed
 * back, the reader's own error passed back, a child stopped by a signal or
 * by its CPU limit refused with the file and the library named, the
 * reading done in the process with PM_ISOLATE=0, a .geo meshed in a child
 * after OpenMP's threads ran; and every input of
 * tests/fuzz/upstream/, which stops the process inside libgmsh or libhdf5
 * when read there, refused by the real readers with the file's name; and
 * what a hostile child could pass back (pm_isolate_stream) refused by the
 * parent with the file's name. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <dirent.h>
#include <math.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz_file.h"
#include "gm_gmsh.h"
#include "gm_mesh.h"
#include "gm_trisurf.h"
#include "pm_checkpoint.h"
#include "pm_h5_vet.h"
#include "pm_isolate.h"
#include "pm_omp.h"
#include "pm_output.h"
#include "pm_probe.h"
#include "pm_run_impl.h"

#define UPSTREAM PM_SOURCE_DIR "/tests/fuzz/upstream/"

/* ---- The mechanism ----------------------------------------------------- */

typedef struct {
  int how; /* 0 result, 1 error, 2 SIGSEGV, 3 abort, 4 spin, 5 exit */
  long n;
  double *v;
  pid_t pid; /* the process the work ran in */
} job_arg;

static pm_err work(void *p) {
  job_arg *a = p;
  a->pid = getpid();
  switch (a->how) {
  case 1: return PM_ERROR(PM_ERR_ARG, "'f.msh': no element of dimension %d", 3);
  case 2: raise(SIGSEGV); break;
  case 3: abort();
  case 5: exit(0);
  case 4:
    for (volatile unsigned long k = 0;; k++) {
    }
  default: break;
  }
  PM_CALL(PM_ALLOC(a->v, a->n, "values"));
  for (long k = 0; k < a->n; k++) a->v[k] = 0.5 * (double)k;
  return PM_SUCCESS;
}

static pm_err put(void *p, int fd) {
  job_arg *a = p;
  PM_CALL(pm_isolate_put(fd, &a->pid, sizeof a->pid));
  return pm_isolate_put_array(fd, a->v, (size_t)a->n, sizeof *a->v);
}

static pm_err get(void *p, int fd) {
  job_arg *a = p;
  size_t n = 0;
  PM_CALL(pm_isolate_get(fd, &a->pid, sizeof a->pid));
  PM_CALL(pm_isolate_get_array(fd, (void **)&a->v, &n, sizeof *a->v));
  a->n = (long)n;
  return PM_SUCCESS;
}

static pm_err run(job_arg *a, double cpu) {
  const pm_isolate_job job = {.path = "f.msh",
                              .library = "gmsh",
                              .what = "a mesh gmsh reads",
                              .code = PM_ERR_MESH,
                              .cpu_seconds = cpu,
                              .work = work,
                              .put = put,
                              .get = get,
                              .arg = a};
  return pm_isolate_run(&job);
}

static void test_result_passed_back(void **state) {
  (void)state;
  job_arg a = {.how = 0, .n = 100000};
  assert_ok(run(&a, 0));
  assert_int_not_equal(a.pid, getpid()); /* read in a child */
  assert_int_equal(a.n, 100000);
  for (long k = 0; k < a.n; k++) assert_true(a.v[k] == 0.5 * (double)k);
  free(a.v);
}

static void test_error_passed_back(void **state) {
  (void)state;
  job_arg a = {.how = 1};
  assert_fails(run(&a, 0), PM_ERR_ARG, "'f.msh': no element of dimension 3");
  assert_null(a.v);
}

static void test_signal_refused(void **state) {
  (void)state;
  job_arg a = {.how = 2};
  /* AddressSanitizer reports a SIGSEGV itself and exits with status 1. */
  assert_fails(run(&a, 0), PM_ERR_MESH, "f.msh: gmsh stopped ");
  assert_non_null(strstr(pm_error_message(),
                         "while reading it: the file is damaged or not a "
                         "mesh gmsh reads"));
  a.how = 3;
  assert_fails(run(&a, 0), PM_ERR_MESH,
               "f.msh: gmsh stopped with SIGABRT while reading it");
  /* exit() in the library: none of this process's atexit handlers run in
   * the child (cmocka's, HDF5's). */
  a.how = 5;
  assert_fails(run(&a, 0), PM_ERR_MESH,
               "f.msh: gmsh ended its process (exit) while reading it");
  pm_error_clear();
}

static void test_cpu_limit(void **state) {
  (void)state;
  job_arg a = {.how = 4};
  assert_fails(run(&a, 1), PM_ERR_MESH,
               "f.msh: gmsh used more than 1 CPU seconds reading it "
               "(SIGXCPU)");
  pm_error_clear();
}

static void test_not_isolated(void **state) {
  (void)state;
  job_arg a = {.how = 0, .n = 3};
  setenv("PM_ISOLATE", "0", 1);
  assert_false(pm_isolate_enabled());
  assert_ok(run(&a, 0));
  unsetenv("PM_ISOLATE");
  assert_int_equal(a.pid, getpid());
  assert_true(a.v[2] == 1.0);
  free(a.v);
}

/* A .geo meshed in a child after OpenMP's threads ran in the parent: the
 * child runs on one thread (libgomp's pool is not in it), and leaves the
 * parent's thread count as it was. */
static void test_after_threads(void **state) {
  (void)state;
  int team = 0;
  PM_OMP(parallel num_threads(2))
  PM_OMP(single)
  team = pm_omp_team();
  const int threads = pm_omp_threads();
  gm_gmsh_mesh m;
  assert_ok(gm_gmsh_load(PM_TEST_DATA "/geometry/sphere.geo", 3, 0.25,
                         GM_SIZES_REPLACE, false, &m));
  assert_true(m.meshed && m.n_nodes > 20 && m.n_elems > 20);
  assert_int_equal(pm_omp_threads(), threads);
  gm_gmsh_mesh_free(&m);
  assert_true(team >= 1);
}

/* ---- The inputs that stop the libraries -------------------------------- */

/* The files of upstream/sub (README aside) into names; their count. */
static int list(const char *sub, char names[8][1024]) {
  char dir[512];
  snprintf(dir, sizeof dir, "%s%s", UPSTREAM, sub);
  DIR *d = opendir(dir);
  assert_non_null(d);
  int n = 0;
  for (struct dirent *e; (e = readdir(d)) && n < 8;)
    if (e->d_name[0] != '.')
      snprintf(names[n++], 1024, "%s/%s", dir, e->d_name);
  closedir(d);
  assert_true(n > 0);
  return n;
}

/* The last failure names the file (or the folder) and, for the refusals
 * of a child, the library. */
static void assert_names(pm_err e, const char *path) {
  if (e == PM_SUCCESS || !strstr(pm_error_message(), path))
    fail_msg("expected a refusal naming %s, got %s: %s", path, pm_err_name(e),
             pm_error_message());
  print_message("refused: %s\n", pm_error_message());
  pm_error_clear();
}

/* `pointmech vet`: a file HDF5 reads without fault passes (its damage is
 * then the reader's to refuse: some of these fault only under
 * AddressSanitizer); one that stops HDF5 is refused naming path. */
static void assert_vetted(pm_err e, const char *path) {
  if (e) assert_names(e, path);
}

static void test_upstream_gmsh(void **state) {
  (void)state;
  char names[8][1024];
  for (int k = 0, n = list("gmsh", names); k < n; k++) {
    gm_mesh *m = NULL;
    assert_names(gm_mesh_file(names[k], 3, 0.1, GM_SIZES_REPLACE, &m),
                 names[k]);
    assert_null(m);
    gm_trisurf s;
    assert_names(gm_trisurf_load(names[k], &s), names[k]);
    assert_null(s.x);
    double lo[3], hi[3];
    assert_names(gm_file_bounds(names[k], 3, lo, hi), names[k]);
  }
}

/* The bytes of path, in a new buffer. */
static uint8_t *slurp(const char *path, size_t *size) {
  char *s = NULL;
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  *size = (size_t)ftell(f);
  rewind(f);
  s = malloc(*size + 1);
  assert_int_equal(fread(s, 1, *size, f), *size);
  fclose(f);
  return (uint8_t *)s;
}

/* As `resume` reads a checkpoint: vetted, opened, its run's items. */
static pm_err read_checkpoint(const char *dir) {
  pm_ckpt *ck = NULL;
  pm_run_header h = {0};
  PM_CALL(pm_ckpt_vet(dir));
  PM_CALL(pm_ckpt_open(dir, &ck));
  pm_err e = pm_run_header_items(ck, &h);
  e = e ? e : pm_ckpt_finish(ck);
  if (e) pm_ckpt_abort(ck);
  pm_run_header_free(&h);
  return e;
}

static void test_upstream_checkpoint(void **state) {
  (void)state;
  char names[8][1024];
  /* A damaged global heap may loop HDF5: the limit, kept short here. */
  setenv("PM_ISOLATE_CPU_SECONDS", "1", 1);
  for (int k = 0, n = list("checkpoint", names); k < n; k++) {
    size_t size = 0;
    uint8_t *data = slurp(names[k], &size);
    const char *path = fuzz_file("checkpoint.h5", data, size);
    assert_names(read_checkpoint(fuzz_dir()), path);
    /* `pointmech vet DIR`, as the Python module asks it. */
    assert_vetted(pm_h5_vet_path(fuzz_dir()), path);
    free(data);
    fuzz_clear();
  }
  unsetenv("PM_ISOLATE_CPU_SECONDS");
}

static void test_upstream_index(void **state) {
  (void)state;
  char names[8][1024];
  setenv("PM_ISOLATE_CPU_SECONDS", "1", 1);
  for (int k = 0, n = list("index", names); k < n; k++) {
    size_t size = 0;
    long n_points = 0, n_frames = 0;
    uint8_t *data = slurp(names[k], &size);
    assert_true(fuzz_results_folder(data, size, &n_points, &n_frames));
    long np = 0;
    double *x = NULL, *u = NULL;
    assert_names(pm_results_read(fuzz_dir(), -1, &np, &x, &u), fuzz_dir());
    assert_null(x);
    FILE *out = fopen("/dev/null", "w");
    assert_names(pm_probe_points(fuzz_dir(), NULL, -1, out), fuzz_dir());
    fclose(out);
    assert_vetted(pm_h5_vet_path(fuzz_dir()), fuzz_dir());
    pm_results *r = NULL;
    assert_names(pm_results_reopen(fuzz_dir(), n_points,
                                   n_frames > 0 ? n_frames : 0, &r),
                 fuzz_dir());
    assert_null(r);
    free(data);
    fuzz_clear();
  }
  unsetenv("PM_ISOLATE_CPU_SECONDS");
}

/* ---- A hostile child's stream ------------------------------------------ */

typedef struct {
  uint8_t b[1024];
  size_t n;
} stream;

static void add(stream *s, const void *p, size_t n) {
  assert_true(s->n + n <= sizeof s->b);
  memcpy(s->b + s->n, p, n);
  s->n += n;
}

static void add_u32(stream *s, uint32_t v) { add(s, &v, sizeof v); }

static void add_array(stream *s, const void *p, uint64_t count, size_t size) {
  add(s, &count, sizeof count);
  add(s, p, (size_t)count * size);
}

/* A tetrahedron as gm_gmsh_isolate.c passes a mesh back; corner 3 of the
 * element is `last`, and the end mark is written when `end`. */
static void tetrahedron(stream *s, long last, bool end) {
  const struct {
    int dim, n_groups;
    long n_nodes, n_elems;
    int meshed;
    double size_factor;
  } head = {3, 0, 4, 1, 0, 1.0};
  const double x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const long elem[4] = {0, 1, 2, last};
  s->n = 0;
  add_u32(s, 0x706d6931u); /* the mark, success, no message */
  add_u32(s, 0);
  add_u32(s, 0);
  add(s, &head, sizeof head);
  add_array(s, x, 12, sizeof *x);
  add_array(s, elem, 4, sizeof *elem);
  if (end) add_u32(s, 0x706d6945u);
}

/* gm_mesh_file of "mesh.msh" reading s as its child's stream. */
static pm_err mesh_from(const stream *s, gm_mesh **m) {
  const char *at = fuzz_file("stream", s->b, s->n);
  const int fd = open(at, O_RDONLY);
  assert_true(fd >= 0);
  const char *path = fuzz_file("mesh.msh", (const uint8_t *)"", 0);
  pm_isolate_stream(fd);
  pm_err e = gm_mesh_file(path, 3, 0.1, GM_SIZES_REPLACE, m);
  pm_isolate_stream(-1);
  close(fd);
  return e;
}

static void test_hostile_stream(void **state) {
  (void)state;
  stream s;
  gm_mesh *m = NULL;
  const char *path = fuzz_path("mesh.msh");
  tetrahedron(&s, 3, true);
  assert_ok(mesh_from(&s, &m));
  assert_int_equal(m->n_nodes, 4);
  assert_int_equal(m->n_cells, 1);
  gm_mesh_destroy(m);
  m = NULL;
  /* A corner that is no node: the process would index past the nodes. */
  tetrahedron(&s, 7, true);
  assert_fails(mesh_from(&s, &m), PM_ERR_MESH, path);
  assert_non_null(strstr(pm_error_message(),
                         "passed a malformed result (an element's corner "
                         "passed back is no node)"));
  /* Cut short, and torn: no end mark, or another in its place. */
  tetrahedron(&s, 3, false);
  s.n -= 5;
  assert_fails(mesh_from(&s, &m), PM_ERR_MESH, path);
  tetrahedron(&s, 3, false);
  add_u32(&s, 0x12345678u);
  assert_fails(mesh_from(&s, &m), PM_ERR_MESH, path);
  assert_non_null(strstr(pm_error_message(), "passed a torn result"));
  /* An array of 2^40 coordinates announced, none sent: refused without
   * allocating them. */
  tetrahedron(&s, 3, true);
  const uint64_t huge = (uint64_t)1 << 40;
  memcpy(s.b + 12 + 40, &huge, sizeof huge);
  assert_fails(mesh_from(&s, &m), PM_ERR_MESH, path);
  /* A coordinate that is not a number. */
  tetrahedron(&s, 3, true);
  const double not_a_number = NAN;
  memcpy(s.b + 12 + 40 + 8, &not_a_number, sizeof not_a_number);
  assert_fails(mesh_from(&s, &m), PM_ERR_MESH, path);
  assert_non_null(strstr(pm_error_message(), "expected finite coordinates"));
  assert_null(m);
  fuzz_clear();
  pm_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_result_passed_back),
      cmocka_unit_test(test_error_passed_back),
      cmocka_unit_test(test_signal_refused),
      cmocka_unit_test(test_cpu_limit),
      cmocka_unit_test(test_not_isolated),
      cmocka_unit_test(test_after_threads),
      cmocka_unit_test(test_upstream_gmsh),
      cmocka_unit_test(test_upstream_checkpoint),
      cmocka_unit_test(test_upstream_index),
      cmocka_unit_test(test_hostile_stream),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
