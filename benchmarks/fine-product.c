/* fine-product: the product multigrid's finest level takes four or five
 * times a V-cycle in FPM's static solve (src/common/solve/pm_newton_fine.c),
 * on a matrix the shape of F3 60%'s tangent at 13762 points: 12183 points
 * of three unknowns, each row coupled to all three unknowns of 232 nearby
 * points (696 entries a row, 25.4 million in all).  Five storages, each
 * timed over 50 products on the threads OMP_NUM_THREADS gives, three
 * rounds in turn:
 *   double          CSR, rows in threes sharing one pass over their columns
 *   single          the same, the values in single precision
 *   double simd     double, the sums over vector lanes (omp simd)
 *   single simd     single, the sums over vector lanes
 *   single blocks   3 x 3 blocks of single precision, one index a block
 * Every sum is in double.  It prints the milliseconds a product and the
 * bytes it reads an entry.
 * cc -O3 -march=x86-64-v3 -ffp-contract=off -fopenmp \
 *   benchmarks/fine-product.c -o fine-product && ./fine-product */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

enum { POINTS = 12183, NEAR = 232, PRODUCTS = 50 };

#define ROWS3(NAME, T, SIMD)                                                   \
  static void NAME(int n, const int *ia, const int *ja, const T *a,            \
                   const double *x, double *y) {                               \
    _Pragma("omp parallel for schedule(static)") for (int b = 0; b < n / 3;    \
                                                      b++) {                   \
      const int i = 3 * b, k0 = ia[i], len = ia[i + 1] - k0;                   \
      const T *a0 = a + k0, *a1 = a + ia[i + 1], *a2 = a + ia[i + 2];          \
      const int *j = ja + k0;                                                  \
      double y0 = 0, y1 = 0, y2 = 0;                                           \
      SIMD for (int k = 0; k < len; k++) {                                     \
        const double xj = x[j[k]];                                             \
        y0 += (double)a0[k] * xj;                                              \
        y1 += (double)a1[k] * xj;                                              \
        y2 += (double)a2[k] * xj;                                              \
      }                                                                        \
      y[i] = y0;                                                               \
      y[i + 1] = y1;                                                           \
      y[i + 2] = y2;                                                           \
    }                                                                          \
  }
ROWS3(rows_double, double, )
ROWS3(rows_single, float, )
ROWS3(rows_double_simd, double, _Pragma("omp simd reduction(+ : y0, y1, y2)"))
ROWS3(rows_single_simd, float, _Pragma("omp simd reduction(+ : y0, y1, y2)"))

static void blocks_single(int nb, const int *ib, const int *jb, const float *a,
                          const double *x, double *y) {
#pragma omp parallel for schedule(static)
  for (int b = 0; b < nb; b++) {
    double y0 = 0, y1 = 0, y2 = 0;
#pragma omp simd reduction(+ : y0, y1, y2)
    for (int k = ib[b]; k < ib[b + 1]; k++) {
      const float *v = a + 9 * (long)k;
      const double *xc = x + 3 * (long)jb[k];
      y0 += (double)v[0] * xc[0] + (double)v[1] * xc[1] + (double)v[2] * xc[2];
      y1 += (double)v[3] * xc[0] + (double)v[4] * xc[1] + (double)v[5] * xc[2];
      y2 += (double)v[6] * xc[0] + (double)v[7] * xc[1] + (double)v[8] * xc[2];
    }
    y[3 * b] = y0;
    y[3 * b + 1] = y1;
    y[3 * b + 2] = y2;
  }
}

