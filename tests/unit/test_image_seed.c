/* test_image_seed: labelled images as bodies (bodies.N.image): a 3-slice
 * TIFF, a folder of its slices, raw volumes of 8 and 16 bits and a point
 * file give the same particles; n^d particles per voxel keep the volume;
 * label ranges partition the voxels; the image shape's contains and
 * bounds; the memory estimate's count; bad images refused at their key
 * with nothing written; the vessel slice of case I2. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gm_image.h"
#include "gm_shape.h"
#include "mpm_estimate.h"
#include "mpm_testing.h"

/* The test volume: 6 x 5 x 3 voxels of 0, 100 or 200 (each value in every
 * slice), voxel D from corner O (m). */
enum { NX = 6, NY = 5, NZ = 3, NV = NX * NY * NZ };
static const double D[3] = {0.1, 0.08, 0.12}, O[3] = {0.05, 0.1, 0.2};
#define VOX "voxel: [0.1, 0.08, 0.12], origin: [0.05, 0.1, 0.2]"

static uint16_t value(long i, long j, long k) {
  return (uint16_t)(100 * ((i + 2 * j + k) % 3));
}

/* Voxels of value v in the crop [lo, hi). */
static long voxels_of(uint16_t v, const long lo[3], const long hi[3]) {
  long n = 0;
  for (long k = lo[2]; k < hi[2]; k++)
    for (long j = lo[1]; j < hi[1]; j++)
      for (long i = lo[0]; i < hi[0]; i++) n += value(i, j, k) == v;
  return n;
}

static const long ALL_LO[3] = {0, 0, 0}, ALL_HI[3] = {NX, NY, NZ};

/* The volume in every source under dir: v.tif (3 pages), slices/ (a page
 * a file, and a file that is not a TIFF), v.raw (8 bits), v16.raw (16
 * bits), v.pts (the centres of the voxels >= 128, in mm). */
static void write_sources(const char *dir) {
  uint16_t v[NV];
  for (long k = 0; k < NZ; k++)
    for (long j = 0; j < NY; j++)
      for (long i = 0; i < NX; i++) v[i + NX * (j + NY * k)] = value(i, j, k);
  gm_image im = {.n = {NX, NY, NZ}, .d = {D[0], D[1], D[2]}, .v = v};
  char path[512];
  snprintf(path, sizeof path, "%s/v.tif", dir);
  assert_ok(gm_image_write_tiff(&im, path));
  snprintf(path, sizeof path, "%s/slices", dir);
  assert_int_equal(mkdir(path, 0755), 0);
  for (long k = 0; k < NZ; k++) {
    gm_image slice = im;
    slice.n[2] = 1;
    slice.v = v + NX * NY * k;
    snprintf(path, sizeof path, "%s/slices/s%ld.tif", dir, k);
    assert_ok(gm_image_write_tiff(&slice, path));
  }
  pm_test_write_file(dir, "slices/notes.txt", "not an image\n", path);
  snprintf(path, sizeof path, "%s/v.raw", dir);
  FILE *r8 = fopen(path, "wb");
  snprintf(path, sizeof path, "%s/v16.raw", dir);
  FILE *r16 = fopen(path, "wb");
  snprintf(path, sizeof path, "%s/v.pts", dir);
  FILE *pts = fopen(path, "w");
  assert_non_null(r8);
  assert_non_null(r16);
  assert_non_null(pts);
  fprintf(pts, "# voxel centres, mm\n");
  for (long q = 0; q < NV; q++) {
    unsigned char b[2] = {(unsigned char)v[q], 0};
    assert_int_equal(fwrite(b, 1, 1, r8), 1);
    assert_int_equal(fwrite(b, 1, 2, r16), 2);
    long idx[3] = {q % NX, (q / NX) % NY, q / (NX * NY)};
    if (v[q] < 128) continue;
    for (int c = 0; c < 3; c++)
      fprintf(pts, "%.17g%s", 1e3 * (O[c] + (idx[c] + 0.5) * D[c]),
              c < 2 ? " " : "\n");
  }
  assert_int_equal(fclose(r8), 0);
  assert_int_equal(fclose(r16), 0);
  assert_int_equal(fclose(pts), 0);
}

/* An MPM scene of dimension dim with materials gel (1000 kg/m^3) and
 * vessel (2000) and the given bodies, as dir/name; its text in text. */
