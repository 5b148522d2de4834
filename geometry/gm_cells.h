/* gm_cells: the table of partitions of a mesh into FPM cells (subdomains),
 * looked up by name: "median-dual" (gm_dual_build) and "voronoi" (the
 * Voronoi cells of the mesh nodes clipped to its box, gm_voronoi_build);
 * another partition is one more entry in gm_cells.c. */
#ifndef GM_CELLS_H
#define GM_CELLS_H

#include "gm_dual.h"

/* Builds the cells of mesh m as a gm_dual (volumes, interfaces, boundary
 * facets with their surfaces; the closure property holds whatever the
 * partition).  Contract as gm_dual_build: on success *out is new and the
 * caller frees it with gm_dual_destroy; on failure *out is NULL. */
typedef pm_err (*gm_cells_build_fn)(const gm_mesh *m, gm_dual **out);

typedef struct {
  const char *name;    /* the name a scene gives ("median-dual") */
  const char *summary; /* one line for listings and messages */
  gm_cells_build_fn build;
} gm_cells_builder;

/* The builder called name, or NULL (unknown name, NULL).  The entry is
 * static: never freed. */
const gm_cells_builder *gm_cells_find(const char *name);

/* Number of builders, and builder i (NULL when out of range), for listing
 * them (e.g. in the message for an unknown name). */
int gm_cells_count(void);
const gm_cells_builder *gm_cells_at(int i);

#endif
