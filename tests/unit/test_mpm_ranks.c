/* test_mpm_ranks: MPM's ranks layer in one process: the decomposition's
 * boxes and nodes, and the core stepping through the exchange interface with
 * a fake share of one rank, which must give one process's state bit for bit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpm_testing.h"
/* (the ranks layer's header, which the core may not include) */
#include "mpm_par.h"

#define DISKS PM_SOURCE_DIR "/cases/mpm/disks-collision.yaml"
#define COLUMN PM_SOURCE_DIR "/cases/mpm/gravity-column.yaml"

/* ---- the decomposition ----------------------------------------------------
 */

/* Whether index i of every axis lies in [lo, hi). */
static bool inside(const long i[3], const long lo[3], const long hi[3]) {
  for (int a = 0; a < 3; a++)
    if (i[a] < lo[a] || i[a] >= hi[a]) return false;
  return true;
}

/* The cut as a checkpoint keeps it (mpm_decomp_pack) reads back the same,
 * and integers that are no cut of the grid are refused: a child that goes
 * back up the tree (a descent that never ends), a box past the grid. */
static void check_pack(const mpm_decomp *d, const mpm_grid *g) {
  const long n = mpm_decomp_items(d->size);
  long *buf = calloc((size_t)n, sizeof *buf);
  assert_non_null(buf);
  mpm_decomp_pack(d, buf);
  mpm_decomp e;
  assert_ok(mpm_decomp_unpack(buf, d->size, g, "cut", &e));
  assert_memory_equal(e.box, d->box, 6 * sizeof(long) * (size_t)d->size);
  assert_memory_equal(e.count, d->count, sizeof(long) * (size_t)d->size);
  assert_memory_equal(e.count0, d->count, sizeof(long) * (size_t)d->size);
  for (int k = 0; k + 1 < d->size; k++) {
    assert_int_equal(e.tree[k].axis, d->tree[k].axis);
    assert_int_equal(e.tree[k].at, d->tree[k].at);
    assert_int_equal(e.tree[k].child[0], d->tree[k].child[0]);
    assert_int_equal(e.tree[k].child[1], d->tree[k].child[1]);
  }
  for (int a = 0; a < 3; a++) assert_int_equal(e.cuts[a], d->cuts[a]);
  mpm_decomp_destroy(&e);
  long *tree = buf + 4 + 6 * (long)d->size;
  if (d->size > 2) { /* (a tree of more than one cut) */
    const long keep = tree[2];
    tree[2] = 0; /* the root's child the root */
    assert_int_equal(mpm_decomp_unpack(buf, d->size, g, "cut", &e), PM_ERR_IO);
    assert_non_null(strstr(pm_error_message(), "cut: expected the cut of"));
    tree[2] = keep;
  }
  buf[4 + 3] = d->cells[0] + 1; /* rank 0's box past the grid */
  assert_int_equal(mpm_decomp_unpack(buf, d->size, g, "cut", &e), PM_ERR_IO);
  pm_error_clear();
  free(buf);
}

/* The boxes of `size` ranks tile the grid's cells, every node has one
 * owner and is held where it is owned, and the particles at their reference
 * positions are counted on the rank whose box holds them. */
static void check_decomposition(const char *path, int size) {
  model m = make_model(path, 0, NULL);
  const mpm_model *md = m.model;
  mpm_decomp d;
  assert_ok(mpm_decomp_create(m.scene, md, size, &d));
  assert_int_equal(d.size, size);
  long c[3];
  for (c[2] = 0; c[2] < d.cells[2]; c[2]++)
    for (c[1] = 0; c[1] < d.cells[1]; c[1]++)
      for (c[0] = 0; c[0] < d.cells[0]; c[0]++) {
        int boxes = 0;
        for (int r = 0; r < size; r++)
          boxes += inside(c, d.box + 6 * r, d.box + 6 * r + 3);
        assert_int_equal(boxes, 1);
      }
  const mpm_grid *g = &md->grid;
  long q[3];
  for (q[2] = 0; q[2] < g->nn[2]; q[2]++)
    for (q[1] = 0; q[1] < g->nn[1]; q[1]++)
      for (q[0] = 0; q[0] < g->nn[0]; q[0]++) {
        int owners = 0;
        for (int r = 0; r < size; r++) {
          long lo[3], hi[3], hlo[3], hhi[3];
          mpm_decomp_nodes(&d, r, lo, hi);
          mpm_decomp_held(&d, r, g, hlo, hhi);
          if (!inside(q, lo, hi)) continue;
          owners++;
          assert_true(inside(q, hlo, hhi));
        }
        assert_int_equal(owners, 1);
      }
  long *count = calloc((size_t)size, sizeof *count), total = 0;
  assert_non_null(count);
  for (long p = 0; p < md->n; p++) {
    const int r = mpm_decomp_rank_at(&d, g, md->x0 + 3 * p);
    assert_in_range(r, 0, size - 1);
    count[r]++;
  }
  for (int r = 0; r < size; r++) {
    assert_int_equal(count[r], d.count[r]);
    assert_true(count[r] > 0);
    total += count[r];
  }
  assert_int_equal(total, md->n);
  free(count);
  check_pack(&d, g);
  mpm_decomp_destroy(&d);
  drop_model(&m);
}

