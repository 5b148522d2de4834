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
 * empty.  Below the readers: the part of an image a scene body takes (a
 * crop and an intensity range), its voxels as a shape and as seeds. */
#ifndef GM_IMAGE_H
#define GM_IMAGE_H

#include <stdbool.h>
#include <stdint.h>

#include "pm_error.h"
#include "pm_scene.h"

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

/* A TIFF source given by path: the file itself, or, when path is a
 * folder, its files named *.tif or *.tiff (any case) in strcmp order of
 * their names, each of one or more pages (as gm_image_read_tiff).
 * PM_ERR_IO (a folder without TIFF files, naming it), and
 * gm_image_read_tiff's errors. */
pm_err gm_image_read_tiff_path(const char *path, const double d[3],
                               const double o[3], gm_image *out);

/* The size in voxels of the TIFF source at path (a file or a folder, as
 * gm_image_read_tiff_path), from the pages' headers, without reading a
 * voxel.  PM_ERR_IO, PM_ERR_ARG as gm_image_read_tiff. */
pm_err gm_image_tiff_size(const char *path, long n[3]);

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

/* ---- an image body's voxels ---------------------------------------------
 * A part of an image: the voxels of the crop [lo, hi) (indices per axis)
 * whose intensity lies in [label[0], label[1]].  Voxel (i, j, k) spans
 * [o + i d, o + (i + 1) d) along each axis (upper faces out).  In a 2-D
 * problem the crop is one slice (hi[2] = lo[2] + 1) and z does not count.
 * im is borrowed. */
typedef struct {
  const gm_image *im;
  long lo[3], hi[3];
  uint16_t label[2];
} gm_image_part;

/* Whether x (3 components) lies in a voxel of p, in dimension dim. */
bool gm_image_part_contains(const gm_image_part *p, int dim, const double x[3]);

/* The number of voxels of p. */
long gm_image_part_voxels(const gm_image_part *p);

/* The box of p's crop in space: [lo, hi] (components beyond dim 0). */
void gm_image_part_box(const gm_image_part *p, int dim, double lo[3],
                       double hi[3]);

/* Seeds of a part: fn(ctx, x, vol) at each of the n^dim sub-voxel centres
 * of every voxel of p, voxels in order (x fastest, then y, then z) and
 * within a voxel likewise; vol is the voxel's volume over n^dim (in 2D its
 * area over n^2, per unit depth, and z = 0).  Returns how many. */
typedef void (*gm_image_seed_fn)(void *ctx, const double x[3], double vol);
long gm_image_seeds(const gm_image_part *p, int dim, int n, gm_image_seed_fn fn,
                    void *ctx);

/* The image of image body b (pm_scene_body.image: its source, voxel size
 * and origin; a voxel size or origin of 2 numbers (2D) takes z = 1 m and
 * 0).  The errors of the source's reader, which name the file. */
pm_err gm_image_of_body(const pm_scene_body *b, gm_image *out);

/* Whether image bodies a and b read the same image (source, file and how
 * it is read, voxel size and origin): one gm_image_of_body serves both. */
bool gm_image_same_source(const pm_scene_body *a, const pm_scene_body *b);

/* The size in voxels of image body b's image, without reading its voxels
 * (a TIFF's headers; the size a raw volume or point file is given). */
pm_err gm_image_body_size(const pm_scene_body *b, long n[3]);

/* The part of im that image body b takes: its crop (the whole image when
 * it gives none) and label.  PM_ERR_ARG when the crop reaches past the
 * image, or, in dimension 2, holds more than one slice; *key is then the
 * key of b's image at fault ("crop.max", or the source: "file", "raw",
 * "points") and the message says what was expected. */
pm_err gm_image_body_part(const gm_image *im, const pm_scene_body *b, int dim,
                          gm_image_part *out, const char **key);

/* The scene's key of image body b's source: "file", "raw" or "points". */
const char *gm_image_source_key(const pm_scene_body *b);

#endif
