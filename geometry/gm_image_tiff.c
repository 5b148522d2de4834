/* gm_image_tiff: images from TIFF stacks (one multi-page file, a list of
 * files or a folder of them, in name order) and TIFF output. */
#include <dirent.h>
#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <tiffio.h>
#include <unistd.h>

#include "gm_image.h"

/* libtiff reports through a handler: its last message, for ours. */
static char tiff_msg[512];

static void tiff_handler(const char *module, const char *fmt, va_list ap) {
  int k = snprintf(tiff_msg, sizeof tiff_msg, "%s: ", module ? module : "");
  if (k < 0 || (size_t)k >= sizeof tiff_msg) k = 0;
  vsnprintf(tiff_msg + k, sizeof tiff_msg - (size_t)k, fmt, ap);
}

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

/* The most bytes of pixels one byte of compressed data can give, by
 * compression: none 1; PackBits 64 (a run of 128 in 2 bytes); deflate
 * 1032 (zlib's bound); LZW's codes of 9 to 12 bits, each at most as long
 * as the table, under 4096; for the others (JPEG, LZMA, ZSTD...) 65536,
 * a bound no real stack nears. */
static uint64_t tiff_ratio(uint16_t compression) {
  switch (compression) {
  case COMPRESSION_NONE: return 1;
  case COMPRESSION_PACKBITS: return 64;
  case COMPRESSION_ADOBE_DEFLATE:
  case COMPRESSION_DEFLATE: return 1032;
  case COMPRESSION_LZW: return 4096;
  default: return 65536;
  }
}

/* Whether the current page's data (its strips' or tiles' bytes) can hold
 * its w x h pixels of `bits`, checked before anything is allocated for
 * them: a page of a few bytes that announces 1e10 pixels is damaged, not
 * an image to make room for.  The strips' bytes count at most the file's
 * size (file_size), and there are no more strips than bytes. */
static bool page_holds(TIFF *t, uint32_t w, uint32_t h, uint16_t bits,
                       uint64_t file_size, char *why, size_t size) {
  uint16_t compression = COMPRESSION_NONE;
  TIFFGetFieldDefaulted(t, TIFFTAG_COMPRESSION, &compression);
  /* In doubles: a hostile page's sizes overflow 64-bit integers. */
  const double need = (double)w * h * (bits / 8);
  const double ratio = (double)tiff_ratio(compression);
  const uint32_t n =
      TIFFIsTiled(t) ? TIFFNumberOfTiles(t) : TIFFNumberOfStrips(t);
  /* The bytes its strips claim, at most the file's. */
  uint64_t bytes = 0;
  if (n <= file_size + 1)
    for (uint32_t k = 0; k < n && bytes < file_size; k++) {
      const uint64_t b = TIFFGetStrileByteCount(t, k);
      bytes = b < file_size - bytes ? bytes + b : file_size;
    }
  const double have = (double)bytes * ratio;
  if (have >= need) return true;
  snprintf(why, size,
           "expected data for %u x %u pixels of %u bits (%.0f bytes), got "
           "%u strips or tiles that hold at most %.0f (compression %u): "
           "truncated or damaged",
           w, h, (unsigned)bits, need, n, have, (unsigned)compression);
  return false;
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
    struct stat st;
    const uint64_t file_size =
        stat(files[f], &st) == 0 ? (uint64_t)st.st_size : 0;
    do {
      uint32_t w = 0, h = 0;
      uint16_t bits = 0;
      char why[256];
      if (!page_format(t, &w, &h, &bits, why, sizeof why)) {
        TIFFClose(t);
        return PM_ERROR(PM_ERR_ARG, "%s: page %ld: %s", files[f], p + 1, why);
      }
      if (!im && !page_holds(t, w, h, bits, file_size, why, sizeof why)) {
        TIFFClose(t);
        return PM_ERROR(PM_ERR_IO, "%s: page %ld: %s", files[f], p + 1, why);
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
