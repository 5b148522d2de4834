/* gm_cells: the table of cell builders for FPM. */
#include "gm_cells.h"

#include <string.h>

static const gm_cells_builder builders[] = {
    {"median-dual",
     "median-dual cells: node, edge midpoints, face and element centroids",
     gm_dual_build},
};

#define N_BUILDERS ((int)(sizeof builders / sizeof builders[0]))

const gm_cells_builder *gm_cells_find(const char *name) {
  if (!name) return NULL;
  for (int i = 0; i < N_BUILDERS; i++)
    if (strcmp(builders[i].name, name) == 0) return &builders[i];
  return NULL;
}

int gm_cells_count(void) { return N_BUILDERS; }

const gm_cells_builder *gm_cells_at(int i) {
  return i >= 0 && i < N_BUILDERS ? &builders[i] : NULL;
}
