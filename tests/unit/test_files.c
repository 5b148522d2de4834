/* test_files: mkdir -p, atomic files, history CSV, the JSON writer, stage
 * timers and the progress line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
/* cmocka needs the three headers above first. */
#include <cmocka.h>

#include "pm_testing.h"

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "pm_files.h"
#include "pm_progress.h"

/* ---- Helpers ----------------------------------------------------------- */

static bool exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

/* ---- mkdir -p and atomic files ----------------------------------------- */

static void test_mkdir_p(void **state) {
  const char *dir = *state;
  char path[512], file[512];
  snprintf(path, sizeof path, "%s/a/b//c/", dir);
  assert_int_equal(pm_mkdir_p(path), PM_SUCCESS);
  assert_int_equal(pm_mkdir_p(path), PM_SUCCESS); /* idempotent */
  snprintf(path, sizeof path, "%s/a/b/c", dir);
  assert_true(exists(path));

  /* A component that is a file. */
  snprintf(file, sizeof file, "%s/plain", dir);
  fclose(fopen(file, "w"));
  snprintf(path, sizeof path, "%s/plain/sub", dir);
  assert_int_equal(pm_mkdir_p(path), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), "plain"));
  assert_int_equal(pm_mkdir_p(""), PM_ERR_ARG);
  pm_error_clear();
}

static void test_afile_commit_abort(void **state) {
  const char *dir = *state;
  char path[512];
  pm_afile *f = NULL;
  snprintf(path, sizeof path, "%s/out.txt", dir);

  assert_int_equal(pm_afile_open(path, &f), PM_SUCCESS);
  fprintf(pm_afile_stream(f), "hello\n");
  assert_false(exists(path)); /* not visible before commit */
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);
  assert_string_equal(pm_afile_path(f), path);
  assert_int_equal(pm_afile_commit(f), PM_SUCCESS);
  pm_test_assert_file(path, "hello\n");
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);

  /* Abort: the old file stays, no temporary file remains. */
  assert_int_equal(pm_afile_open(path, &f), PM_SUCCESS);
  fprintf(pm_afile_stream(f), "partial");
  pm_afile_abort(f);
  pm_test_assert_file(path, "hello\n");
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);

  /* Abort of a new file leaves nothing at all. */
  snprintf(path, sizeof path, "%s/new.txt", dir);
  assert_int_equal(pm_afile_open(path, &f), PM_SUCCESS);
  pm_afile_abort(f);
  assert_false(exists(path));
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);
  pm_afile_abort(NULL);
  assert_int_equal(pm_afile_commit(NULL), PM_SUCCESS);
}

static void test_bad_directory(void **state) {
  const char *dir = *state;
  char missing[400], path[512];
  pm_afile *f = (pm_afile *)1;
  pm_history *h = (pm_history *)1;
  pm_json *j = (pm_json *)1;
  const char *names[] = {"t"};
  snprintf(missing, sizeof missing, "%s/no/such/dir", dir);
  snprintf(path, sizeof path, "%s/x.txt", missing);

  assert_int_equal(pm_afile_open(path, &f), PM_ERR_IO);
  assert_null(f);
  assert_non_null(strstr(pm_error_message(), missing));
  assert_int_equal(pm_history_open(missing, 1, names, -1, &h), PM_ERR_IO);
  assert_null(h);
  assert_non_null(strstr(pm_error_message(), missing));
  snprintf(path, sizeof path, "%s/summary.json", missing);
  assert_int_equal(pm_json_open(path, &j), PM_ERR_IO);
  assert_null(j);
  assert_non_null(strstr(pm_error_message(), missing));

  /* Unwritable directory (root ignores permissions: skip then). */
  if (geteuid() != 0) {
    char ro[400];
    snprintf(ro, sizeof ro, "%s/readonly", dir);
    assert_int_equal(mkdir(ro, 0500), 0);
    snprintf(path, sizeof path, "%s/x.txt", ro);
    assert_int_equal(pm_afile_open(path, &f), PM_ERR_IO);
    assert_non_null(strstr(pm_error_message(), ro));
    chmod(ro, 0700);
  }
  pm_error_clear();
}

/* ---- History ----------------------------------------------------------- */

