/* fpm_region: a rank's share of an FPM model made without the whole model.
 * Rank 0 alone meshes the domain and builds its cells (the cheap geometry:
 * the points, their supports and the interfaces' and facets' shapes), and
 * cuts from them each rank's part: its own points and the rings around
 * them, in one-process order (fpm_part), which it sends to that rank
 * (fpm_part_pack, fpm_par.h).  The operators (GFD weights, interface
 * records, quadratic fits, averaging weights, boundary flux) are computed
 * on the part only (fpm_model_create_part): the whole model's on every
 * point the share holds, so that the share made of it (fpm_share_create)
 * is the share cut from the whole model, bit for bit.
 *
 * The share holds its own points and 3 rings of support around them, 5
 * with the quadratic jump (fpm_share.h); the part holds one ring more with
 * its rows (the fits over two rings and the averaging weights of the
 * share's outer ring read them) and one more without (the neighbours of
 * those rows). */
#ifndef FPM_REGION_H
#define FPM_REGION_H

#include <stddef.h>

#include "fpm_model.h"
#include "gm_mesh.h"

/* Rank r's part of the whole cells: all a rank needs of them to build its
 * share. */
typedef struct {
  gm_dual *cells; /* the part's cells, its points in one-process order:
                     rows where they are held, none at the part's edge */
  long *gid;      /* [cells->n_points] each point's index in the whole */
  int *owner;     /* [n_points] each point's rank */
  long *index;    /* [n_points] each point's index among its owner's own
                     points (where the ghosts' values come from) */
  int n_bcs;      /* the scene's conditions */
  long *tf_ptr;   /* [n_bcs + 1] each condition's range in tf_id */
  long *tf_id;    /* the part's facets of each traction condition, each by
                     its index among the whole model's traction facets */
  long n_whole;   /* the whole model's points */
} fpm_part;

/* What cutting every rank's part of the whole cells d (scene s, fpm
 * options o, mesh the one d was built on) under partition owner reads,
 * made once: the conditions' facets on the whole (errors of the scene's
 * conditions are the whole model's: a condition that selects no facet of
 * the whole) and each point's index among its owner's. */
typedef struct {
  const gm_dual *d;
  const int *owner;
  int held; /* the share's rings */
  int n_bcs;
  unsigned *traction; /* [n_bcs] whether each condition is a traction or a
                         pressure (its facets are traction facets) */
  long *index;        /* [n_points] */
  long *wptr, *wf;    /* the conditions' facets on the whole */
} fpm_cutter;

pm_err fpm_cutter_init(fpm_cutter *c, const pm_scene *s, const fpm_options *o,
                       const gm_mesh *mesh, const gm_dual *d, const int *owner,
                       int parts);
void fpm_cutter_free(fpm_cutter *c);

/* Rank r's part (c made on the whole cells).  *p owns its arrays. */
pm_err fpm_part_cut(const fpm_cutter *c, int r, fpm_part *p);
void fpm_part_free(fpm_part *p);

/* Rank r's share of the model of scene s (fpm options o; mesh: the names
 * of the whole mesh's surfaces, all the conditions read of it) built on
 * part p: the model fpm_share_create makes of the whole model, bit for
 * bit, with besides the facets of each condition among its own points (its
 * dual's facet points and area vectors, and the lists of them; none in a
 * share cut from the whole), on which fpm_reaction gives its own points'
 * part of each reaction.  The part's cells lose their interfaces and
 * facets once the part's model is built (its points, gid, owner and index
 * stay), and the share takes the part's model (fpm_share_take), so that
 * the two are not held whole together.  *out owns its arrays. */
pm_err fpm_part_share(const pm_scene *s, const fpm_options *o,
                      const gm_mesh *mesh, fpm_part *p, int r, fpm_model **out);

/* Part p as the bytes rank 0 sends (*buf, *len; the caller frees *buf),
 * and the part read from them. */
pm_err fpm_part_pack(const fpm_part *p, char **buf, size_t *len);
pm_err fpm_part_unpack(const char *buf, size_t len, fpm_part *p);

/* The mesh a rank without the whole one holds: m's dimension, box,
 * meshing figures and the names of its surfaces, no nodes nor cells (the
 * conditions find their surfaces by name in it).  *out: gm_mesh_destroy. */
pm_err fpm_mesh_names(const gm_mesh *m, gm_mesh **out);

/* Rank r's share as that rank builds it on the bytes of its part, on one
 * process: the conditions' facets of the whole cells *whole (the mesh
 * mesh's) and its part cut, packed and read back (with release, *whole is
 * destroyed and NULL once the part is cut, before the part's model is
 * built, so that the two are never held together), and fpm_part_share. */
pm_err fpm_share_build(const pm_scene *s, const fpm_options *o,
                       const gm_mesh *mesh, gm_dual **whole, bool release,
                       const int *owner, int r, fpm_model **out);

#endif
