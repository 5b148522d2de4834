/* test_checkpoint_pieces: a checkpoint written in pieces (as ranks write
 * it) and its index: a piece read back whole with the checksum its index
 * names, refused with another's; the index in place removes the older
 * checkpoint's pieces and the temporary ones a crash left, keeping its
 * own; a whole checkpoint removes them all. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "pm_testing.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "pm_checkpoint.h"

/* Piece `piece` of checkpoint id under dir holding x (3 values); its
 * checksum into *sum. */
static void write_piece(const char *dir, long id, int piece, double *x,
                        unsigned long long *sum) {
  pm_ckpt *ck = NULL;
  long n = 3;
  assert_ok(pm_ckpt_create_piece(dir, id, piece, sum, &ck));
  assert_ok(pm_ckpt_long(ck, "piece.n", &n));
  assert_ok(pm_ckpt_doubles(ck, "piece.x", 3, x));
  assert_ok(pm_ckpt_finish(ck));
}

/* The index of checkpoint id (its pieces' checksums), in place. */
static void write_index(const char *dir, long id, long *sums) {
  pm_ckpt *ck = NULL;
  long n = 2;
  assert_ok(pm_ckpt_create(dir, &ck));
  assert_ok(pm_ckpt_long(ck, "pieces.n", &n));
  assert_ok(pm_ckpt_longs(ck, "pieces.sums", 2, sums));
  pm_ckpt_set_pieces(ck, id);
  assert_ok(pm_ckpt_finish(ck));
}

static bool exists(const char *dir, long id, int piece) {
  char path[512];
  assert_ok(pm_ckpt_piece_path(path, sizeof path, dir, id, piece));
  return access(path, F_OK) == 0;
}

/* Read piece `piece` of checkpoint id expecting checksum sum: its values
 * into x, and the finish's outcome. */
static pm_err read_piece(const char *dir, long id, int piece,
                         unsigned long long sum, double *x) {
  pm_ckpt *ck = NULL;
  long n = 0;
  assert_ok(pm_ckpt_open_piece(dir, id, piece, sum, true, &ck));
  assert_ok(pm_ckpt_long(ck, "piece.n", &n));
  assert_int_equal(n, 3);
  assert_ok(pm_ckpt_doubles(ck, "piece.x", 3, x));
  return pm_ckpt_finish(ck);
}

static void test_pieces(void **state) {
  const char *dir = *state;
  double a[3] = {1, 2, 3}, b[3] = {4, 5, 6}, x[3];
  unsigned long long sa = 0, sb = 0;
  assert_ok(pm_ckpt_pieces_folder(dir));
  write_piece(dir, 10, 0, a, &sa);
  write_piece(dir, 10, 1, b, &sb);
  assert_true(sa != sb);
  long sums[2] = {(long)sa, (long)sb};
  write_index(dir, 10, sums);
  pm_ckpt *ck = NULL;
  assert_ok(pm_ckpt_open(dir, &ck));
  assert_true(pm_ckpt_has(ck, "pieces.n"));
  assert_false(pm_ckpt_has(ck, "mpm.t"));
  pm_ckpt_abort(ck);
  assert_ok(read_piece(dir, 10, 1, sb, x));
  assert_memory_equal(x, b, sizeof b);
  /* Piece 1 read as if it were piece 0 of the index: refused. */
  assert_fails(read_piece(dir, 10, 1, sa, x), PM_ERR_IO,
               "not the one its index names");

  /* A later checkpoint: its pieces, then a temporary piece a crash left;
   * the older pieces stay until the new index is in place. */
  write_piece(dir, 20, 0, b, &sa);
  write_piece(dir, 20, 1, a, &sb);
  char tmp[512];
  assert_ok(pm_ckpt_piece_path(tmp, sizeof tmp, dir, 30, 0));
  strcat(tmp, ".tmp.1");
  FILE *f = fopen(tmp, "w");
  assert_non_null(f);
  fclose(f);
  assert_true(exists(dir, 10, 0) && exists(dir, 20, 1));
  long sums2[2] = {(long)sa, (long)sb};
  write_index(dir, 20, sums2);
  assert_false(exists(dir, 10, 0) || exists(dir, 10, 1));
  assert_true(exists(dir, 20, 0) && exists(dir, 20, 1));
  assert_int_equal(access(tmp, F_OK), -1);
  assert_ok(read_piece(dir, 20, 0, sa, x));
  assert_memory_equal(x, b, sizeof b);

  /* A whole checkpoint (one process's) in place: no piece is left. */
  assert_ok(pm_ckpt_create(dir, &ck));
  assert_ok(pm_ckpt_doubles(ck, "mpm.x", 3, a));
  assert_ok(pm_ckpt_finish(ck));
  assert_false(exists(dir, 20, 0) || exists(dir, 20, 1));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_pieces, pm_test_make_dir,
                                      pm_test_drop_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