static void test_history(void **state) {
  const char *dir = *state;
  const char *names[] = {"time", "kinetic", "reaction, x"};
  char path[512];
  pm_history *h = NULL;
  snprintf(path, sizeof path, "%s/history.csv", dir);

  assert_int_equal(pm_history_open(dir, 3, names, -1, &h), PM_SUCCESS);
  assert_int_equal(pm_history_ncols(h), 3);
  for (int i = 0; i < 3; i++) {
    double row[3] = {0.5 * i, 1.0 / 3.0, -2e-12 * i};
    assert_int_equal(pm_history_row(h, row), PM_SUCCESS);
  }
  /* Synced rows are on disk while the run goes on. */
  assert_int_equal(pm_history_sync(h), PM_SUCCESS);
  pm_test_assert_file(path, "time,kinetic,\"reaction, x\"\n"
                            "0,0.3333333333,-0\n"
                            "0.5,0.3333333333,-2e-12\n"
                            "1,0.3333333333,-4e-12\n");
  double bad[3] = {NAN, INFINITY, 1e300};
  assert_int_equal(pm_history_row(h, bad), PM_SUCCESS);
  assert_int_equal(pm_history_close(h), PM_SUCCESS);
  pm_test_assert_file(path, "time,kinetic,\"reaction, x\"\n"
                            "0,0.3333333333,-0\n"
                            "0.5,0.3333333333,-2e-12\n"
                            "1,0.3333333333,-4e-12\n"
                            "nan,inf,1e+300\n");
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);

  /* Resuming keeps the first rows and appends after them. */
  assert_int_equal(pm_history_open(dir, 3, names, 2, &h), PM_SUCCESS);
  double next[3] = {2, 0, 0};
  assert_int_equal(pm_history_row(h, next), PM_SUCCESS);
  assert_int_equal(pm_history_close(h), PM_SUCCESS);
  pm_test_assert_file(path, "time,kinetic,\"reaction, x\"\n"
                            "0,0.3333333333,-0\n"
                            "0.5,0.3333333333,-2e-12\n"
                            "2,0,0\n");
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);
  /* ... but not another table's, nor more rows than it has. */
  assert_int_equal(pm_history_open(dir, 1, names, 1, &h), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), "columns"));
  assert_int_equal(pm_history_open(dir, 3, names, 9, &h), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), "holds 3 rows"));
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);

  assert_int_equal(pm_history_open(dir, 0, names, -1, &h), PM_ERR_ARG);
  assert_int_equal(pm_history_close(NULL), PM_SUCCESS);
  pm_error_clear();
}

/* ---- Output folders ----------------------------------------------------- */

static void test_outdir(void **state) {
  const char *dir = *state;
  char out[512], path[600];
  pm_outdir *d = NULL, *d2 = (pm_outdir *)1;
  snprintf(out, sizeof out, "%s/run", dir);

  /* A new folder is created and locked: a second claim names the pid. */
  assert_int_equal(pm_outdir_claim(out, PM_OUTDIR_NEW, &d), PM_SUCCESS);
  assert_int_equal(pm_outdir_claim(out, PM_OUTDIR_OVERWRITE, &d2), PM_ERR_IO);
  assert_null(d2);
  char pid[32];
  snprintf(pid, sizeof pid, "pid %ld", (long)getpid());
  assert_non_null(strstr(pm_error_message(), "in use"));
  assert_non_null(strstr(pm_error_message(), pid));
  /* A run's files and a killed run's temporary file. */
  snprintf(path, sizeof path, "%s/summary.json", out);
  FILE *fp = fopen(path, "w");
  fputs("{\n  \"status\": \"completed\"\n}\n", fp);
  fclose(fp);
  snprintf(path, sizeof path, "%s/results.h5.tmp.1", out);
  fclose(fopen(path, "w"));
  /* The user's own files are never touched, whatever their names. */
  snprintf(path, sizeof path, "%s/notes.tmp.txt", out);
  fclose(fopen(path, "w"));
  snprintf(path, sizeof path, "%s/history.csv.tmp.12x", out);
  fclose(fopen(path, "w"));
  pm_outdir_release(d);

  /* Not overwritten unless asked. */
  assert_int_equal(pm_outdir_claim(out, PM_OUTDIR_NEW, &d), PM_ERR_IO);
  assert_non_null(strstr(pm_error_message(), "status \"completed\""));
  assert_non_null(strstr(pm_error_message(), "--overwrite"));
  snprintf(path, sizeof path, "%s/summary.json", out);
  assert_true(exists(path));
  assert_int_equal(pm_outdir_claim(out, PM_OUTDIR_RESUME, &d), PM_SUCCESS);
  assert_true(exists(path));
  pm_outdir_release(d);
  assert_int_equal(pm_outdir_claim(out, PM_OUTDIR_OVERWRITE, &d), PM_SUCCESS);
  assert_false(exists(path));
  snprintf(path, sizeof path, "%s/results.h5.tmp.1", out);
  assert_false(exists(path));
  snprintf(path, sizeof path, "%s/notes.tmp.txt", out);
  assert_true(exists(path));
  snprintf(path, sizeof path, "%s/history.csv.tmp.12x", out);
  assert_true(exists(path));
  pm_outdir_release(d);
  /* Resuming needs the folder. */
  snprintf(path, sizeof path, "%s/none", dir);
  assert_int_equal(pm_outdir_claim(path, PM_OUTDIR_RESUME, &d), PM_ERR_IO);
  assert_null(d);
  pm_error_clear();
}

