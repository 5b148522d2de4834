/* gm_image: labelled volumetric images (confocal stacks of vessels in a gel)
 * for seeding particles, one or n^d per voxel.  A volume is nx x ny x nz
 * voxels of size dx x dy x dz, x fastest, each an intensity of 8 or 16
 * bits, kept as 16-bit integers (a 512 x 512 x 52 stack takes 27 MB, not
 * the 109 MB of doubles).  Three sources:
 *   - TIFF, one file of nz pages or a list of files of one page each
 *     (libtiff; 8- or 16-bit grey, strips or tiles), read a row at a time;
 *   - raw: nx ny nz values of 8 or 16 bits (little-endian), x fastest;
 *   - a point file: one voxel centre per line (x y [z], in the voxel size's
 *     unit), intensity 255 there and 0 elsewhere in the given box.
 * Every failure names the file and what was expected, and leaves *out
 * empty. */
#ifndef GM_IMAGE_H
#define GM_IMAGE_H

#include <stdint.h>

#include "pm_error.h"

typedef struct {
  long n[3];   /* voxels per axis (n[2] = 1 for a 2-D image) */
  double d[3]; /* voxel size, m */
  double o[3]; /* position of the corner of voxel (0, 0, 0), m */
  uint16_t *v; /* n[0] n[1] n[2] intensities, x fastest */
  int bits;    /* 8 or 16: the source's */
} gm_image;

/* A TIFF stack: nfiles files read in order, each of one or more pages,
 * every page of the same width, height and depth.  d: the voxel size (3
 * components), o: the corner.  PM_ERR_IO (a file that does not open or is
 * truncated, naming it and the page), PM_ERR_ARG (pages of different sizes,
 * a format other than 8/16-bit grey), PM_ERR_MEMORY. */
pm_err gm_image_read_tiff(int nfiles, const char *const *files,
                          const double d[3], const double o[3], gm_image *out);

/* A raw volume of n[0] n[1] n[2] values of `bits` (8 or 16, little-endian)
 * bits.  PM_ERR_IO (a file shorter or longer than that: both sizes in the
 * message), PM_ERR_ARG, PM_ERR_MEMORY. */
pm_err gm_image_read_raw(const char *file, const long n[3], int bits,
                         const double d[3], const double o[3], gm_image *out);

/* A point file of voxel centres (x y, or x y z; '#' comments), in metres
 * after multiplying by `unit` (1e-6 for micrometres), on the n[0] x n[1] x
 * n[2] grid of voxel size d and corner o: each centre's voxel gets 255, the
 * others 0.  PM_ERR_SCENE with FILE:LINE:COL for a bad line or a centre
 * off the grid (more than 1e-3 voxel from a voxel centre, or outside),
 * PM_ERR_IO, PM_ERR_MEMORY. */
pm_err gm_image_read_points(const char *file, double unit, const long n[3],
                            const double d[3], const double o[3],
                            gm_image *out);

/* Write an image as a multi-page TIFF (one page per z; 8 bits when every
 * value fits, else 16; deflate-compressed), atomically (a temporary file
 * renamed).  PM_ERR_IO. */
pm_err gm_image_write_tiff(const gm_image *im, const char *file);

/* A new image of n voxels of size d with corner o (NULL: 0), every value
 * 0, bits unset.  PM_ERR_ARG (a size or voxel size not positive),
 * PM_ERR_MEMORY; on failure *im is empty. */
pm_err gm_image_alloc(gm_image *im, const long n[3], const double d[3],
                      const double o[3]);

/* The 6-connected components of the nonzero voxels of im: their number and
 * the voxel count of the largest (both 0 when no voxel is set).
 * PM_ERR_MEMORY. */
pm_err gm_image_components(const gm_image *im, long *components, long *largest);

/* The intensity at voxel (i, j, k). */
static inline uint16_t gm_image_at(const gm_image *im, long i, long j, long k) {
  return im->v[i + im->n[0] * (j + im->n[1] * k)];
}

void gm_image_free(gm_image *im);

#endif
