/* gm_image: labelled volumetric images from TIFF stacks, raw volumes and
 * point files, TIFF output, and the connected components of the set voxels
 * (see gm_image.h). */
#include "gm_image.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <tiffio.h>
#include <unistd.h>

/* libtiff reports through a handler: its last message, for ours. */
static char tiff_msg[512];

static void tiff_handler(const char *module, const char *fmt, va_list ap) {
  int k = snprintf(tiff_msg, sizeof tiff_msg, "%s: ", module ? module : "");
  if (k < 0 || (size_t)k >= sizeof tiff_msg) k = 0;
  vsnprintf(tiff_msg + k, sizeof tiff_msg - (size_t)k, fmt, ap);
}

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

/* ---- TIFF ---------------------------------------------------------------- */

/* One page's size and depth; false (with the reason in why) when it is not
 * 8- or 16-bit grey of one sample. */
static bool page_format(TIFF *t, uint32_t *w, uint32_t *h, uint16_t *bits,
                        char *why, size_t size) {
  uint16_t spp = 1, photo = PHOTOMETRIC_MINISBLACK, fmt = SAMPLEFORMAT_UINT;
  TIFFGetField(t, TIFFTAG_IMAGEWIDTH, w);
  TIFFGetField(t, TIFFTAG_IMAGELENGTH, h);
  TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, bits);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &fmt);
  TIFFGetField(t, TIFFTAG_PHOTOMETRIC, &photo);
  if (spp != 1 || (*bits != 8 && *bits != 16) || fmt != SAMPLEFORMAT_UINT ||
      (photo != PHOTOMETRIC_MINISBLACK && photo != PHOTOMETRIC_MINISWHITE)) {
    snprintf(why, size,
             "expected 8- or 16-bit unsigned grey of one sample, got %u "
             "sample(s) of %u bits (format %u, photometric %u)",
             (unsigned)spp, (unsigned)*bits, (unsigned)fmt, (unsigned)photo);
    return false;
  }
  return true;
}

/* Page p of t (w x h of `bits`) into dst (w h values), row by row (or tile
 * by tile); false on a read error (tiff_msg says why). */
static bool read_page(TIFF *t, uint32_t w, uint32_t h, uint16_t bits,
                      uint16_t *dst) {
  const size_t bps = bits / 8;
  uint16_t photo = PHOTOMETRIC_MINISBLACK;
  TIFFGetField(t, TIFFTAG_PHOTOMETRIC, &photo);
  const uint16_t top = bits == 8 ? 255 : 65535;
  bool ok = true;
  if (TIFFIsTiled(t)) {
    uint32_t tw = 0, th = 0;
    TIFFGetField(t, TIFFTAG_TILEWIDTH, &tw);
    TIFFGetField(t, TIFFTAG_TILELENGTH, &th);
    unsigned char *buf = _TIFFmalloc(TIFFTileSize(t));
    if (!buf) return false;
    for (uint32_t y0 = 0; ok && y0 < h; y0 += th)
      for (uint32_t x0 = 0; ok && x0 < w; x0 += tw) {
        if (TIFFReadTile(t, buf, x0, y0, 0, 0) < 0) {
          ok = false;
          break;
        }
        for (uint32_t y = y0; y < y0 + th && y < h; y++)
          for (uint32_t x = x0; x < x0 + tw && x < w; x++) {
            size_t k = (size_t)(y - y0) * tw + (x - x0);
            dst[(size_t)y * w + x] =
                bps == 1 ? buf[k] : ((uint16_t *)(void *)buf)[k];
          }
      }
    _TIFFfree(buf);
  } else {
    unsigned char *row = _TIFFmalloc(TIFFScanlineSize(t));
    if (!row) return false;
    for (uint32_t y = 0; y < h; y++) {
      if (TIFFReadScanline(t, row, y, 0) < 0) {
        ok = false;
        break;
      }
      for (uint32_t x = 0; x < w; x++)
        dst[(size_t)y * w + x] =
            bps == 1 ? row[x] : ((uint16_t *)(void *)row)[x];
    }
    _TIFFfree(row);
  }
  if (ok && photo == PHOTOMETRIC_MINISWHITE)
    for (size_t k = 0; k < (size_t)w * h; k++) dst[k] = top - dst[k];
  return ok;
}

