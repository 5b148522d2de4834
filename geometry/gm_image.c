/* gm_image: labelled volumetric images: their storage, raw volumes and
 * point files read into them, and the connected components of the set
 * voxels (see gm_image.h; TIFF in gm_image_tiff.c, bodies in
 * gm_image_body.c). */
#include "gm_image.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void gm_image_free(gm_image *im) {
  if (!im) return;
  free(im->v);
  memset(im, 0, sizeof *im);
}

pm_err gm_image_alloc(gm_image *im, const long n[3], const double d[3],
                      const double o[3]) {
  memset(im, 0, sizeof *im);
  for (int c = 0; c < 3; c++) {
    PM_CHECK(n[c] > 0, PM_ERR_ARG,
             "image: expected a positive size along %c, got %ld", "xyz"[c],
             n[c]);
    PM_CHECK(d[c] > 0 && isfinite(d[c]), PM_ERR_ARG,
             "image: expected a positive voxel size along %c, got %g", "xyz"[c],
             d[c]);
    im->n[c] = n[c];
    im->d[c] = d[c];
    im->o[c] = o ? o[c] : 0;
  }
  return PM_ALLOC(im->v, n[0] * n[1] * n[2], "image voxels");
}

/* ---- connected components ------------------------------------------------ */

static bool seen_bit(const unsigned char *bits, long q) {
  return bits[q >> 3] & (1u << (q & 7));
}

static void mark_bit(unsigned char *bits, long q) {
  bits[q >> 3] |= (unsigned char)(1u << (q & 7));
}

pm_err gm_image_components(const gm_image *im, long *components,
                           long *largest) {
  *components = *largest = 0;
  const long nx = im->n[0], ny = im->n[1], nz = im->n[2];
  const long nv = nx * ny * nz;
  long set = 0;
  for (long q = 0; q < nv; q++) set += im->v[q] != 0;
  if (set == 0) return PM_SUCCESS;
  pm_err ret = PM_SUCCESS;
  unsigned char *seen = NULL; /* a bit per voxel */
  long *stack = NULL;         /* each set voxel enters it once */
  PM_TRY(PM_ALLOC(seen, nv / 8 + 1, "voxel marks"));
  PM_TRY(PM_ALLOC(stack, set, "flood-fill stack"));
  for (long q0 = 0; q0 < nv; q0++) {
    if (!im->v[q0] || seen_bit(seen, q0)) continue;
    long top = 0, size = 0;
    mark_bit(seen, q0);
    stack[top++] = q0;
    while (top > 0) {
      const long q = stack[--top];
      size++;
      const long i = q % nx, j = (q / nx) % ny, k = q / (nx * ny);
      const long nb[6] = {
          i > 0 ? q - 1 : -1,       i < nx - 1 ? q + 1 : -1,
          j > 0 ? q - nx : -1,      j < ny - 1 ? q + nx : -1,
          k > 0 ? q - nx * ny : -1, k < nz - 1 ? q + nx * ny : -1};
      for (int m = 0; m < 6; m++) {
        const long p = nb[m];
        if (p < 0 || !im->v[p] || seen_bit(seen, p)) continue;
        mark_bit(seen, p);
        stack[top++] = p;
      }
    }
    (*components)++;
    if (size > *largest) *largest = size;
  }
done:
  free(seen);
  free(stack);
  return ret;
}

/* ---- raw ----------------------------------------------------------------- */