static void write_scene(const char *dir, const char *name, int dim,
                        const char *bodies, char *text, size_t size,
                        char path[512]) {
  snprintf(text, size,
           "name: image\n"
           "method: mpm\n"
           "dimension: %d\n"
           "domain: {box: {min: [0, 0%s], max: [1, 1%s]}}\n"
           "discretization: {mesh_size: 0.25}\n"
           "materials:\n"
           "  - {name: gel, model: neo-hookean, density: 1000, "
           "youngs_modulus: 1.0e4, poisson_ratio: 0.3}\n"
           "  - {name: vessel, model: neo-hookean, density: 2000, "
           "youngs_modulus: 2.0e4, poisson_ratio: 0.3}\n"
           "bodies:\n%s"
           "time: {end: 1}\n",
           dim, dim == 3 ? ", 0" : "", dim == 3 ? ", 1" : "", bodies);
  pm_test_write_file(dir, name, text, path);
}

/* A scene's particles: count, positions, volumes, masses. */
typedef struct {
  long n;
  double *x, *vol, *mass;
} particles;

static particles seed(const char *path, int nset, const char *const *set) {
  model m = make_model(path, nset, set);
  particles p = {.n = m.model->n};
  p.x = malloc(sizeof(double) * 3 * (size_t)p.n);
  p.vol = malloc(sizeof(double) * (size_t)p.n);
  p.mass = malloc(sizeof(double) * (size_t)p.n);
  assert_true(p.x && p.vol && p.mass);
  memcpy(p.x, m.state->x, sizeof(double) * 3 * (size_t)p.n);
  memcpy(p.vol, m.model->vol0, sizeof(double) * (size_t)p.n);
  memcpy(p.mass, m.model->mass, sizeof(double) * (size_t)p.n);
  drop_model(&m);
  return p;
}

static void drop(particles *p) {
  free(p->x);
  free(p->vol);
  free(p->mass);
}

static double total_volume(const particles *p) {
  double v = 0;
  for (long q = 0; q < p->n; q++) v += p->vol[q];
  return v;
}

/* ---- the same particles from every source --------------------------------
 */

static void test_sources(void **state) {
  const char *dir = *state;
  write_sources(dir);
  static const char *const source[] = {
      "file: v.tif",
      "file: slices",
      "raw: {file: v.raw, size: [6, 5, 3]}",
      "raw: {file: v16.raw, size: [6, 5, 3], bits: 16}",
      "points: {file: v.pts, size: [6, 5, 3], unit: 1.0e-3}",
  };
  particles ref = {0};
  const double dv = D[0] * D[1] * D[2];
  for (int k = 0; k < 5; k++) {
    char bodies[512], text[2048], path[512], name[32];
    snprintf(bodies, sizeof bodies,
             "  - {material: vessel, image: {%s, " VOX
             ", label: [128, 255]}}\n",
             source[k]);
    snprintf(name, sizeof name, "source-%d.yaml", k);
    write_scene(dir, name, 3, bodies, text, sizeof text, path);
    particles p = seed(path, 0, NULL);
    /* One particle at each centre of a voxel of 200, in voxel order. */
    assert_int_equal(p.n, voxels_of(200, ALL_LO, ALL_HI));
    long q = 0;
    for (long kk = 0; kk < NZ; kk++)
      for (long j = 0; j < NY; j++)
        for (long i = 0; i < NX; i++) {
          if (value(i, j, kk) < 128) continue;
          const long idx[3] = {i, j, kk};
          for (int c = 0; c < 3; c++)
            assert_near(p.x[3 * q + c], O[c] + (idx[c] + 0.5) * D[c], 1e-15);
          assert_near(p.vol[q], dv, 1e-15 * dv);
          assert_near(p.mass[q], 2000 * p.vol[q], 1e-15 * p.mass[q]);
          q++;
        }
    /* Every source gives the very same numbers. */
    if (k == 0) {
      ref = p;
      continue;
    }
    assert_int_equal(p.n, ref.n);
    assert_memory_equal(p.x, ref.x, sizeof(double) * 3 * (size_t)p.n);
    assert_memory_equal(p.vol, ref.vol, sizeof(double) * (size_t)p.n);
    drop(&p);
  }
  drop(&ref);
}

/* ---- n^d particles per voxel ---------------------------------------------
 */