static void test_decomposition(void **state) {
  (void)state;
  for (int size = 2; size <= 5; size++) {
    check_decomposition(DISKS, size);
    check_decomposition(COLUMN, size);
  }
}

/* ---- the core through the exchange ----------------------------------------
 */

/* A share of one rank: every node its own, nothing from other ranks; it
 * counts what the core asked of it. */
typedef struct {
  mpm_exchange xc;
  unsigned char *owned;
  int reductions, agreements, node_sums, step_ends, migrations;
} fake_share;

static int released; /* fake shares released */

static fake_share *fake_of(const mpm_model *m) { return m->xc->ctx; }

static void fake_sum(void *ctx, double *v, int n) {
  (void)v, (void)n;
  ((fake_share *)ctx)->reductions++;
}
static void fake_sum_long(void *ctx, long *v, int n) {
  (void)v, (void)n;
  ((fake_share *)ctx)->reductions++;
}
static pm_err fake_agree(void *ctx, pm_err e) {
  ((fake_share *)ctx)->agreements++;
  return e;
}
static long fake_offset(void *ctx, long n) {
  (void)ctx, (void)n;
  return 0;
}
static pm_err fake_sum_nodes(const mpm_model *m, mpm_nodes *nd, int mode,
                             bool imp) {
  (void)nd, (void)mode, (void)imp;
  fake_of(m)->node_sums++;
  return PM_SUCCESS;
}
static pm_err fake_nodes_reduce(const mpm_model *m, void *a, mpm_xc_unit unit,
                                mpm_xc_op op) {
  (void)a, (void)unit, (void)op;
  fake_of(m)->node_sums++;
  return PM_SUCCESS;
}
static pm_err fake_nodes_bcast(const mpm_model *m, void *a, mpm_xc_unit unit) {
  (void)a, (void)unit;
  fake_of(m)->node_sums++;
  return PM_SUCCESS;
}
static const unsigned char *fake_owned(const mpm_model *m) {
  return fake_of(m)->owned;
}
static void fake_work_attach(const mpm_model *m, mpm_work *w) {
  w->nodes.owned = fake_of(m)->owned;
}
static void fake_step_end(const mpm_model *m, mpm_work *w) {
  (void)w;
  fake_of(m)->step_ends++;
}
static pm_err fake_migrate(mpm_model *m, mpm_state *s, mpm_work *w) {
  (void)s, (void)w;
  fake_of(m)->migrations++;
  return PM_SUCCESS;
}
static const double *fake_ghost_x(const mpm_model *m, int gi) {
  (void)m, (void)gi;
  return NULL;
}
static const long *fake_ghost_ids(const mpm_model *m, int gi, long *n) {
  (void)m, (void)gi;
  *n = 0;
  return NULL;
}
static const double *fake_nearby(const mpm_model *m, int gi, long *n,
                                 const long **ids) {
  (void)m, (void)gi;
  *n = 0;
  *ids = NULL;
  return NULL;
}
static void fake_cells(const mpm_model *m, long nn[3], long lo[3], long hi[3]) {
  for (int a = 0; a < 3; a++) {
    nn[a] = m->grid.nn[a];
    lo[a] = 0;
    hi[a] = a < m->dim ? m->grid.nn[a] - 1 : 1;
  }
}
static pm_err fake_number_unknowns(const mpm_model *m, long nunk, long *dof,
                                   long *gnum, long **ghost, long *nghost) {
  (void)m, (void)nunk, (void)dof, (void)gnum, (void)ghost;
  *nghost = 0;
  return PM_SUCCESS;
}
static pm_err fake_gather_nodes(const mpm_model *m, const mpm_model *full,
                                const double *local, double *whole) {
  (void)full;
  memcpy(whole, local, 3 * sizeof(double) * (size_t)m->grid.n_nodes);
  return PM_SUCCESS;
}
static void fake_release(mpm_exchange *xc) {
  fake_share *f = xc->ctx;
  free(f->owned);
  free(f);
  released++;
}