/* The pages of files[0..nfiles): count and size (first pass), then their
 * values (second, into im). */
static pm_err tiff_pass(int nfiles, const char *const *files, gm_image *im,
                        long *pages, uint32_t *w0, uint32_t *h0, uint16_t *b0) {
  *pages = 0;
  for (int f = 0; f < nfiles; f++) {
    tiff_msg[0] = '\0';
    TIFF *t = TIFFOpen(files[f], "r");
    PM_CHECK(t, PM_ERR_IO, "%s: cannot read it as a TIFF (%s)", files[f],
             tiff_msg[0] ? tiff_msg : strerror(errno));
    long p = 0, expect = 0;
    do {
      uint32_t w = 0, h = 0;
      uint16_t bits = 0;
      char why[256];
      if (!page_format(t, &w, &h, &bits, why, sizeof why)) {
        TIFFClose(t);
        return PM_ERROR(PM_ERR_ARG, "%s: page %ld: %s", files[f], p + 1, why);
      }
      if (*pages == 0) {
        *w0 = w, *h0 = h, *b0 = bits;
      } else if (w != *w0 || h != *h0 || bits != *b0) {
        TIFFClose(t);
        return PM_ERROR(PM_ERR_ARG,
                        "%s: page %ld: expected %u x %u pixels of %u bits "
                        "like the first page, got %u x %u of %u",
                        files[f], p + 1, *w0, *h0, (unsigned)*b0, w, h,
                        (unsigned)bits);
      }
      if (im &&
          !read_page(t, w, h, bits, im->v + (size_t)*pages * (size_t)w * h)) {
        TIFFClose(t);
        return PM_ERROR(PM_ERR_IO, "%s: page %ld: cannot read it (%s)",
                        files[f], p + 1,
                        tiff_msg[0] ? tiff_msg : "truncated or damaged");
      }
      uint16_t page = 0, total = 0;
      if (TIFFGetField(t, TIFFTAG_PAGENUMBER, &page, &total) && total > 0)
        expect = total;
      (*pages)++;
      p++;
      tiff_msg[0] = '\0';
    } while (TIFFReadDirectory(t));
    TIFFClose(t);
    /* The end of the chain of pages, or a damaged one: libtiff says which
     * only through its handler.  A file that announces its page count
     * (PageNumber) must hold them all. */
    PM_CHECK(!tiff_msg[0], PM_ERR_IO,
             "%s: cannot read page %ld: truncated or damaged (%s)", files[f],
             p + 1, tiff_msg);
    PM_CHECK(expect == 0 || p >= expect, PM_ERR_IO,
             "%s: expected %ld pages (its PageNumber tag), got %ld: truncated",
             files[f], expect, p);
  }
  return PM_SUCCESS;
}

/* tiff_pass with libtiff's messages caught for ours: n the voxels per
 * axis, bits the depth. */
static pm_err tiff_run(int nfiles, const char *const *files, gm_image *im,
                       long n[3], uint16_t *bits) {
  TIFFErrorHandler old_e = TIFFSetErrorHandler(tiff_handler);
  TIFFErrorHandler old_w = TIFFSetWarningHandler(NULL);
  long pages = 0;
  uint32_t w = 0, h = 0;
  pm_err e = tiff_pass(nfiles, files, im, &pages, &w, &h, bits);
  TIFFSetErrorHandler(old_e);
  TIFFSetWarningHandler(old_w);
  n[0] = (long)w;
  n[1] = (long)h;
  n[2] = pages;
  return e;
}

pm_err gm_image_read_tiff(int nfiles, const char *const *files,
                          const double d[3], const double o[3], gm_image *out) {
  PM_CHECK(out && files && nfiles > 0, PM_ERR_ARG,
           "gm_image_read_tiff: no file");
  memset(out, 0, sizeof *out);
  pm_err ret = PM_SUCCESS;
  long n[3];
  uint16_t bits = 0;
  PM_TRY(tiff_run(nfiles, files, NULL, n, &bits));
  PM_TRY(gm_image_alloc(out, n, d, o));
  out->bits = bits;
  PM_TRY(tiff_run(nfiles, files, out, n, &bits));
done:
  if (ret) gm_image_free(out);
  return ret;
}