static void test_per_voxel(void **state) {
  const char *dir = *state;
  write_sources(dir);
  char text[2048], path[512];
  /* 3D: 2^3 per voxel at the sub-voxel centres, the same total volume. */
  write_scene(dir, "n3.yaml", 3,
              "  - {material: vessel, image: {file: v.tif, " VOX
              ", label: [128, 255]}}\n",
              text, sizeof text, path);
  const char *two = "bodies.0.image.particles_per_voxel=2";
  particles p1 = seed(path, 0, NULL), p2 = seed(path, 1, &two);
  assert_int_equal(p2.n, 8 * p1.n);
  double v1 = total_volume(&p1), v2 = total_volume(&p2);
  /* Sums of n equal terms, each in error by n eps at most. */
  assert_near(v2, v1, (p1.n + p2.n) * EPS * v1);
  assert_near(v1, p1.n * D[0] * D[1] * D[2], 2 * p1.n * EPS * v1);
  /* The first voxel of 200 is (2, 0, 0): its 8 particles, x fastest. */
  assert_int_equal(value(2, 0, 0), 200);
  for (int s = 0; s < 8; s++) {
    const double sub[3] = {s % 2, (s / 2) % 2, s / 4};
    const double idx[3] = {2, 0, 0};
    for (int c = 0; c < 3; c++)
      assert_near(p2.x[3 * s + c], O[c] + (idx[c] + (sub[c] + 0.5) / 2) * D[c],
                  1e-15);
    assert_near(p2.vol[s], D[0] * D[1] * D[2] / 8, 1e-15);
  }
  drop(&p1);
  drop(&p2);
  /* 2D: one slice (k = 1) of the stack, 3^2 per voxel, area per unit
   * depth, z = 0. */
  write_scene(dir, "n2.yaml", 2,
              "  - {material: vessel, image: {file: v.tif, " VOX
              ", crop: {min: [0, 0, 1], max: [6, 5, 2]}, label: [128, "
              "255]}}\n",
              text, sizeof text, path);
  const char *three = "bodies.0.image.particles_per_voxel=3";
  p1 = seed(path, 0, NULL);
  p2 = seed(path, 1, &three);
  const long lo[3] = {0, 0, 1}, hi[3] = {NX, NY, 2};
  assert_int_equal(p1.n, voxels_of(200, lo, hi));
  assert_int_equal(p2.n, 9 * p1.n);
  v1 = total_volume(&p1);
  v2 = total_volume(&p2);
  assert_near(v1, p1.n * D[0] * D[1], 2 * p1.n * EPS * v1);
  assert_near(v2, v1, (p1.n + p2.n) * EPS * v1);
  for (long q = 0; q < p2.n; q++) assert_near(p2.x[3 * q + 2], 0, 0);
  drop(&p1);
  drop(&p2);
}

/* ---- label ranges partition the voxels -----------------------------------
 */

/* Body b's particles lie in voxels whose value is in [lo, hi]. */
static void check_labels(const model *m, int b, int lo, int hi) {
  for (long q = m->model->body_begin[b]; q < m->model->body_end[b]; q++) {
    long idx[3];
    for (int c = 0; c < 3; c++)
      idx[c] = (long)floor((m->state->x[3 * q + c] - O[c]) / D[c]);
    int v = value(idx[0], idx[1], idx[2]);
    if (v < lo || v > hi)
      fail_msg("bodies.%d: particle %ld in a voxel of %d, not in [%d, %d]", b,
               q, v, lo, hi);
  }
}

