/* fuzz_table: the readers of CSV tables under a fuzzer.  An input is one
 * text file, read as an FE ladder, as an FE lattice, as a load curve's
 * table, as the claimed
 * tolerances of an FE reference folder whose ladder and lattice are valid,
 * and as the history.csv a resumed run cuts back to its checkpoint's
 * rows. */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_file.h"
#include "pm_curve.h"
#include "pm_fe.h"
#include "pm_history_csv.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A valid ladder and lattice: the first rows of cases/fe/f1-compression's. */
static const char ladder[] =
    "N,nodes,dofs,element,h,reaction_x,reaction_y,reaction_z,mean_sed,von_"
    "mises_centre,increments,wall_seconds,ccx_version,model,iterations,cpu_"
    "seconds,work_density,load_fraction,status\n"
    "1,149,298,CPE8R,1,-4834.359,-9.972245e-13,0,106.2621113,875.0611877,12,1."
    "105563647,2.20,whole,33,0.32566,106.3952574,1,converged\n"
    "2,537,1074,CPE8R,0.5,-4784.942,-4.859523e-13,0,105.4714358,865.6092502,12,"
    "1.361684706,2.20,whole,34,1.327344,105.6001587,1,converged\n"
    "4,2033,4066,CPE8R,0.25,-4749.883,-1.439452e-12,0,104.9465197,859.4321527,"
    "12,6.986386015,2.20,whole,39,6.878142,105.0716851,1,converged\n";
static const char lattice[] =
    "x,y,z,u_x,u_y,u_z\n"
    "0.000000000e+00,0.000000000e+00,0.000000000e+00,0.000000000e+00,0."
    "000000000e+00,0.000000000e+00\n"
    "0.000000000e+00,5.000000000e-01,0.000000000e+00,0.000000000e+00,0."
    "000000000e+00,0.000000000e+00\n"
    "0.000000000e+00,1.000000000e+00,0.000000000e+00,0.000000000e+00,0."
    "000000000e+00,0.000000000e+00\n";

static void write_text(const char *name, const char *text) {
  (void)fuzz_file(name, (const uint8_t *)text, strlen(text));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *path = fuzz_file("table.csv", data, size);
  pm_fe_row *rows = NULL;
  int n_rows = 0;
  (void)pm_fe_read_ladder(path, &rows, &n_rows);
  free(rows);
  pm_error_clear();
  long n = 0;
  double *x = NULL, *u = NULL;
  (void)pm_fe_read_lattice(path, &n, &x, &u);
  free(x);
  free(u);
  pm_error_clear();
  pm_curve *c = NULL;
  if (pm_curve_create(path, NULL, &c) == PM_SUCCESS)
    (void)pm_curve_at(c, 0.5 * pm_curve_end(c));
  pm_curve_destroy(c);
  pm_error_clear();
  write_text("fe/ladder.csv", ladder);
  write_text("fe/lattice.csv", lattice);
  (void)fuzz_file("fe/tolerance.csv", data, size);
  pm_fe_reference *r = NULL;
  (void)pm_fe_load(fuzz_path("fe"), &r);
  pm_fe_free(r);
  pm_error_clear();
  static const char *const columns[] = {"time", "step", "wall_seconds"};
  (void)fuzz_file("history.csv", data, size);
  pm_history *h = NULL;
  if (pm_history_open(fuzz_dir(), 3, columns, 2, &h) == PM_SUCCESS)
    (void)pm_history_close(h);
  pm_error_clear();
  fuzz_clear();
  return 0;
}