static bool is_tiff_name(const char *name) {
  const char *dot = strrchr(name, '.');
  return dot && (strcasecmp(dot, ".tif") == 0 || strcasecmp(dot, ".tiff") == 0);
}

static int name_order(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static void free_names(int n, char **names) {
  for (int k = 0; names && k < n; k++) free(names[k]);
  free(names);
}

/* The files of a TIFF source: path itself, or the TIFF files of the folder
 * path in the order of their names.  *files (*n of them) is the caller's
 * (free_names). */
static pm_err tiff_files(const char *path, int *n, char ***files) {
  struct stat st;
  *n = 0;
  *files = NULL;
  pm_err ret = PM_SUCCESS;
  char **names = NULL;
  int count = 0, cap = 0;
  DIR *dir = NULL;
  if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode)) {
    PM_TRY(PM_ALLOC(names, 1, "image file name"));
    names[0] = strdup(path);
    PM_ENSURE(names[0], PM_ERR_MEMORY, "cannot copy %s", path);
    count = 1;
  } else {
    dir = opendir(path);
    PM_ENSURE(dir, PM_ERR_IO, "%s: cannot list the folder (%s)", path,
              strerror(errno));
    for (struct dirent *e; (e = readdir(dir));) {
      if (!is_tiff_name(e->d_name)) continue;
      if (count == cap) {
        cap = cap ? 2 * cap : 64;
        char **grown = realloc(names, (size_t)cap * sizeof *names);
        PM_ENSURE(grown, PM_ERR_MEMORY, "%s: cannot list the folder", path);
        names = grown;
      }
      size_t len = strlen(path) + 1 + strlen(e->d_name) + 1;
      names[count] = malloc(len);
      PM_ENSURE(names[count], PM_ERR_MEMORY, "%s: cannot list the folder",
                path);
      snprintf(names[count++], len, "%s/%s", path, e->d_name);
    }
    PM_ENSURE(count > 0, PM_ERR_IO,
              "%s: expected a folder of TIFF files (*.tif, *.tiff), found "
              "none",
              path);
    qsort(names, (size_t)count, sizeof *names, name_order);
  }
  *n = count;
  *files = names;
  names = NULL;
done:
  if (dir) closedir(dir);
  if (ret) free_names(count, names);
  return ret;
}

pm_err gm_image_read_tiff_path(const char *path, const double d[3],
                               const double o[3], gm_image *out) {
  PM_CHECK(out && path, PM_ERR_ARG, "gm_image_read_tiff_path: no path");
  memset(out, 0, sizeof *out);
  int n = 0;
  char **files = NULL;
  PM_CALL(tiff_files(path, &n, &files));
  pm_err e = gm_image_read_tiff(n, (const char *const *)files, d, o, out);
  free_names(n, files);
  return e;
}

pm_err gm_image_tiff_size(const char *path, long n[3]) {
  PM_CHECK(path && n, PM_ERR_ARG, "gm_image_tiff_size: no path");
  int nf = 0;
  char **files = NULL;
  uint16_t bits = 0;
  PM_CALL(tiff_files(path, &nf, &files));
  pm_err e = tiff_run(nf, (const char *const *)files, NULL, n, &bits);
  free_names(nf, files);
  return e;
}