static void test_partition(void **state) {
  const char *dir = *state;
  write_sources(dir);
  char text[2048], path[512];
  write_scene(
      dir, "labels.yaml", 3,
      "  - {material: gel, image: {file: v.tif, " VOX ", label: [0, 50]}}\n"
      "  - {material: vessel, image: {file: v.tif, " VOX
      ", label: [51, 150]}}\n"
      "  - {material: gel, image: {file: v.tif, " VOX ", label: [151, 255]}}\n",
      text, sizeof text, path);
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  static const int range[3][2] = {{0, 50}, {51, 150}, {151, 255}};
  for (int b = 0; b < 3; b++) {
    assert_int_equal(md->body_end[b] - md->body_begin[b],
                     voxels_of((uint16_t)(100 * b), ALL_LO, ALL_HI));
    check_labels(&m, b, range[b][0], range[b][1]);
    for (long q = md->body_begin[b]; q < md->body_end[b]; q++)
      assert_near(md->mass[q], (b == 1 ? 2000 : 1000) * md->vol0[q],
                  1e-15 * md->mass[q]);
  }
  /* Every voxel once: the image's volume (a sum of 90 equal terms, in
   * error by 90 eps at most, and the product's 2 eps). */
  assert_int_equal(md->n, NV);
  double vol = 0;
  for (long q = 0; q < md->n; q++) vol += md->vol0[q];
  const double image = NV * D[0] * D[1] * D[2];
  assert_near(vol, image, (NV + 4) * EPS * image);
  /* The estimate counts the shared voxels once. */
  long points = 0;
  mpm_estimate_bytes(m.scene, &points);
  assert_int_equal(points, NV);
  /* The shape of body 1: its particles in, the others out; bounds the
   * image's box. */
  gm_shape *sh = NULL;
  assert_ok(gm_shape_create(&m.scene->bodies[1], 3, m.scene->box_min,
                            m.scene->box_max, 0, &sh));
  assert_string_equal(gm_shape_kind(sh), "image");
  assert_true(gm_shape_thread_safe(sh));
  for (long q = 0; q < md->n; q++)
    assert_int_equal(gm_shape_contains(sh, m.state->x + 3 * q),
                     q >= md->body_begin[1] && q < md->body_end[1]);
  double lo[3], hi[3];
  assert_true(gm_shape_bounds(sh, lo, hi));
  for (int c = 0; c < 3; c++) {
    assert_near(lo[c], O[c], 1e-15);
    assert_near(hi[c], O[c] + ALL_HI[c] * D[c], 1e-15);
  }
  /* A voxel's lower face is its own, its upper face the next voxel's:
   * voxel (1, 0, 0) is 100, (2, 0, 0) 200. */
  double face[3] = {O[0] + 2 * D[0], O[1] + 0.5 * D[1], O[2] + 0.5 * D[2]};
  assert_false(gm_shape_contains(sh, face));
  face[0] = nextafter(face[0], 0);
  assert_true(gm_shape_contains(sh, face));
  gm_shape_destroy(sh);
  drop_model(&m);
  /* A crop: body 1's voxels of [1, 5) x [1, 4) x [0, 2), its box; the
   * estimate adds them to the 90 of the others (at most: 4 x 3 x 2). */
  const char *crop = "bodies.1.image.crop={min: [1, 1, 0], max: [5, 4, 2]}";
  m = make_model(path, 1, &crop);
  const long clo[3] = {1, 1, 0}, chi[3] = {5, 4, 2};
  assert_int_equal(m.model->body_end[1] - m.model->body_begin[1],
                   voxels_of(100, clo, chi));
  check_labels(&m, 1, 51, 150);
  assert_ok(gm_shape_create(&m.scene->bodies[1], 3, m.scene->box_min,
                            m.scene->box_max, 0, &sh));
  assert_true(gm_shape_bounds(sh, lo, hi));
  for (int c = 0; c < 3; c++) {
    assert_near(lo[c], O[c] + clo[c] * D[c], 1e-15);
    assert_near(hi[c], O[c] + chi[c] * D[c], 1e-15);
  }
  gm_shape_destroy(sh);
  mpm_estimate_bytes(m.scene, &points);
  assert_int_equal(points, NV + 4 * 3 * 2);
  drop_model(&m);
}

/* ---- bad images ----------------------------------------------------------
 */