/* Three processes claim and release one folder that each claim creates
 * and leaves empty, so that each release unlinks the lock file and
 * removes the folder while another may hold the file open: never two
 * holders at once (a shared count of holders, its largest value). */
static void test_outdir_race(void **state) {
  const char *dir = *state;
  char out[512], shm[] = "/dev/shm/pm_test_XXXXXX";
  /* On a tmpfs where there is one: the claims' folder syncs (pm_mkdir_p)
   * cost milliseconds each on a disk. */
  const bool on_shm = mkdtemp(shm) != NULL;
  snprintf(out, sizeof out, "%s/race", on_shm ? shm : dir);
  char count[600];
  snprintf(count, sizeof count, "%s/holders", dir);
  int fd = open(count, O_RDWR | O_CREAT, 0644);
  assert_true(fd >= 0 && ftruncate(fd, 2 * sizeof(int)) == 0);
  int *shared =
      mmap(NULL, 2 * sizeof(int), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  assert_true(shared != MAP_FAILED);
  close(fd);
  shared[0] = shared[1] = 0; /* holders now, most holders at once */
  enum { PROCS = 3, CLAIMS = 3000 };
  pid_t kids[PROCS];
  for (int k = 0; k < PROCS; k++) {
    kids[k] = fork();
    assert_true(kids[k] >= 0);
    if (kids[k] > 0) continue;
    for (int c = 0; c < CLAIMS; c++) {
      pm_outdir *d = NULL;
      if (pm_outdir_claim(out, PM_OUTDIR_NEW, &d) != PM_SUCCESS) {
        pm_error_clear();
        continue;
      }
      int now = __atomic_add_fetch(&shared[0], 1, __ATOMIC_SEQ_CST);
      int top = __atomic_load_n(&shared[1], __ATOMIC_SEQ_CST);
      while (now > top &&
             !__atomic_compare_exchange_n(&shared[1], &top, now, false,
                                          __ATOMIC_SEQ_CST, __ATOMIC_SEQ_CST)) {
      }
      /* a hold long enough for the others to try */
      nanosleep(&(struct timespec){.tv_nsec = 20000}, NULL);
      __atomic_sub_fetch(&shared[0], 1, __ATOMIC_SEQ_CST);
      pm_outdir_release(d);
    }
    _exit(0);
  }
  for (int k = 0; k < PROCS; k++) {
    int st = 0;
    assert_int_equal(waitpid(kids[k], &st, 0), kids[k]);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  }
  printf("outdir race: at most %d holder(s) at once over %d claims\n",
         shared[1], PROCS * CLAIMS);
  const int most = shared[1];
  munmap(shared, 2 * sizeof(int));
  if (on_shm) pm_test_remove_tree(shm); /* before a failure leaves it */
  assert_int_equal(most, 1);
}

/* ---- JSON -------------------------------------------------------------- */

/* Validate with Python's json module when it is installed. */
static void python_json_check(const char *path) {
  char cmd[1024];
  if (access("/usr/bin/python3", X_OK) != 0) return;
  snprintf(
      cmd, sizeof cmd,
      "/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1]));"
      " assert d[\"name\"] == \"a \\\"q\\\" \\\\ b\\n\\t\\u0001 \\u00e9\"; "
      "assert d[\"nested\"][2][0][\"deep\"] == []; "
      "assert d[\"nan\"] is None' %s",
      path);
  assert_int_equal(system(cmd), 0);
}

static void test_json(void **state) {
  const char *dir = *state;
  char path[512];
  pm_json *j = NULL;
  snprintf(path, sizeof path, "%s/summary.json", dir);

  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_begin_object(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_string(j, "name", "a \"q\" \\ b\n\t\x01 \xc3\xa9"),
                   PM_SUCCESS);
  assert_int_equal(pm_json_integer(j, "steps", 123456789012LL), PM_SUCCESS);
  assert_int_equal(pm_json_number(j, "dt", 0.25), PM_SUCCESS);
  assert_int_equal(pm_json_number(j, "nan", NAN), PM_SUCCESS);
  assert_int_equal(pm_json_bool(j, "ok", true), PM_SUCCESS);
  assert_int_equal(pm_json_begin_array(j, "nested"), PM_SUCCESS);
  assert_int_equal(pm_json_number(j, NULL, -1.5e-300), PM_SUCCESS);
  assert_int_equal(pm_json_null(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_begin_array(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_begin_object(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_begin_array(j, "deep"), PM_SUCCESS);
  assert_int_equal(pm_json_end_array(j), PM_SUCCESS);
  assert_int_equal(pm_json_end_object(j), PM_SUCCESS);
  assert_int_equal(pm_json_end_array(j), PM_SUCCESS);
  assert_int_equal(pm_json_end_array(j), PM_SUCCESS);
  assert_int_equal(pm_json_begin_object(j, "empty"), PM_SUCCESS);
  assert_int_equal(pm_json_end_object(j), PM_SUCCESS);
  assert_int_equal(pm_json_string(j, "null", NULL), PM_SUCCESS);
  assert_int_equal(pm_json_end_object(j), PM_SUCCESS);
  assert_false(exists(path));
  assert_int_equal(pm_json_close(j, true), PM_SUCCESS);
  pm_test_assert_file(
      path, "{\n"
            "  \"name\": \"a \\\"q\\\" \\\\ b\\n\\t\\u0001 \xc3\xa9\",\n"
            "  \"steps\": 123456789012,\n"
            "  \"dt\": 0.25,\n"
            "  \"nan\": null,\n"
            "  \"ok\": true,\n"
            "  \"nested\": [\n"
            "    -1.5e-300,\n"
            "    null,\n"
            "    [\n"
            "      {\n"
            "        \"deep\": []\n"
            "      }\n"
            "    ]\n"
            "  ],\n"
            "  \"empty\": {},\n"
            "  \"null\": null\n"
            "}\n");
  assert_int_equal(pm_test_count_entries(dir, NULL), 1);
  python_json_check(path);
}

static void test_json_misuse(void **state) {
  const char *dir = *state;
  char path[512];
  pm_json *j = NULL;
  snprintf(path, sizeof path, "%s/bad.json", dir);

  /* Key inside an array, then the writer refuses to commit. */
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_begin_array(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_number(j, "x", 1.0), PM_ERR_ARG);
  assert_int_equal(pm_json_end_array(j), PM_ERR_ARG);
  assert_int_equal(pm_json_close(j, true), PM_ERR_ARG);
  assert_false(exists(path));

  /* Missing key in an object; mismatched end. */
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_begin_object(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_bool(j, NULL, false), PM_ERR_ARG);
  assert_int_equal(pm_json_close(j, true), PM_ERR_ARG);
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_begin_object(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_end_array(j), PM_ERR_ARG);
  assert_int_equal(pm_json_close(j, true), PM_ERR_ARG);

  /* Depth limit: 16 levels fine, the 17th fails. */
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  for (int i = 0; i < PM_JSON_MAX_DEPTH; i++)
    assert_int_equal(pm_json_begin_array(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_begin_array(j, NULL), PM_ERR_ARG);
  assert_int_equal(pm_json_close(j, true), PM_ERR_ARG);

  /* Unclosed and empty documents are not committed; two top values fail. */
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_begin_object(j, NULL), PM_SUCCESS);
  assert_int_equal(pm_json_close(j, true), PM_ERR_ARG);
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_close(j, true), PM_ERR_ARG);
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_integer(j, NULL, 1), PM_SUCCESS);
  assert_int_equal(pm_json_integer(j, NULL, 2), PM_ERR_ARG);
  assert_int_equal(pm_json_close(j, false), PM_SUCCESS);
  assert_false(exists(path));
  assert_int_equal(pm_test_count_entries(dir, NULL), 0);

  /* A bare top-level scalar is a valid document. */
  assert_int_equal(pm_json_open(path, &j), PM_SUCCESS);
  assert_int_equal(pm_json_number(j, NULL, 2.5), PM_SUCCESS);
  assert_int_equal(pm_json_close(j, true), PM_SUCCESS);
  pm_test_assert_file(path, "2.5\n");
  pm_error_clear();
}

/* ---- Timers and progress ----------------------------------------------- */

static void test_timers(void **state) {
  (void)state;
  pm_timers t = {0};
  char buf[2048];
  FILE *fp;
  size_t n;
  double t0 = pm_wtime();
  int a = pm_timers_add(&t, "assemble");
  int b = pm_timers_add(&t, "solve");
  assert_int_equal(a, 0);
  assert_int_equal(b, 1);
  assert_int_equal(pm_timers_add(&t, "assemble"), 0);
  for (int i = 0; i < 3; i++) {
    pm_timers_start(&t, a);
    struct timespec ts = {0, 2000000};
    nanosleep(&ts, NULL);
    pm_timers_stop(&t, a);
  }
  pm_timers_stop(&t, b); /* stop without start: ignored */
  pm_timers_start(&t, -1);
  pm_timers_stop(&t, -1);
  assert_int_equal(t.stage[a].calls, 3);
  assert_int_equal(t.stage[b].calls, 0);
  assert_true(pm_timers_seconds(&t, a) >= 0.006);
  assert_true(pm_wtime() - t0 >= pm_timers_seconds(&t, a));

  static const char *names[PM_TIMERS_MAX + 1] = {0};
  static char storage[PM_TIMERS_MAX + 1][16];
  for (int i = 0; i <= PM_TIMERS_MAX; i++) {
    snprintf(storage[i], sizeof storage[i], "s%d", i);
    names[i] = storage[i];
  }
  for (int i = 2; i < PM_TIMERS_MAX; i++)
    assert_int_equal(pm_timers_add(&t, names[i]), i);
  assert_int_equal(pm_timers_add(&t, names[PM_TIMERS_MAX]), -1);

  fp = tmpfile();
  assert_non_null(fp);
  pm_timers_print(&t, fp, 1.0);
  rewind(fp);
  n = fread(buf, 1, sizeof buf - 1, fp);
  buf[n] = '\0';
  fclose(fp);
  assert_non_null(strstr(buf, "stage"));
  assert_non_null(strstr(buf, "assemble"));
  assert_non_null(strstr(buf, "total"));
}

static void test_progress(void **state) {
  (void)state;
  pm_progress p;
  char buf[1024];
  size_t n;
  FILE *fp = tmpfile();
  assert_non_null(fp);

  /* Not a terminal: nothing at all. */
  pm_progress_init(&p, fp, "run");
  assert_false(p.tty);
  pm_progress_update(&p, 0.5, "status");
  pm_progress_finish(&p);
  assert_int_equal(ftell(fp), 0);

  /* Forced terminal: first update draws, the next is rate limited,
   * completion draws, finish ends the line. */
  p.tty = true;
  pm_progress_update(&p, 0.42, "t=0.51 s step 1234");
  pm_progress_update(&p, 0.43, "skipped");
  pm_progress_update(&p, 1.0, "done");
  pm_progress_finish(&p);
  rewind(fp);
  n = fread(buf, 1, sizeof buf - 1, fp);
  buf[n] = '\0';
  fclose(fp);
  assert_non_null(strstr(buf, "\r[run]   42.0%  ETA "));
  assert_non_null(strstr(buf, "t=0.51 s step 1234"));
  assert_null(strstr(buf, "skipped"));
  assert_non_null(strstr(buf, "\r[run]  100.0%  ETA 0:00  done"));
  assert_int_equal(buf[n - 1], '\n');
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_mkdir_p, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_afile_commit_abort, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_bad_directory, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_outdir, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_outdir_race, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_history, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_json, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test_setup_teardown(test_json_misuse, pm_test_make_dir,
                                      pm_test_drop_dir),
      cmocka_unit_test(test_timers),
      cmocka_unit_test(test_progress),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