pm_err gm_image_read_raw(const char *file, const long n[3], int bits,
                         const double d[3], const double o[3], gm_image *out) {
  PM_CHECK(out && file, PM_ERR_ARG, "gm_image_read_raw: no file");
  memset(out, 0, sizeof *out);
  PM_CHECK(bits == 8 || bits == 16, PM_ERR_ARG,
           "%s: expected 8 or 16 bits per voxel, got %d", file, bits);
  pm_err ret = PM_SUCCESS;
  FILE *f = fopen(file, "rb");
  unsigned char *buf = NULL;
  PM_ENSURE(f, PM_ERR_IO, "%s: cannot open it (%s)", file, strerror(errno));
  PM_TRY(gm_image_alloc(out, n, d, o));
  out->bits = bits;
  const size_t bytes = (size_t)bits / 8, nx = (size_t)n[0];
  const size_t want = nx * n[1] * n[2] * bytes;
  fseek(f, 0, SEEK_END);
  long have = ftell(f);
  fseek(f, 0, SEEK_SET);
  PM_ENSURE(have >= 0 && (size_t)have == want, PM_ERR_IO,
            "%s: expected %zu bytes (%ld x %ld x %ld voxels of %d bits), "
            "got %ld",
            file, want, n[0], n[1], n[2], bits, have);
  PM_TRY(PM_ALLOC(buf, nx * bytes, "image row"));
  for (long r = 0; r < n[1] * n[2]; r++) {
    PM_ENSURE(fread(buf, bytes, nx, f) == nx, PM_ERR_IO,
              "%s: cannot read row %ld (%s)", file, r, strerror(errno));
    for (size_t x = 0; x < nx; x++)
      out->v[(size_t)r * nx + x] =
          bytes == 1 ? buf[x] : (uint16_t)(buf[2 * x] | buf[2 * x + 1] << 8);
  }
done:
  if (f) fclose(f);
  free(buf);
  if (ret) gm_image_free(out);
  return ret;
}

/* ---- point files --------------------------------------------------------- */

pm_err gm_image_read_points(const char *file, double unit, const long n[3],
                            const double d[3], const double o[3],
                            gm_image *out) {
  PM_CHECK(out && file, PM_ERR_ARG, "gm_image_read_points: no file");
  memset(out, 0, sizeof *out);
  pm_err ret = PM_SUCCESS;
  FILE *f = fopen(file, "r");
  char *line = NULL;
  size_t cap = 0;
  ssize_t len;
  long ln = 0;
  PM_ENSURE(f, PM_ERR_IO, "%s: cannot open it (%s)", file, strerror(errno));
  PM_TRY(gm_image_alloc(out, n, d, o));
  out->bits = 8;
  /* Whole lines, however long: a fixed buffer would read the rest of a
   * long line as a line of its own. */
  while ((len = getline(&line, &cap, f)) >= 0) {
    ln++;
    const size_t text = strlen(line);
    PM_ENSURE(text == (size_t)len, PM_ERR_SCENE,
              "%s:%ld:%zu: expected text, got a NUL byte (a binary file?)",
              file, ln, text + 1);
    char *hash = strchr(line, '#');
    if (hash) *hash = '\0';
    double x[3] = {0, 0, 0};
    char *p = line, *end;
    int got = 0;
    while (got < 3) {
      while (*p == ' ' || *p == '\t' || *p == ',') p++;
      if (*p == '\0' || *p == '\n' || *p == '\r') break;
      x[got] = strtod(p, &end);
      PM_ENSURE(end != p && isfinite(x[got]), PM_ERR_SCENE,
                "%s:%ld:%ld: expected a number (x y [z]), got '%.20s'", file,
                ln, (long)(p - line) + 1, p);
      p = end;
      got++;
    }
    if (got == 0) continue;
    PM_ENSURE(got >= 2, PM_ERR_SCENE,
              "%s:%ld:1: expected 2 or 3 coordinates, got %d", file, ln, got);
    long idx[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++) {
      if (c >= got) continue;
      double u = (x[c] * unit - out->o[c]) / out->d[c] - 0.5;
      long i = lround(u);
      PM_ENSURE(fabs(u - (double)i) <= 1e-3 && i >= 0 && i < n[c], PM_ERR_SCENE,
                "%s:%ld:1: expected a voxel centre on the %ld x %ld x %ld "
                "grid of voxels of %g m from (%g, %g, %g) m, got %c = %g",
                file, ln, n[0], n[1], n[2], out->d[c], out->o[0], out->o[1],
                out->o[2], "xyz"[c], x[c]);
      idx[c] = i;
    }
    out->v[idx[0] + n[0] * (idx[1] + n[1] * idx[2])] = 255;
  }
  PM_ENSURE(!ferror(f), PM_ERR_IO, "%s: read error (%s)", file,
            strerror(errno));
done:
  if (f) fclose(f);
  free(line);
  if (ret) gm_image_free(out);
  return ret;
}