static const struct {
  const char *name;
  int dim;
  const char *bodies;
  const char *at;   /* where the message points */
  const char *key;  /* the key path it names */
  const char *what; /* what it expected */
  const char *got;  /* and what it got */
  bool at_load;     /* refused by the scene; else when seeding */
} BAD[] = {
    {"cut.yaml", 3,
     "  - {material: gel, image: {file: cut.tif, " VOX ", label: [0, 255]}}\n",
     "cut.tif", ": bodies.0.image.file: ",
     "expected a TIFF of 8- or 16-bit grey pages", "cut.tif: ", false},
    {"short.yaml", 3,
     "  - {material: gel, image: {raw: {file: short.raw, size: [6, 5, 3]}, " VOX
     ", label: [0, 255]}}\n",
     "{file: short",
     ": bodies.0.image.raw: ", "expected a raw volume of the given size",
     "short.raw: expected 90 bytes (6 x 5 x 3 voxels of 8 bits), got 80",
     false},
    {"no-voxel.yaml", 3,
     "  - {material: gel, image: {file: v.tif, " VOX ", label: [0, 255]}}\n"
     "  - {material: vessel, image: {file: v.tif, " VOX ", label: [50, 60]}}\n",
     "[50, 60]",
     ": bodies.1.image.label: ", "expected a range matching some voxel of ",
     "v.tif (crop [0, 6) x [0, 5) x [0, 3)), got [50, 60]: no voxel", false},
    {"crop.yaml", 3,
     "  - {material: gel, image: {file: v.tif, " VOX
     ", crop: {min: [0, 2, 0], max: [7, 5, 3]}, label: [0, 255]}}\n",
     "[7, 5, 3]", ": bodies.0.image.crop.max: ",
     "expected a crop inside the image (6 x 5 x 3 voxels of ",
     "v.tif), got max.0 = 7", false},
    {"slices.yaml", 2,
     "  - {material: gel, image: {file: v.tif, " VOX ", label: [0, 255]}}\n",
     "v.tif", ": bodies.0.image.file: ",
     "expected an image of one slice for dimension 2", "got 3 slices of ",
     false},
    {"outside.yaml", 3,
     "  - {material: gel, image: {file: v.tif, voxel: [0.1, 0.08, 0.12], "
     "origin: [0.5, 0.1, 0.2], label: [0, 255]}}\n",
     "{material: gel, image",
     ": bodies.0.image: ", "expected a shape inside domain.box (x in [0, 1])",
     "got one reaching x = 1.1: its particles would be outside the grid",
     false},
    {"per-cell.yaml", 3,
     "  - {material: gel, image: {file: v.tif, " VOX
     ", label: [0, 255]}, particles_per_cell: [2]}\n",
     "particles_per_cell", ": bodies.0.particles_per_cell: ",
     "use image.particles_per_voxel", "got particles_per_cell", true},
    {"two-sources.yaml", 3,
     "  - {material: gel, image: {file: v.tif, raw: {file: v.raw, size: [6, "
     "5, 3]}, " VOX ", label: [0, 255]}}\n",
     "raw: {file: v.raw", ": bodies.0.image.raw: ",
     "expected one source (file, raw or points)", "got file and raw", true},
    {"label-order.yaml", 3,
     "  - {material: gel, image: {file: v.tif, " VOX ", label: [200, 100]}}\n",
     "[200, 100]", ": bodies.0.image.label: ",
     "expected [lo, hi] with lo <= hi", "got [200, 100]", true},
    {"voxel-2.yaml", 3,
     "  - {material: gel, image: {file: v.tif, voxel: [0.1, 0.08], label: "
     "[0, 255]}}\n",
     "[0.1, 0.08]", ": bodies.0.image.voxel: ", "expected 3 numbers",
     "(dimension 3), got 2", true},
};