int main(void) {
  const int n = 3 * POINTS;
  const long nnz = (long)n * NEAR * 3, blocks = (long)POINTS * NEAR;
  int *ia = malloc((n + 1) * sizeof *ia), *ja = malloc(nnz * sizeof *ja);
  int *ib = malloc((POINTS + 1) * sizeof *ib),
      *jb = malloc(blocks * sizeof *jb);
  double *ad = malloc(nnz * sizeof *ad), *x = malloc(n * sizeof *x),
         *y = malloc(n * sizeof *y);
  float *as = malloc(nnz * sizeof *as), *ab = malloc(nnz * sizeof *ab);
  if (!ia || !ja || !ib || !jb || !ad || !x || !y || !as || !ab) return 1;
  srand(1);
  ia[0] = ib[0] = 0;
  for (int p = 0; p < POINTS; p++) {
    /* NEAR points from about NEAR before p, in order, one or two apart
     * (a cloud numbered along a curve: neighbours near in number) */
    int q = p - NEAR < 0 ? 0 : p - NEAR, *near = jb + (long)p * NEAR;
    for (int c = 0; c < NEAR; c++) {
      q += 1 + rand() % 2;
      near[c] = q % POINTS;
    }
    for (int u = 1; u < NEAR; u++) /* (wrapped ones sorted to the front) */
      for (int w = u; w > 0 && near[w - 1] > near[w]; w--) {
        const int t = near[w];
        near[w] = near[w - 1];
        near[w - 1] = t;
      }
    ib[p + 1] = ib[p] + NEAR;
    for (int r = 0; r < 3; r++) {
      const int i = 3 * p + r;
      ia[i + 1] = ia[i] + 3 * NEAR;
      for (int c = 0; c < NEAR; c++)
        for (int d = 0; d < 3; d++) ja[ia[i] + 3 * c + d] = 3 * near[c] + d;
    }
  }
  for (long k = 0; k < nnz; k++) {
    ad[k] = rand() / (double)RAND_MAX - 0.5;
    as[k] = (float)ad[k];
  }
  for (int p = 0; p < POINTS; p++)
    for (int c = 0; c < NEAR; c++)
      for (int r = 0; r < 3; r++)
        for (int d = 0; d < 3; d++)
          ab[9 * ((long)p * NEAR + c) + 3 * r + d] =
              as[ia[3 * p + r] + 3 * c + d];
  for (int i = 0; i < n; i++) x[i] = rand() / (double)RAND_MAX;
  printf("%d unknowns, %ld entries, %d threads; ms a product (median of "
         "3 rounds of %d)\n",
         n, nnz, omp_get_max_threads(), PRODUCTS);
  static const char *name[5] = {"double", "single", "double simd",
                                "single simd", "single blocks"};
  static const double bytes[5] = {8 + 4.0 / 3, 4 + 4.0 / 3, 8 + 4.0 / 3,
                                  4 + 4.0 / 3, 4 + 4.0 / 9};
  double ms[5][3];
  for (int round = 0; round < 3; round++)
    for (int v = 0; v < 5; v++) {
      const double t = omp_get_wtime();
      for (int r = 0; r < PRODUCTS; r++) switch (v) {
        case 0: rows_double(n, ia, ja, ad, x, y); break;
        case 1: rows_single(n, ia, ja, as, x, y); break;
        case 2: rows_double_simd(n, ia, ja, ad, x, y); break;
        case 3: rows_single_simd(n, ia, ja, as, x, y); break;
        default: blocks_single(POINTS, ib, jb, ab, x, y); break;
        }
      ms[v][round] = (omp_get_wtime() - t) / PRODUCTS * 1e3;
    }
  printf("| storage | bytes an entry | ms a product | rounds "
         "|\n|---|---|---|---|\n");
  for (int v = 0; v < 5; v++) {
    double a = ms[v][0], b = ms[v][1], c = ms[v][2];
    const double med =
        a > b ? (b > c ? b : (a > c ? c : a)) : (a > c ? a : (b > c ? c : b));
    printf("| %s | %.2f | %.2f | %.2f, %.2f, %.2f |\n", name[v], bytes[v], med,
           a, b, c);
  }
  free(ia), free(ja), free(ib), free(jb), free(ad), free(x), free(y);
  free(as), free(ab);
  return 0;
}