pm_err gm_image_write_tiff(const gm_image *im, const char *file) {
  PM_CHECK(im && im->v && file, PM_ERR_ARG, "gm_image_write_tiff: no image");
  const size_t nv = (size_t)im->n[0] * im->n[1] * im->n[2];
  uint16_t bits = 8;
  for (size_t k = 0; k < nv; k++)
    if (im->v[k] > 255) bits = 16;
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp-%ld", file, (long)getpid());
  TIFFErrorHandler old_e = TIFFSetErrorHandler(tiff_handler);
  tiff_msg[0] = '\0';
  TIFF *t = TIFFOpen(tmp, "w");
  pm_err ret = PM_SUCCESS;
  unsigned char *row = NULL;
  PM_ENSURE(t, PM_ERR_IO, "%s: cannot write it (%s)", tmp,
            tiff_msg[0] ? tiff_msg : strerror(errno));
  PM_TRY(PM_ALLOC(row, (size_t)im->n[0] * 2, "image row"));
  for (long z = 0; z < im->n[2]; z++) {
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, (uint32_t)im->n[0]);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, (uint32_t)im->n[1]);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, bits);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, (uint16_t)1);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(t, 0));
    TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
    TIFFSetField(t, TIFFTAG_PAGENUMBER, (uint16_t)z, (uint16_t)im->n[2]);
    for (long y = 0; y < im->n[1]; y++) {
      const uint16_t *src = im->v + (size_t)im->n[0] * (y + im->n[1] * z);
      for (long x = 0; x < im->n[0]; x++) {
        if (bits == 8)
          row[x] = (unsigned char)src[x];
        else
          ((uint16_t *)(void *)row)[x] = src[x];
      }
      PM_ENSURE(TIFFWriteScanline(t, row, (uint32_t)y, 0) >= 0, PM_ERR_IO,
                "%s: cannot write row %ld of page %ld (%s)", tmp, y, z + 1,
                tiff_msg);
    }
    PM_ENSURE(TIFFWriteDirectory(t), PM_ERR_IO,
              "%s: cannot write page %ld (%s)", tmp, z + 1, tiff_msg);
  }
  TIFFClose(t);
  t = NULL;
  PM_ENSURE(rename(tmp, file) == 0, PM_ERR_IO,
            "%s: cannot rename %s to it (%s)", file, tmp, strerror(errno));
done:
  if (t) TIFFClose(t);
  if (ret) unlink(tmp);
  free(row);
  TIFFSetErrorHandler(old_e);
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
  char line[1024];
  long ln = 0;
  PM_ENSURE(f, PM_ERR_IO, "%s: cannot open it (%s)", file, strerror(errno));
  PM_TRY(gm_image_alloc(out, n, d, o));
  out->bits = 8;
  while (fgets(line, sizeof line, f)) {
    ln++;
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
  if (ret) gm_image_free(out);
  return ret;
}

/* ---- an image body's voxels ---------------------------------------------- */

bool gm_image_part_contains(const gm_image_part *p, int dim,
                            const double x[3]) {
  const gm_image *im = p->im;
  long idx[3] = {0, 0, p->lo[2]};
  for (int c = 0; c < dim; c++) {
    double u = floor((x[c] - im->o[c]) / im->d[c]);
    if (!(u >= (double)p->lo[c] && u < (double)p->hi[c])) return false;
    idx[c] = (long)u;
  }
  uint16_t v = gm_image_at(im, idx[0], idx[1], idx[2]);
  return v >= p->label[0] && v <= p->label[1];
}

long gm_image_part_voxels(const gm_image_part *p) {
  return gm_image_seeds(p, 3, 1, NULL, NULL);
}

void gm_image_part_box(const gm_image_part *p, int dim, double lo[3],
                       double hi[3]) {
  for (int c = 0; c < 3; c++) {
    lo[c] = c < dim ? p->im->o[c] + (double)p->lo[c] * p->im->d[c] : 0;
    hi[c] = c < dim ? p->im->o[c] + (double)p->hi[c] * p->im->d[c] : 0;
  }
}

long gm_image_seeds(const gm_image_part *p, int dim, int n, gm_image_seed_fn fn,
                    void *ctx) {
  const gm_image *im = p->im;
  const int nz = dim == 3 ? n : 1;
  double vol = 1;
  for (int c = 0; c < dim; c++) vol *= im->d[c] / n;
  long count = 0;
  for (long k = p->lo[2]; k < p->hi[2]; k++)
    for (long j = p->lo[1]; j < p->hi[1]; j++)
      for (long i = p->lo[0]; i < p->hi[0]; i++) {
        uint16_t v = gm_image_at(im, i, j, k);
        if (v < p->label[0] || v > p->label[1]) continue;
        count += (long)n * n * nz;
        if (!fn) continue;
        const long idx[3] = {i, j, k};
        for (int s2 = 0; s2 < nz; s2++)
          for (int s1 = 0; s1 < n; s1++)
            for (int s0 = 0; s0 < n; s0++) {
              const int sub[3] = {s0, s1, s2};
              double x[3] = {0, 0, 0};
              for (int c = 0; c < dim; c++)
                x[c] =
                    im->o[c] + ((double)idx[c] + (sub[c] + 0.5) / n) * im->d[c];
              fn(ctx, x, vol);
            }
      }
  return count;
}