static void test_bad_images(void **state) {
  const char *dir = *state;
  write_sources(dir);
  char path[512], at[600], where[700], out[600];
  /* A TIFF cut in half, a raw file 10 bytes short. */
  char src[512], cut[512];
  snprintf(src, sizeof src, "%s/v.tif", dir);
  snprintf(cut, sizeof cut, "%s/cut.tif", dir);
  FILE *f = fopen(src, "rb"), *g = fopen(cut, "wb");
  assert_true(f && g);
  char buf[8192];
  size_t len = fread(buf, 1, sizeof buf, f);
  assert_true(len > 0 && len < sizeof buf);
  assert_int_equal(fwrite(buf, 1, len / 2, g), len / 2);
  fclose(f);
  fclose(g);
  pm_test_write_file(dir, "short.raw", "", path);
  f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(buf, 1, 80, f), 80);
  fclose(f);
  for (size_t k = 0; k < sizeof BAD / sizeof BAD[0]; k++) {
    char text[2048];
    write_scene(dir, BAD[k].name, BAD[k].dim, BAD[k].bodies, text, sizeof text,
                path);
    pm_test_locate(path, text, BAD[k].at, at, sizeof at);
    pm_scene *s = NULL;
    pm_error_clear();
    if (BAD[k].at_load) {
      assert_int_equal(pm_scene_load(path, 0, NULL, &s), PM_ERR_SCENE);
      assert_null(s);
    } else {
      /* Refused before anything is written: no output folder. */
      assert_ok(pm_scene_load(path, 0, NULL, &s));
      snprintf(out, sizeof out, "%s/out-%zu", dir, k);
      pm_outcome o;
      assert_int_equal(pm_run_scene(s, out, PM_RUN_QUIET, &o), PM_ERR_SCENE);
      assert_int_not_equal(access(out, F_OK), 0);
      pm_scene_destroy(s);
    }
    const char *msg = pm_error_message();
    snprintf(where, sizeof where, "%s%s", at, BAD[k].key);
    assert_contains(msg, where);
    assert_contains(msg, BAD[k].what);
    assert_contains(msg, BAD[k].got);
    print_message("%s\n", msg);
  }
  /* FPM has no image bodies: refused at the key. */
  const char *fpm_text =
      "name: fpm-image\n"
      "method: fpm\n"
      "dimension: 3\n"
      "domain: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
      "discretization: {mesh_size: 0.25}\n"
      "materials:\n"
      "  - {name: gel, model: neo-hookean, density: 1000, youngs_modulus: "
      "1.0e4, poisson_ratio: 0.3}\n"
      "bodies:\n"
      "  - {material: gel, image: {file: v.tif, " VOX ", label: [0, 255]}}\n"
      "time: {end: 1}\n";
  pm_test_write_file(dir, "fpm.yaml", fpm_text, path);
  pm_test_locate(path, fpm_text, "image:", at, sizeof at);
  pm_scene *s = NULL;
  assert_int_equal(pm_scene_load(path, 0, NULL, &s), PM_ERR_SCENE);
  snprintf(where, sizeof where, "%s: bodies.0.image: ", at);
  assert_contains(pm_error_message(), where);
  assert_contains(pm_error_message(), "got image (method mpm)");
}

/* ---- the vessel slice of case I2 -----------------------------------------
 */

static void test_vessel_slice(void **state) {
  const char *dir = *state;
  char text[2048], path[512];
  /* 537.6 um square, 64 cells a side; collagen 0-127, vessel 128-255. */
  const char *head = "name: slice\n"
                     "method: mpm\n"
                     "dimension: 2\n"
                     "domain: {box: {min: [0, 0], max: [537.6e-6, "
                     "537.6e-6]}}\n"
                     "discretization: {mesh_size: 8.4e-6}\n"
                     "materials:\n"
                     "  - {name: collagen, model: neo-hookean-log, density: "
                     "1000, shear_modulus: 520.8, bulk_modulus: 1041.6}\n"
                     "  - {name: vessel, model: neo-hookean-log, density: "
                     "1000, shear_modulus: 1041.6, bulk_modulus: 2083.2}\n"
                     "bodies:\n";
  const char *file = PM_SOURCE_DIR "/cases/mpm/data/vesselslice25_512.tif";
  snprintf(text, sizeof text,
           "%s"
           "  - material: collagen\n"
           "    image: {file: %s, voxel: [1.05e-6, 1.05e-6, 1.0e-6], label: "
           "[0, 127]}\n"
           "  - material: vessel\n"
           "    image: {file: %s, voxel: [1.05e-6, 1.05e-6, 1.0e-6], label: "
           "[128, 255]}\n"
           "time: {end: 1}\n",
           head, file, file);
  pm_test_write_file(dir, "slice.yaml", text, path);
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  assert_int_equal(md->n, 512 * 512);
  assert_int_equal(md->body_end[1] - md->body_begin[1], 50760);
  double area = 0, vessel = 0;
  for (long q = 0; q < md->n; q++) area += md->vol0[q];
  for (long q = md->body_begin[1]; q < md->body_end[1]; q++)
    vessel += md->vol0[q];
  /* Sums of n equal terms, each in error by n eps at most. */
  const double side = 537.6e-6, pixel = 1.05e-6 * 1.05e-6;
  assert_near(area, side * side, md->n * EPS * side * side);
  assert_near(vessel, 50760 * pixel, 50760 * EPS * 50760 * pixel);
  long points = 0;
  mpm_estimate_bytes(m.scene, &points);
  assert_int_equal(points, 512 * 512);
  drop_model(&m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_sources, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_per_voxel, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_partition, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_images, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_vessel_slice, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