/* Give model m a fake share of one rank. */
static fake_share *attach_fake(mpm_model *m) {
  fake_share *f = calloc(1, sizeof *f);
  assert_non_null(f);
  f->owned = malloc((size_t)m->grid.n_nodes);
  assert_non_null(f->owned);
  memset(f->owned, 1, (size_t)m->grid.n_nodes);
  f->xc = (mpm_exchange){.ctx = f,
                         .sum = fake_sum,
                         .max = fake_sum,
                         .min = fake_sum,
                         .sum_long = fake_sum_long,
                         .agree = fake_agree,
                         .offset = fake_offset,
                         .sum_nodes = fake_sum_nodes,
                         .nodes_reduce = fake_nodes_reduce,
                         .nodes_bcast = fake_nodes_bcast,
                         .owned = fake_owned,
                         .work_attach = fake_work_attach,
                         .step_end = fake_step_end,
                         .migrate = fake_migrate,
                         .ghost_x = fake_ghost_x,
                         .ghost_ids = fake_ghost_ids,
                         .nearby = fake_nearby,
                         .cells = fake_cells,
                         .number_unknowns = fake_number_unknowns,
                         .gather_nodes = fake_gather_nodes,
                         .release = fake_release};
  m->xc = &f->xc;
  return f;
}

/* n doubles alike bit for bit (none: alike, whatever the pointers). */
static bool same(const double *a, const double *b, long n) {
  return n == 0 || memcmp(a, b, sizeof(double) * (size_t)n) == 0;
}

/* Steps of scene path on one process and on a fake share of one rank:
 * every call through the exchange, the same state bit for bit. */
static void check_through_exchange(const char *path, int steps) {
  model one = make_model(path, 0, NULL);
  model shared = {NULL, NULL, NULL, NULL};
  assert_ok(pm_scene_load(path, 0, NULL, &shared.scene));
  assert_ok(mpm_model_create(shared.scene, &shared.model, &shared.state));
  fake_share *f = attach_fake(shared.model);
  assert_ok(mpm_work_create(shared.model, &shared.work));
  assert_ptr_equal(shared.work->nodes.owned, f->owned);
  for (int k = 0; k < steps; k++) {
    step(&one);
    step(&shared);
    assert_ok(mpm_xc_migrate(shared.model, shared.state, shared.work));
  }
  const mpm_state *a = one.state, *b = shared.state;
  const long n = one.model->n;
  assert_int_equal(shared.model->n, n);
  assert_true(a->t == b->t && a->dt == b->dt && a->step == b->step);
  assert_true(same(a->x, b->x, 3 * n));
  assert_true(same(a->v, b->v, 3 * n));
  assert_true(same(a->vol, b->vol, n));
  assert_true(same(a->sigma, b->sigma, 9 * n));
  assert_true(same(one.work->cond.reaction, shared.work->cond.reaction,
                   3 * one.model->n_bcs));
  /* every transfer's node sums, every stage's agreement, each step's end
   * and migration went through the share */
  assert_true(f->node_sums >= steps);
  assert_true(f->agreements >= steps * shared.model->pipeline.n);
  assert_int_equal(f->step_ends, steps);
  assert_int_equal(f->migrations, steps);
  const int before = released;
  drop_model(&shared);
  assert_int_equal(released, before + 1); /* the model released its share */
  drop_model(&one);
}

static void test_core_through_exchange(void **state) {
  (void)state;
  check_through_exchange(DISKS, 20);
  check_through_exchange(COLUMN, 20);
}

/* On one process the accessors do what one process does. */
static void test_one_process(void **state) {
  (void)state;
  model m = make_model(DISKS, 0, NULL);
  const mpm_model *md = m.model;
  assert_false(mpm_xc_shared(md));
  double v[2] = {1.5, -2};
  mpm_xc_sum(md, v, 2);
  mpm_xc_max(md, v, 2);
  mpm_xc_min(md, v, 2);
  assert_true(v[0] == 1.5 && v[1] == -2);
  assert_int_equal(mpm_xc_agree(md, PM_ERR_SCENE), PM_ERR_SCENE);
  assert_int_equal(mpm_xc_offset(md, 7), 0);
  assert_null(mpm_xc_owned(md));
  long n = -1;
  const long *ids = (const long *)&n;
  assert_null(mpm_xc_ghost_x(md, 0));
  assert_null(mpm_xc_ghost_ids(md, 0, &n));
  assert_int_equal(n, 0);
  n = -1;
  assert_null(mpm_xc_nearby(md, 0, &n, &ids));
  assert_int_equal(n, 0);
  assert_null(ids);
  long nn[3], lo[3], hi[3];
  mpm_xc_cells(md, nn, lo, hi);
  for (int a = 0; a < 3; a++) {
    assert_int_equal(nn[a], md->grid.nn[a]);
    assert_int_equal(lo[a], 0);
    assert_int_equal(hi[a], a < md->dim ? md->grid.nn[a] - 1 : 1);
  }
  drop_model(&m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_decomposition),
      cmocka_unit_test(test_core_through_exchange),
      cmocka_unit_test(test_one_process),
  };
  if (pm_app_init() != PM_SUCCESS) return 1;
  return cmocka_run_group_tests(tests, NULL, NULL);
}
