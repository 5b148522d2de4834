/* gm_image_body: a scene's image body: its image read from the source it
 * names, its part (the voxels of its labels in its crop), and the seeds,
 * box and inside test of that part. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "gm_image.h"

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