/* Voxel size, corner and size in voxels of image body b (z: 1 m, 0 and 1
 * voxel when not given). */
static void body_frame(const pm_scene_body *b, double d[3], double o[3],
                       long n[3]) {
  for (int c = 0; c < 3; c++) {
    d[c] = c < b->image.n_voxel ? b->image.voxel[c] : 1;
    o[c] = c < b->image.n_origin ? b->image.origin[c] : 0;
    n[c] = c < b->image.n_size ? (long)b->image.size[c] : 1;
  }
}

const char *gm_image_source_key(const pm_scene_body *b) {
  static const char *const keys[] = {[PM_IMAGE_TIFF] = "file",
                                     [PM_IMAGE_RAW] = "raw",
                                     [PM_IMAGE_POINTS] = "points"};
  return keys[b->image.source];
}

pm_err gm_image_of_body(const pm_scene_body *b, gm_image *out) {
  PM_CHECK(b && out && b->image.file, PM_ERR_ARG,
           "gm_image_of_body: no image body");
  double d[3], o[3];
  long n[3];
  body_frame(b, d, o, n);
  switch (b->image.source) {
  case PM_IMAGE_RAW:
    return gm_image_read_raw(b->image.file, n, b->image.bits, d, o, out);
  case PM_IMAGE_POINTS:
    return gm_image_read_points(b->image.file, b->image.unit, n, d, o, out);
  default: return gm_image_read_tiff_path(b->image.file, d, o, out);
  }
}

bool gm_image_same_source(const pm_scene_body *a, const pm_scene_body *b) {
  if (a->image.source != b->image.source || !a->image.file || !b->image.file ||
      strcmp(a->image.file, b->image.file) != 0)
    return false;
  double da[3], oa[3], db[3], ob[3];
  long na[3], nb[3];
  body_frame(a, da, oa, na);
  body_frame(b, db, ob, nb);
  for (int c = 0; c < 3; c++)
    if (da[c] != db[c] || oa[c] != ob[c] || na[c] != nb[c]) return false;
  return a->image.bits == b->image.bits && a->image.unit == b->image.unit;
}

pm_err gm_image_body_size(const pm_scene_body *b, long n[3]) {
  PM_CHECK(b && n && b->image.file, PM_ERR_ARG,
           "gm_image_body_size: no image body");
  if (b->image.source == PM_IMAGE_TIFF)
    return gm_image_tiff_size(b->image.file, n);
  double d[3], o[3];
  body_frame(b, d, o, n);
  return PM_SUCCESS;
}

pm_err gm_image_body_part(const gm_image *im, const pm_scene_body *b, int dim,
                          gm_image_part *out, const char **key) {
  PM_CHECK(im && b && out && key, PM_ERR_ARG, "gm_image_body_part: NULL");
  memset(out, 0, sizeof *out);
  const int nc = b->image.n_crop_min;
  *key = gm_image_source_key(b);
  out->im = im;
  for (int c = 0; c < 3; c++) {
    out->lo[c] = c < nc ? (long)b->image.crop_min[c] : 0;
    out->hi[c] = c < nc ? (long)b->image.crop_max[c] : im->n[c];
    if (out->hi[c] > im->n[c]) {
      *key = "crop.max";
      return PM_ERROR(PM_ERR_ARG,
                      "expected a crop inside the image (%ld x %ld x %ld "
                      "voxels of %s), got max.%d = %ld",
                      im->n[0], im->n[1], im->n[2], b->image.file, c,
                      out->hi[c]);
    }
  }
  if (dim == 2 && out->hi[2] - out->lo[2] != 1) {
    if (nc == 3) *key = "crop.max";
    return PM_ERROR(PM_ERR_ARG,
                    "expected an image of one slice for dimension 2 (or a "
                    "crop of one: crop: {min: [i0, j0, k], max: [i1, j1, k + "
                    "1]}), got %ld slices of %s",
                    out->hi[2] - out->lo[2], b->image.file);
  }
  out->label[0] = (uint16_t)b->image.label[0];
  out->label[1] = (uint16_t)b->image.label[1];
  return PM_SUCCESS;
}
